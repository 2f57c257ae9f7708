#!/usr/bin/env bash
# Every check of primo, from a fresh machine: installs what it needs, then
# formatting, lints (host and Cortex-M4F), the embedded build, docs, tests.
set -euo pipefail
cd "$(dirname "$0")"

rustup target add thumbv7em-none-eabihf
rustup component add clippy rustfmt

cargo fmt --all --check
cargo clippy --workspace --all-targets --locked -- -D warnings
cargo clippy -p primo-core --target thumbv7em-none-eabihf --locked -- -D warnings
cargo build -p primo-core --target thumbv7em-none-eabihf --release --locked
RUSTDOCFLAGS="-D warnings" cargo doc -p primo-core -p primo-host --no-deps --locked
log=$(mktemp)
cargo test --workspace --locked 2>&1 | tee "$log"
# One closing tally over every test binary and the doc tests.
awk '/^test result:/ { p += $4; f += $6 } END { printf "all tests: %d passed, %d failed\n", p, f }' "$log"
