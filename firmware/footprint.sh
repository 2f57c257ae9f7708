#!/usr/bin/env bash
# The firmware's footprint: flash and RAM of the release images (the
# coprocessor, the scale under QEMU and the scale on a NUCLEO-G431RB),
# and what the footprint probe measures on the emulated Cortex-M4F (instructions per DMP step, per PoWER update and per
# scale reading; the service's and the scale's stack depth).
set -euo pipefail
cd "$(dirname "$0")"
cargo build --release --locked -q
# Wherever cargo puts it: CARGO_TARGET_DIR and cargo's config respected.
target=$(cargo metadata --format-version 1 --no-deps --locked |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
release=$target/thumbv7em-none-eabihf/release
# The NUCLEO-G431RB's scale image: its own build (boards/nucleo-g431),
# measured as the others (it cannot run here: no board).
board=boards/nucleo-g431
(cd "$board" && cargo build --release --locked -q)
board_target=$(cd "$board" && cargo metadata --format-version 1 --no-deps --locked |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
for image in "$release/primo-firmware 64 32" "$release/primo-scale 126 32" \
  "$board_target/thumbv7em-none-eabihf/release/primo-nucleo-g431 126 32"; do
  set -- $image
  size -A "$1" | awk -v name="$(basename "$1")" -v flash_kib="$2" -v ram_kib="$3" '
    $1 == ".vector_table" || $1 == ".text" || $1 == ".rodata" || $1 == ".data" { flash += $2 }
    $1 == ".data" || $1 == ".bss" || $1 == ".uninit" { ram += $2 }
    END { printf "%s flash: %d bytes (%.1f KiB of %d)\n%s statics: %d bytes (%.1f KiB of %d, the rest is stack)\n",
      name, flash, flash / 1024, flash_kib, name, ram, ram / 1024, ram_kib }'
done
qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
  -semihosting-config enable=on,target=native -icount shift=0 \
  -kernel "$release/footprint"
