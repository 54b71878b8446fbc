#!/usr/bin/env bash
# Unpack the real Nav2 (Jazzy) that the test machine carries (../shared/ros2/nav2-*.tar.zst,
# see its README: bt_navigator, planner, controller, behaviours, waypoint follower, ... and
# Nav2's loopback simulator) for tests/test_nav2_real.py and benchmarks/bench_nav2_real.py.
# A test dependency only: users run Nav2 from their ROS 2 install. The tree is a superset of
# the minimal ROS 2 one and goes beside it, into $NAVSEQ_NAV2_PREFIX (default /opt/nav2),
# by scripts/install-ros2-min.sh's rules (stamp, atomic swap, Debian packages). Without the
# archive this script says so and does nothing (the real-Nav2 tests are then skipped).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
archive="${NAVSEQ_NAV2_ARCHIVE:-}"
if [ -z "$archive" ]; then
  for dir in "$repo/../shared/ros2" /work/shared/ros2; do
    found=$(ls "$dir"/nav2-*.tar.zst 2>/dev/null | head -n 1 || true)
    if [ -n "$found" ]; then archive="$found"; break; fi
  done
fi
if [ -z "$archive" ] || [ ! -f "$archive" ]; then
  echo "install-nav2: no real Nav2 archive found; the real-Nav2 tests will be skipped"
  exit 0
fi
# The C++ servers' runtime libraries, as the archive's README lists them.
NAVSEQ_ROS2_ARCHIVE="$archive" \
NAVSEQ_ROS2_PREFIX="${NAVSEQ_NAV2_PREFIX:-/opt/nav2}" \
NAVSEQ_ROS2_EXTRA_PACKAGES="libtinyxml2-9 libconsole-bridge1.0 libyaml-cpp0.7 liborocos-kdl1.5
  libgraphicsmagick++-q16-12 libzmq5 libsqlite3-0 libuuid1 python3-transforms3d" \
  exec "$repo/scripts/install-ros2-min.sh"
