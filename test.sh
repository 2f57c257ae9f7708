#!/usr/bin/env bash
# Every check of primo, from a fresh machine: installs what it needs, then
# formatting, lints (host and Cortex-M4F), the embedded build, docs, the
# firmware's on-target tests under QEMU, the hardware-in-the-loop tests,
# the Python package, the book and its checks, fuzzing.
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
# The no_std crates the images are made of, linted and built for the M4F.
no_std="-p primo-core -p primo-protocol -p primo-learner -p primo-device"
cargo clippy $no_std --target thumbv7em-none-eabihf --locked -- -D warnings
cargo build $no_std --target thumbv7em-none-eabihf --release --locked
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
log=$(mktemp)
# The firmware: its own build, lints, on-target tests under QEMU, the
# release ELF the hardware-in-the-loop tests boot, and the board image.
(
  cd firmware
  cargo fmt --check
  cargo clippy --release --all-targets --locked -- -D warnings
  cargo test --release --locked
  # The NUCLEO-G431RB's scale image (its own build, boards/nucleo-g431):
  # lints here, built and measured by footprint.sh; no board to run it on
  # (its flash sequence is tested on the host, device/tests/flash.rs).
  (
    cd boards/nucleo-g431
    cargo fmt --check
    cargo clippy --release --locked -- -D warnings
  )
  ./footprint.sh
) 2>&1 | tee "$log"
cargo test --workspace --locked 2>&1 | tee -a "$log"
# ---- Robots through their independent peers (issue 29) ----------------
# From the peers' environment tests/peers/setup.sh makes (cold about 80 s
# and 450 MB, reused after): ROS 2, primo-ros2 and `primo robot play` /
# `primo learn --robot ros2:/CONTROLLER` against an rclpy
# FollowJointTrajectory server publishing /joint_states
# (tests/peers/fake_jtc.py), each test on a ROS_DOMAIN_ID of its own;
# Franka, primo's FCI client on franka-sim and pylibfranka (Franka's own
# client) driving primo's simulated controller (tests/peers/plf_drive.py).
# DDS discovery and franka-sim (it binds every interface) must stay on
# this machine: the tests run in a network namespace with loopback alone
# (`unshare -n` as root, a user namespace otherwise), built outside it and
# run offline inside, and refuse to run anywhere else. 18 tests: about
# 45 s here with the environment reused, up to a minute and a half while
# other builds load both cores; primo-ros2 and ros2-client's 79 crates add
# about 40 s to a cold build on 2 cores.
peers=$(tests/peers/setup.sh)
peer_tests=(-p primo-ros2 -p primo-franka -p primo-cli --test rclpy --test ros2 --test peers)
cargo test --locked "${peer_tests[@]}" --no-run
# A private /dev/shm too (a mount namespace with its own tmpfs): Fast DDS
# leaves its shared-memory files there, and they go with the namespace.
as_root=$([ "$(id -u)" = 0 ] || echo -r)
unshare $as_root -n -m sh -c 'mount -t tmpfs tmpfs /dev/shm && ip link set lo up &&
  exec "$@"' sh \
  env PRIMO_PEERS_VENV="$peers" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST \
  ROS_DISTRO=jazzy cargo test --offline --locked "${peer_tests[@]}" 2>&1 | tee -a "$log"
# ---- end of the robots' peers ------------------------------------------
# The Python package (python/, its own build; the distribution
# primo-robotics): lints, then the release's Linux artifacts into
# target/python-dist, built through the package's own build backend
# (python/build-backend): the abi3 wheel, manylinux2014 by linking with zig,
# and the sdist; twine checks both, auditwheel the wheel's tag, pip the
# sdist's metadata. That wheel is what the tests below run on, installed
# into a virtual environment under target/ (its Rust build is kept in
# target/python for the next run), against the primo binary built above
# (the experiment sweeps' among them, on a local Ray: requirements-test.txt
# installs it), with the docstring examples of the installed package. The
# release's steps take 7 s with the build cached (the sdist, twine,
# auditwheel and pip about 5 s of it; a cold build of the wheel takes about
# 2 minutes on 2 cores, as `pip install ./python` did) and add 370 MB to the
# environment (ziglang 337 MB, twine, auditwheel).
(
  cd python
  cargo fmt --check
  cargo clippy --all-targets --locked -- -D warnings
)
venv=target/python-venv
dist=target/python-dist
[ -x "$venv/bin/pytest" ] || python3 -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check -r python/requirements-test.txt
rm -rf "$dist"
(
  export PATH="$PWD/$venv/bin:$PATH" CARGO_TARGET_DIR="$PWD/target/python" PIP_DISABLE_PIP_VERSION_CHECK=1
  pip wheel -q --no-deps --no-build-isolation -w "$dist" \
    --config-settings=build-args="--zig --compatibility manylinux2014" ./python
  maturin sdist -m python/Cargo.toml -o "$dist"
  twine check --strict "$dist"/*
  shown=$(auditwheel show "$dist"/*.whl)
  grep -Fq "\"manylinux_2_17_$(uname -m)\"" <<<"$shown" || { echo "$shown"; exit 1; }
  echo "auditwheel: $(basename "$dist"/*.whl) is manylinux_2_17_$(uname -m)"
  pip install -q --no-deps --no-build-isolation --dry-run "$dist"/*.tar.gz
  pip install -q --no-deps --force-reinstall "$dist"/*.whl
)
PRIMO_BIN="$PWD/target/debug/primo" "$venv/bin/pytest" -q -p no:cacheprovider python/tests \
  --doctest-modules --pyargs primo 2>&1 | tee -a "$log"
# The benchmark suite's smoke test (bench/suite, issue 28): reach-v3 and
# push-v3 (Metaworld) and Reacher-v5, one context, 3 roll-outs of each of
# its methods through primo.gym.BlackBox, in its own pinned environment
# target/bench-venv with the wheel built above; it asserts that every run
# ends and writes target/bench-smoke/suite.csv. About 9 s once the
# environment exists; the first run adds about 32 s from a warm pip cache
# (46 s with none) and 456 MB (scipy, Metaworld, matplotlib, MuJoCo, ...).
PRIMO_WHEEL=$(ls "$PWD/$dist"/*.whl) bench/suite/run.sh --smoke
# The book (docs/, mdBook; installed where missing, search only: about two
# minutes of build), then docs/check.py over it and the README,
# ARCHITECTURE.md, CHANGELOG.md, python/README.md and bench/results/:
# every relative link and #anchor resolves (rustdoc's in the docs built
# above), every `primo ...` command line names real subcommands and flags
# (the binary built above), Python blocks compile and run in the package's
# environment, the README's five-minute path runs in a scratch directory.
mdbook --version 2>/dev/null | grep -q '^mdbook v0\.5\.' ||
  cargo install mdbook --locked --version '^0.5.4' --no-default-features --features search
mdbook build docs
target_dir=$(cargo metadata --format-version 1 --no-deps |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
python3 docs/check.py --primo "$target_dir/debug/primo" --python "$PWD/$venv/bin/python"
# Fuzzing (fuzz/README.md): every target for 30 s from its committed seeds,
# in a scratch corpus; any crash fails (its input lands in fuzz/artifacts/).
cargo +nightly --version >/dev/null 2>&1 || rustup toolchain install nightly --profile minimal
cargo fuzz --version >/dev/null 2>&1 || cargo install cargo-fuzz --locked
(
  cd fuzz
  cargo fmt --check
  cargo +nightly fetch --locked
  cargo +nightly fuzz build
  for target in $(cargo +nightly fuzz list); do
    corpus=$(mktemp -d)
    cp "seeds/$target"/* "$corpus"
    if ! cargo +nightly fuzz run "$target" "$corpus" -- -max_total_time=30 >"$corpus.log" 2>&1; then
      tail -n 40 "$corpus.log"
      echo "fuzz $target: crashed"
      exit 1
    fi
    echo "fuzz $target: $(grep -o 'Done [0-9]* runs in [0-9]* second(s)' "$corpus.log"), clean"
    rm -rf "$corpus" "$corpus.log"
  done
)
# One closing tally over every test binary, the doc tests and pytest.
awk '/^test result:/ { p += $4; f += $6 }
     /^[0-9]+ (passed|failed)/ { for (i = 1; i < NF; i++) {
       if ($(i + 1) ~ /^passed/) p += $i; if ($(i + 1) ~ /^failed/) f += $i } }
     END { printf "all tests: %d passed, %d failed\n", p, f }' "$log"
