"""Nav2's ``map_server`` on the ROS 2 simulator node: the map, and a new map on request.

As nav2_map_server (Jazzy) serves it, on the ``map_server`` lifecycle node:

- ``map`` (``nav_msgs/OccupancyGrid``, reliable, transient local, depth 1: a late
  subscriber gets the last map), published at start and after every map loaded;
- ``map_server/map`` (``nav_msgs/srv/GetMap``): the map now;
- ``map_server/load_map`` (``nav2_msgs/srv/LoadMap``, what ``nav2_simple_commander``'s
  ``changeMap()`` calls): ``map_url`` is a map YAML's path. The new map **replaces the
  world**: the body collides with its walls, the planner and both costmaps use it, a
  running goal is planned again on it; a robot that now overlaps an obstacle is logged
  as a warning (it cannot move until placed elsewhere). Nav2's result codes: an empty
  ``map_url`` ``RESULT_MAP_DOES_NOT_EXIST``; a YAML that cannot be read or whose
  settings are wrong (a missing file too: Nav2's YAML reader fails first)
  ``RESULT_INVALID_MAP_METADATA``; an image that cannot be read
  ``RESULT_INVALID_MAP_DATA``. On failure the old map stays.

While ``map_server`` is not active both services answer with an empty response (result 0,
no map) and a warning, as Nav2's callbacks return without filling it in.

Nav2's map_server publishes no ``map_metadata`` (ROS 1's map_server did); neither does
this one.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from nav2_msgs.srv import LoadMap
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.srv import GetMap
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from navseq.errors import NavseqError, error_text
from navseq.ros2.messages import grid_msg
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.occupancy import OccupancyGrid, check_map_description, load_map

MAP_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def load_map_result(url: str) -> tuple[int, OccupancyGrid | str]:
    """``LoadMap``'s result code and the grid, or the code and why there is none."""
    if not url:
        return LoadMap.Response.RESULT_MAP_DOES_NOT_EXIST, "map_url is empty"
    try:
        check_map_description(url)
    except NavseqError as error:
        return LoadMap.Response.RESULT_INVALID_MAP_METADATA, error_text(error)
    try:
        return LoadMap.Response.RESULT_SUCCESS, load_map(url)
    except NavseqError as error:
        return LoadMap.Response.RESULT_INVALID_MAP_DATA, error_text(error)


class MapServer:
    """The map topic and services of ``server`` (the ``map_server`` lifecycle node)."""

    def __init__(
        self,
        server: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        active: Callable[[], bool],
        stamp: Callable[[], Any],
        frame: str,
        on_new_map: Callable[[], None] = lambda: None,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._active = active
        self._stamp = stamp
        self._frame = frame
        self._on_new_map = on_new_map
        self._log = server.get_logger()
        self._publisher = server.create_publisher(OccupancyGridMsg, "map", MAP_QOS)
        name = server.get_name()
        server.create_service(GetMap, f"{name}/map", self._get_map, callback_group=group)
        server.create_service(LoadMap, f"{name}/load_map", self._load_map, callback_group=group)
        self.publish()

    def publish(self) -> None:
        with self._lock:
            grid = self._standin.world.grid
        self._publisher.publish(self._message(grid))

    def _message(self, grid: OccupancyGrid) -> OccupancyGridMsg:
        return grid_msg(grid, self._frame, self._stamp())

    def _get_map(self, _request: Any, response: Any) -> Any:
        if not self._active():
            self._log.warning("Received GetMap request but not in ACTIVE state, ignoring!")
            return response
        with self._lock:
            grid = self._standin.world.grid
        response.map = self._message(grid)
        return response

    def _load_map(self, request: Any, response: Any) -> Any:
        if not self._active():
            self._log.warning("Received LoadMap request but not in ACTIVE state, ignoring!")
            return response
        url = str(request.map_url)
        code, loaded = load_map_result(url)
        response.result = code
        if isinstance(loaded, str):
            self._log.error(f"load_map {url!r} failed (result {code}): {loaded}")
            return response
        with self._lock:
            warning = self._standin.replace_map(loaded)
        message = self._message(loaded)
        response.map = message
        self._publisher.publish(message)
        self._log.info(f"load_map: {url} ({loaded.width} x {loaded.height} cells)")
        if warning is not None:
            self._log.warning(f"load_map: {warning}")
        self._on_new_map()
        return response


__all__ = ["MapServer", "load_map_result"]
