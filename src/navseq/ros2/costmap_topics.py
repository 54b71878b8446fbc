"""Nav2's costmap topics and services on the ROS 2 simulator node, for both costmaps.

What RViz's costmap displays and ``nav2_simple_commander``'s ``getGlobalCostmap()`` /
``getLocalCostmap()`` read, under nav2_bringup's names:

- ``global_costmap/costmap`` (``nav_msgs/OccupancyGrid``, costs by Nav2's translation
  table: :func:`navseq.sim.costmap.occupancy_values`), ``global_costmap/costmap_raw``
  (``nav2_msgs/Costmap``, the costs as they are), both reliable and transient local, in
  the map frame: the navigation server's costmap, published again whenever it changes
  (cleared, other robots moved into it);
- ``local_costmap/...`` the same for a 3 m × 3 m window about the robot (nav2_bringup's
  rolling window) in the odom frame, twice a second. It is cut from the global costmap:
  the stand-in has no sensors, so both see the map (and the other robots);
- ``*/published_footprint`` (``geometry_msgs/PolygonStamped``): the robot's outline
  where it stands, in each costmap's frame;
- ``*/get_costmap`` (``nav2_msgs/srv/GetCostmap``): the costmap now.
"""

from __future__ import annotations

import array
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from geometry_msgs.msg import Point32, PolygonStamped
from nav2_msgs.msg import Costmap as CostmapMsg
from nav2_msgs.srv import GetCostmap
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from navseq.geometry import Pose2D, compose, inverse
from navseq.ros2.messages import pose_msg
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.costmap import occupancy_values

LOCAL_SIZE_M = 3.0  # nav2_bringup's local_costmap width and height
LOCAL_PERIOD = 0.5  # s: nav2_bringup's local_costmap publish_frequency, 2 Hz
LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


@dataclass(frozen=True)
class CostWindow:
    """Costs (uint8, row 0 at the bottom), their cell size and the pose of the lower-left
    corner of cell (0, 0) in ``frame``."""

    cost: np.ndarray
    resolution: float
    origin: Pose2D
    frame: str


class CostmapTopics:
    """Publishes both costmaps of ``standin`` on ``node`` and answers ``get_costmap``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        stamp: Callable[[], Any],
        map_frame: str,
        odom_frame: str,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._stamp = stamp
        self._map_frame = map_frame
        self._odom_frame = odom_frame
        self._global_version: int | None = None
        self._publishers: dict[str, tuple[Any, Any, Any]] = {}
        for name in ("global_costmap", "local_costmap"):
            self._publishers[name] = (
                node.create_publisher(OccupancyGridMsg, f"{name}/costmap", LATCHED),
                node.create_publisher(CostmapMsg, f"{name}/costmap_raw", LATCHED),
                node.create_publisher(PolygonStamped, f"{name}/published_footprint", 10),
            )
            node.create_service(
                GetCostmap, f"{name}/get_costmap", self._get_costmap(name), callback_group=group
            )
        node.create_timer(LOCAL_PERIOD, self.publish, callback_group=group)

    def publish(self) -> None:
        """Both footprints and the local costmap; the global one when it changed."""
        with self._lock:
            server = self._standin.world.server
            body = self._standin.world.body
            changed = server.costmap_version != self._global_version
            self._global_version = server.costmap_version
            windows = {"local_costmap": self._local_window()}
            if changed:
                windows["global_costmap"] = self._global_window()
            # Where the robot believes it is: the transforms the node publishes.
            localization = self._standin.localization
            pose, odom_pose = localization.believed_pose, localization.odom_pose
            footprint = body.footprint.polygon
        stamp = self._stamp()
        for name, window in windows.items():
            grid, raw, _ = self._publishers[name]
            grid.publish(occupancy_msg(window, stamp))
            raw.publish(costmap_msg(window, stamp))
        for name, at, frame in (
            ("global_costmap", pose, self._map_frame),
            ("local_costmap", odom_pose, self._odom_frame),
        ):
            self._publishers[name][2].publish(footprint_msg(footprint, at, frame, stamp))

    def _get_costmap(self, name: str) -> Callable[[Any, Any], Any]:
        def answer(_request: Any, response: Any) -> Any:
            with self._lock:
                window = self._global_window() if name == "global_costmap" else self._local_window()
            response.map = costmap_msg(window, self._stamp())
            return response

        return answer

    def _global_window(self) -> CostWindow:
        costmap = self._standin.world.server.costmap
        grid = costmap.grid
        return CostWindow(costmap.cost, grid.resolution, grid.origin, self._map_frame)

    def _local_window(self) -> CostWindow:
        """The rolling window about the robot, cut from the global costmap (cells off the
        map unknown), its origin given in the odom frame."""
        costmap = self._standin.world.server.costmap
        grid, localization = costmap.grid, self._standin.localization
        cells = round(LOCAL_SIZE_M / grid.resolution)
        believed = localization.believed_pose
        row, col = grid.world_to_cell(believed.x, believed.y)
        top, left = row - cells // 2, col - cells // 2
        window = np.full((cells, cells), 255, dtype=np.uint8)
        rows = slice(max(top, 0), min(top + cells, grid.height))
        cols = slice(max(left, 0), min(left + cells, grid.width))
        if rows.start < rows.stop and cols.start < cols.stop:
            window[rows.start - top : rows.stop - top, cols.start - left : cols.stop - left] = (
                costmap.cost[rows, cols]
            )
        corner = compose(grid.origin, Pose2D(left * grid.resolution, top * grid.resolution, 0.0))
        in_odom = compose(inverse(localization.estimate), corner)
        return CostWindow(window, grid.resolution, in_odom, self._odom_frame)


def occupancy_msg(window: CostWindow, stamp: Any) -> OccupancyGridMsg:
    message = OccupancyGridMsg()
    message.header.frame_id = window.frame
    message.header.stamp = stamp
    message.info.map_load_time = stamp
    message.info.resolution = float(window.resolution)
    message.info.height, message.info.width = (int(n) for n in window.cost.shape)
    message.info.origin = pose_msg(window.origin)
    values = np.ascontiguousarray(occupancy_values(window.cost))
    message.data = array.array("b", values.tobytes())
    return message


def costmap_msg(window: CostWindow, stamp: Any) -> CostmapMsg:
    message = CostmapMsg()
    message.header.frame_id = window.frame
    message.header.stamp = stamp
    specs = message.metadata
    specs.map_load_time = specs.update_time = stamp
    specs.layer = "master"
    specs.resolution = float(window.resolution)
    specs.size_y, specs.size_x = (int(n) for n in window.cost.shape)
    specs.origin = pose_msg(window.origin)
    message.data = array.array("B", np.ascontiguousarray(window.cost, dtype=np.uint8).tobytes())
    return message


def footprint_msg(polygon: np.ndarray, at: Pose2D, frame: str, stamp: Any) -> PolygonStamped:
    message = PolygonStamped()
    message.header.frame_id = frame
    message.header.stamp = stamp
    for x, y in polygon:
        corner = compose(at, Pose2D(float(x), float(y), 0.0))
        message.polygon.points.append(Point32(x=corner.x, y=corner.y, z=0.0))
    return message


__all__ = ["CostmapTopics"]
