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
- ``*/costmap_updates`` (``map_msgs/OccupancyGridUpdate``) and ``*/costmap_raw_updates``
  (``nav2_msgs/CostmapUpdate``), reliable and transient local as Nav2's
  ``Costmap2DPublisher`` has them: after a costmap's first full message, the cells inside
  the bounds of what changed, when the costmap changed but kept its size, resolution and
  origin (a rolling window that moved, or a new map of another size, is sent in full
  only). ``costmap_updates`` only where map_msgs is installed (the log says when it is
  not). The full costmap is published as well, so a display that reads only the full
  topic stays right;
- ``*/published_footprint`` (``geometry_msgs/PolygonStamped``): the robot's outline
  where it stands, in each costmap's frame; ``*/footprint`` (``geometry_msgs/Polygon``,
  subscribed as Nav2's costmaps do) replaces that costmap's outline (the robot frame's
  points), and the local one is the collision monitor's ``FootprintApproach`` polygon.
  The body, the planner and the controller keep the robot profile's;
- ``*/get_costmap`` (``nav2_msgs/srv/GetCostmap``): the costmap now.
"""

from __future__ import annotations

import array
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from geometry_msgs.msg import Point32, Polygon, PolygonStamped
from nav2_msgs.msg import Costmap as CostmapMsg
from nav2_msgs.msg import CostmapUpdate
from nav2_msgs.srv import GetCostmap
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from navseq.geometry import Pose2D, compose, inverse
from navseq.ros2.messages import pose_msg
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.costmap import occupancy_values
from navseq.sim.occupancy import OccupancyGrid

try:  # Nav2's build has map_msgs; a minimal ROS 2 (the test machine's) may not
    from map_msgs.msg import OccupancyGridUpdate
except ImportError:  # pragma: no cover - depends on the ROS 2 install
    OccupancyGridUpdate = None

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
        self._update_publishers: dict[str, tuple[Any | None, Any]] = {}
        self._last_sent: dict[str, CostWindow] = {}  # each costmap as last published
        # A footprint published on a costmap's ``footprint`` topic replaces the profile's
        # for that costmap (None: the profile's), as Nav2's setRobotFootprintPolygon does.
        self._footprints: dict[str, np.ndarray | None] = {}
        self._log = node.get_logger()
        for name in ("global_costmap", "local_costmap"):
            self._publishers[name] = (
                node.create_publisher(OccupancyGridMsg, f"{name}/costmap", LATCHED),
                node.create_publisher(CostmapMsg, f"{name}/costmap_raw", LATCHED),
                node.create_publisher(PolygonStamped, f"{name}/published_footprint", 10),
            )
            self._update_publishers[name] = (
                None
                if OccupancyGridUpdate is None
                else node.create_publisher(OccupancyGridUpdate, f"{name}/costmap_updates", LATCHED),
                node.create_publisher(CostmapUpdate, f"{name}/costmap_raw_updates", LATCHED),
            )
            node.create_service(
                GetCostmap, f"{name}/get_costmap", self._get_costmap(name), callback_group=group
            )
            node.create_subscription(
                Polygon, f"{name}/footprint", self._on_footprint(name), 10, callback_group=group
            )
        if OccupancyGridUpdate is None:
            node.get_logger().info(
                "*/costmap_updates not served: map_msgs is not installed "
                "(the changed cells are on */costmap_raw_updates)"
            )
        node.create_timer(LOCAL_PERIOD, self.publish, callback_group=group)

    def publish(self) -> None:
        """Both footprints and the local costmap; the global one when it changed."""
        with self._lock:
            server = self._standin.world.server
            changed = server.costmap_version != self._global_version
            self._global_version = server.costmap_version
            windows = {"local_costmap": self._local_window()}
            if changed:
                windows["global_costmap"] = self._global_window()
            # Where the robot believes it is: the transforms the node publishes.
            localization = self._standin.localization
            pose, odom_pose = localization.believed_pose, localization.odom_pose
            footprints = {name: self.footprint(name) for name in self._publishers}
        stamp = self._stamp()
        for name, window in windows.items():
            grid, raw, _ = self._publishers[name]
            grid.publish(occupancy_msg(window, stamp))
            raw.publish(costmap_msg(window, stamp))
            self._publish_update(name, window, stamp)
        for name, at, frame in (
            ("global_costmap", pose, self._map_frame),
            ("local_costmap", odom_pose, self._odom_frame),
        ):
            self._publishers[name][2].publish(footprint_msg(footprints[name], at, frame, stamp))

    def footprint(self, name: str) -> np.ndarray:
        """The outline costmap ``name`` holds (robot frame): one published on its
        ``footprint`` topic, else the robot profile's (call with the lock)."""
        given = self._footprints.get(name)
        return self._standin.world.body.footprint.polygon if given is None else given

    def _on_footprint(self, name: str) -> Callable[[Any], None]:
        def take(message: Any) -> None:
            points = np.array([(p.x, p.y) for p in message.points], dtype=float).reshape(-1, 2)
            if len(points) < 3:
                self._log.warning(f"{name}/footprint ignored: fewer than 3 points")
                return
            with self._lock:
                self._footprints[name] = points
                if name == "local_costmap":  # the collision monitor's footprint_topic
                    self._standin.monitor.monitor.footprint = points
            self._log.info(f"{name}: footprint of {len(points)} points")

        return take

    def _publish_update(self, name: str, window: CostWindow, stamp: Any) -> None:
        """The changed part of ``name`` since it was last published, if any."""
        previous = self._last_sent.get(name)
        # The global window is the live costmap: keep a copy to compare the next one with.
        self._last_sent[name] = CostWindow(
            window.cost.copy(), window.resolution, window.origin, window.frame
        )
        if previous is None or not same_area(previous, window):
            return
        bounds = changed_bounds(previous.cost, window.cost)
        if bounds is None:
            return
        grid_update, raw_update = self._update_publishers[name]
        if grid_update is not None:
            grid_update.publish(occupancy_update_msg(window, bounds, stamp))
        raw_update.publish(costmap_update_msg(window, bounds, stamp))

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
        return local_window(
            costmap.cost, costmap.grid, self._standin.localization, self._odom_frame, fill=255
        )


def local_window(
    cost: np.ndarray, grid: OccupancyGrid, localization: Any, frame: str, *, fill: int
) -> CostWindow:
    """nav2_bringup's rolling window (``LOCAL_SIZE_M`` square) about the robot's believed
    pose, cut from ``cost`` (cells of ``grid``; ``fill`` off the map), its origin given in
    the odom frame ``frame`` through ``localization``'s estimate."""
    cells = round(LOCAL_SIZE_M / grid.resolution)
    believed = localization.believed_pose
    row, col = grid.world_to_cell(believed.x, believed.y)
    top, left = row - cells // 2, col - cells // 2
    window = np.full((cells, cells), fill, dtype=np.uint8)
    rows = slice(max(top, 0), min(top + cells, grid.height))
    cols = slice(max(left, 0), min(left + cells, grid.width))
    if rows.start < rows.stop and cols.start < cols.stop:
        window[rows.start - top : rows.stop - top, cols.start - left : cols.stop - left] = cost[
            rows, cols
        ]
    corner = compose(grid.origin, Pose2D(left * grid.resolution, top * grid.resolution, 0.0))
    in_odom = compose(inverse(localization.estimate), corner)
    return CostWindow(window, grid.resolution, in_odom, frame)


#: Changed cells: column and row of the lower-left one, width and height (in cells).
Bounds = tuple[int, int, int, int]


def same_area(first: CostWindow, second: CostWindow) -> bool:
    """Whether two windows cover the same cells (an update can say what changed)."""
    return (
        first.cost.shape == second.cost.shape
        and first.resolution == second.resolution
        and first.origin == second.origin
        and first.frame == second.frame
    )


def changed_bounds(before: np.ndarray, after: np.ndarray) -> Bounds | None:
    """The smallest box of cells holding every cell that differs, or None."""
    rows, cols = np.nonzero(before != after)
    if rows.size == 0:
        return None
    x, y = int(cols.min()), int(rows.min())
    return x, y, int(cols.max()) - x + 1, int(rows.max()) - y + 1


def _cut(window: CostWindow, bounds: Bounds) -> np.ndarray:
    x, y, width, height = bounds
    return np.ascontiguousarray(window.cost[y : y + height, x : x + width], dtype=np.uint8)


def occupancy_update_msg(window: CostWindow, bounds: Bounds, stamp: Any) -> Any:
    assert OccupancyGridUpdate is not None
    message = OccupancyGridUpdate()
    message.header.frame_id = window.frame
    message.header.stamp = stamp
    message.x, message.y, message.width, message.height = bounds
    values = np.ascontiguousarray(occupancy_values(_cut(window, bounds)))
    message.data = array.array("b", values.tobytes())
    return message


def costmap_update_msg(window: CostWindow, bounds: Bounds, stamp: Any) -> CostmapUpdate:
    message = CostmapUpdate()
    message.header.frame_id = window.frame
    message.header.stamp = stamp
    message.x, message.y, message.size_x, message.size_y = bounds
    message.data = array.array("B", _cut(window, bounds).tobytes())
    return message


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
