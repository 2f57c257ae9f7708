# Sourced by the real-time benchmarks (fri_load.sh, franka_load.sh) from
# the repository's root: builds the release `primo` ($primo), makes a
# scratch directory ($work) and loads the machine on demand (`load [NICE]`:
# two busy loops per core, at that niceness if given; `unload`); the
# loops and the scratch directory go when the script exits.
cargo build --release --locked -q --bin primo
target=$(cargo metadata --format-version 1 --no-deps --locked |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
primo=$target/release/primo
work=$(mktemp -d)
loaders=()

unload() {
  for pid in "${loaders[@]}"; do kill "$pid" 2>/dev/null || true; done
  loaders=()
}

cleanup() {
  unload
  rm -rf "$work"
}
trap cleanup EXIT

load() {
  local niceness=${1:-0}
  for _ in $(seq $((2 * $(nproc)))); do
    nice -n "$niceness" sh -c 'while :; do :; done' &
    loaders+=($!)
  done
}
