#!/usr/bin/env bash
# Install the ROS 1 (Noetic-era) packages navseq's ROS side needs, from Debian's archive.
# Debian ships rospy, actionlib, roslaunch and the messages, but no move_base/Gazebo:
# navseq's own simulator nodes stand in for those.
set -euo pipefail
packages=(
  python3-rospy python3-actionlib python3-move-base-msgs python3-nav-msgs
  python3-geometry-msgs python3-visualization-msgs python3-std-srvs python3-tf2-msgs
  python3-sensor-msgs
  python3-tf2-ros python3-rosmaster python3-roslaunch python3-rosparam python3-rostopic
  rosbash catkin python3-venv
  # What the nodes import besides ROS, for catkin installs run by /usr/bin/python3
  # (a venv has its own copies from PyPI).
  python3-numpy python3-scipy python3-pil python3-yaml
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-ros1-debian: all ROS 1 packages present"
  exit 0
fi
if [ "$(id -u)" != 0 ]; then SUDO=sudo; else SUDO=; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
