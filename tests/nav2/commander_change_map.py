"""nav2_simple_commander's changeMap(), unchanged, against the stand-in (tests/test_ros2_world.py).

    python commander_change_map.py MAP.yaml

changeMap() waits for ``map_server/load_map`` and spins until its answer (a stand-in that
does not answer makes it hang: the test's timeout says so). Afterwards the map on
``map`` must be the new one. Prints one JSON line: the width published before and after.
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from nav2_simple_commander.robot_navigator import BasicNavigator
from nav_msgs.msg import OccupancyGrid
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def main() -> int:
    rclpy.init()
    navigator = BasicNavigator()
    maps: list[OccupancyGrid] = []
    navigator.create_subscription(OccupancyGrid, "map", maps.append, LATCHED)

    def latest_width(seconds: float) -> int | None:
        end = time.monotonic() + seconds
        while time.monotonic() < end and not maps:
            rclpy.spin_once(navigator, timeout_sec=0.05)
        return maps[-1].info.width if maps else None

    out = {"before": latest_width(10.0)}
    maps.clear()
    navigator.changeMap(sys.argv[1])
    out["after"] = latest_width(5.0)
    print(json.dumps(out), flush=True)
    navigator.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
