#!/usr/bin/env python3
"""Regenerate navseq's recording message definitions (src/navseq/sinks/recording/definitions/).

A recording's schema is the message type's full definition: its own .msg text followed by
every type it uses, each under a ``MSG: package/Type`` line, as rosbag and rosbag2 store
them. They are taken verbatim from the installed messages, never written by hand:

- ROS 1: the ``_full_text`` of Debian's generated Python messages (python3-nav-msgs ...);
- ROS 2: the .msg files under a ROS 2 install's share/ (default /opt/ros2min/share).

Run with Debian's python3 (which sees its ROS 1 messages):
``/usr/bin/python3 scripts/ros_msg_definitions.py [ROS2_SHARE]``.
"""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

TYPES = (
    "nav_msgs/OccupancyGrid",
    "nav_msgs/Path",
    "nav_msgs/Odometry",
    "geometry_msgs/PoseStamped",
    "tf2_msgs/TFMessage",
    "visualization_msgs/MarkerArray",
)
OUT = Path(__file__).resolve().parents[1] / "src/navseq/sinks/recording/definitions"
SEPARATOR = "=" * 80
PRIMITIVES = {
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string", "wstring", "time", "duration",
}  # fmt: skip


def ros1(name: str) -> str:
    package, type_name = name.split("/")
    module = importlib.import_module(f"{package}.msg")
    return getattr(module, type_name)._full_text


def _used_types(package: str, text: str) -> list[str]:
    used = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        field_type = re.sub(r"\[.*\]|<=\d+", "", line.split()[0])
        if field_type in PRIMITIVES:
            continue
        used.append(field_type if "/" in field_type else f"{package}/{field_type}")
    return used


def ros2(name: str, share: Path) -> str:
    def text_of(type_name: str) -> str:
        package, short = type_name.split("/")
        return (share / package / "msg" / f"{short}.msg").read_text()

    parts, seen, todo = [text_of(name)], {name}, _used_types(name.split("/")[0], text_of(name))
    while todo:
        used = todo.pop(0)
        if used in seen:
            continue
        seen.add(used)
        text = text_of(used)
        parts.append(f"{SEPARATOR}\nMSG: {used}\n{text}")
        todo.extend(_used_types(used.split("/")[0], text))
    return "\n".join(part.rstrip("\n") for part in parts) + "\n"


def main() -> None:
    share = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/opt/ros2min/share")
    for flavour in ("ros1", "ros2"):
        (OUT / flavour).mkdir(parents=True, exist_ok=True)
    for name in TYPES:
        file_name = name.replace("/", ".") + ".msg"
        (OUT / "ros1" / file_name).write_text(ros1(name))
        (OUT / "ros2" / file_name).write_text(ros2(name, share))


if __name__ == "__main__":
    main()
