"""``map_server/load_map``'s result code for each URL given (tests/test_nav2_real.py asks
the real Nav2 what tests/test_ros2_world.py asks the stand-in).

    python load_map_codes.py URL [URL ...]     # prints one JSON list of result codes
"""

from __future__ import annotations

import json
import sys

import rclpy
from nav2_msgs.srv import LoadMap


def main() -> int:
    rclpy.init()
    node = rclpy.create_node("load_map_codes")
    client = node.create_client(LoadMap, "map_server/load_map")
    if not client.wait_for_service(timeout_sec=30):
        sys.exit("no map_server/load_map within 30 s")
    codes = []
    for url in sys.argv[1:]:
        future = client.call_async(LoadMap.Request(map_url=url))
        rclpy.spin_until_future_complete(node, future, timeout_sec=30)
        codes.append(future.result().result if future.done() else None)
    print(json.dumps(codes), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
