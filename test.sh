#!/usr/bin/env bash
# Every check of primo, from a fresh machine: installs what it needs, then
# formatting, lints (host and Cortex-M4F), the embedded build, docs, the
# firmware's on-target tests under QEMU, the hardware-in-the-loop tests.
set -euo pipefail
cd "$(dirname "$0")"

rustup target add thumbv7em-none-eabihf
rustup component add clippy rustfmt
# The coprocessor runs on an emulated Cortex-M4F (Debian's qemu-system-arm).
if ! command -v qemu-system-arm >/dev/null; then
  sudo=$([ "$(id -u)" = 0 ] || echo sudo)
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq qemu-system-arm >/dev/null
fi

cargo fmt --all --check
cargo clippy --workspace --all-targets --locked -- -D warnings
cargo clippy -p primo-core --target thumbv7em-none-eabihf --locked -- -D warnings
cargo build -p primo-core --target thumbv7em-none-eabihf --release --locked
RUSTDOCFLAGS="-D warnings" cargo doc -p primo-core -p primo-host --no-deps --locked
log=$(mktemp)
# The firmware: its own build, lints, on-target tests under QEMU, and the
# release ELF the hardware-in-the-loop tests boot.
(
  cd firmware
  cargo fmt --check
  cargo clippy --release --all-targets --locked -- -D warnings
  cargo test --release --locked
  ./footprint.sh
) 2>&1 | tee "$log"
cargo test --workspace --locked 2>&1 | tee -a "$log"
# One closing tally over every test binary and the doc tests.
awk '/^test result:/ { p += $4; f += $6 } END { printf "all tests: %d passed, %d failed\n", p, f }' "$log"
