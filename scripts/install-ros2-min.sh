#!/usr/bin/env bash
# Unpack the minimal ROS 2 Jazzy that the test machine carries (../shared/ros2, see its
# README) and install the Debian packages it needs. ROS 2 is in neither Debian 12 nor
# PyPI: users install it their usual way (apt from packages.ros.org); this tree is a test
# dependency only. Without the archive this script says so and does nothing (the ros2
# tests are then skipped with a reason).
#
# Where the archive is looked for: $NAVSEQ_ROS2_ARCHIVE, then ../shared/ros2/ next to the
# repository, then /work/shared/ros2/. Where it is unpacked: $NAVSEQ_ROS2_PREFIX (default
# /opt/ros2min); a stamp file keeps a second run from unpacking the same archive again.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
prefix="${NAVSEQ_ROS2_PREFIX:-/opt/ros2min}"

archive="${NAVSEQ_ROS2_ARCHIVE:-}"
if [ -z "$archive" ]; then
  for dir in "$repo/../shared/ros2" /work/shared/ros2; do
    found=$(ls "$dir"/ros2-*.tar.zst 2>/dev/null | head -n 1 || true)
    if [ -n "$found" ]; then archive="$found"; break; fi
  done
fi
if [ -z "$archive" ] || [ ! -f "$archive" ]; then
  echo "install-ros2-min: no ROS 2 archive found; the ros2 tests will be skipped"
  exit 0
fi

packages=(zstd libpython3.11 libyaml-0-2 python3-numpy python3-yaml python3-lark
  python3-psutil python3-packaging)
# A larger tree (the real Nav2, scripts/install-nav2.sh) names the libraries it needs too,
# separated by spaces or newlines: `read -d ''` takes them all (without it, only the
# first line was read, and the Nav2 servers needing the rest could not start).
read -r -d '' -a extra <<< "${NAVSEQ_ROS2_EXTRA_PACKAGES:-}" || true
packages+=("${extra[@]}")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "$(id -u)" != 0 ]; then SUDO=sudo; else SUDO=; fi
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

stamp="$prefix/.navseq-archive"
signature="$(basename "$archive") $(stat -c %s "$archive")"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$signature" ]; then
  echo "install-ros2-min: ROS 2 already unpacked in $prefix"
  exit 0
fi
$SUDO rm -rf "$prefix.partial"
$SUDO mkdir -p "$prefix.partial"
$SUDO tar --zstd -xf "$archive" -C "$prefix.partial"
echo "$signature" | $SUDO tee "$prefix.partial/.navseq-archive" >/dev/null
# Swap in the complete tree only: an interrupted unpack never looks installed.
$SUDO rm -rf "$prefix"
$SUDO mv "$prefix.partial" "$prefix"
echo "install-ros2-min: ROS 2 unpacked in $prefix"
