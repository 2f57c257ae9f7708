# Sourced by the real-time benchmarks (fri_load.sh, franka_load.sh) from
# the repository's root: builds the release `primo` ($primo), makes a
# scratch directory ($work) and loads the machine on demand (`load [NICE]`:
# two busy loops per core, at that niceness if given; `unload`) and runs
# the measurements (`measure`); the loops and the scratch directory go
# when the script exits.
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

# The runs: on the idle machine and under `load NICENESS`, each with the
# loop's real-time scheduling and with --no-realtime, the busy real-time
# case $repeats times; `run [FLAGS]` (the script's) prints "late total
# late-sends scheduling". Sets $rows (the table's) and $spread (of the
# busy real-time late shares).
measure() {
  local niceness=$1 machine mode late total late_sends sched share row
  local busy_shares=()
  rows=()
  for machine in idle busy; do
    [ "$machine" = busy ] && load "$niceness"
    local modes=(realtime no-realtime)
    [ "$machine" = busy ] && for _ in $(seq 2 "$repeats"); do modes+=(realtime); done
    for mode in "${modes[@]}"; do
      local flags=()
      [ "$mode" = no-realtime ] && flags=(--no-realtime)
      read -r late total late_sends sched < <(run "${flags[@]}")
      share=$(awk -v l="$late" -v a="$total" 'BEGIN { printf "%.3f", a ? 100 * l / a : 0 }')
      [ "$machine$mode" = busyrealtime ] && busy_shares+=("$share")
      row="| $machine | $sched | $total | $late | $share % | $late_sends |"
      echo "$row"
      rows+=("$row")
    done
    unload
  done
  spread=$(printf '%s\n' "${busy_shares[@]}" | sort -n | awk '
    { v[NR] = $1 } END { printf "%s runs: %.3f to %.3f %%, median %.3f %%", NR, v[1], v[NR], v[int((NR + 1) / 2)] }')
}
