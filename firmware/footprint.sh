#!/usr/bin/env bash
# The coprocessor's footprint: flash and RAM of the release firmware, and
# what the footprint probe measures on the emulated Cortex-M4F (instructions
# per DMP step and per PoWER update, the service's stack depth).
set -euo pipefail
cd "$(dirname "$0")"
cargo build --release --locked -q
# Wherever cargo puts it: CARGO_TARGET_DIR and cargo's config respected.
target=$(cargo metadata --format-version 1 --no-deps --locked |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
release=$target/thumbv7em-none-eabihf/release
elf=$release/primo-firmware
size -A "$elf" | awk '
  $1 == ".vector_table" || $1 == ".text" || $1 == ".rodata" || $1 == ".data" { flash += $2 }
  $1 == ".data" || $1 == ".bss" || $1 == ".uninit" { ram += $2 }
  END { printf "flash: %d bytes (%.1f KiB of 64)\nstatics: %d bytes (%.1f KiB of 32, the rest is stack)\n", flash, flash / 1024, ram, ram / 1024 }'
qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
  -semihosting-config enable=on,target=native -icount shift=0 \
  -kernel "$release/footprint"
