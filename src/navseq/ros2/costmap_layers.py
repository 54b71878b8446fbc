"""Nav2's per-layer costmap topics and services on the ROS 2 simulator node.

What a default Jazzy bringup's costmaps publish for each layer that keeps cells
(:mod:`navseq.sim.costmap_layers` says what each holds in the stand-in), with the same
publisher as the costmaps themselves (:mod:`navseq.ros2.costmap_topics`: reliable,
transient local; a layer in full, then the cells that changed in it, as Nav2's
publisher sends a layer):

- ``global_costmap/static_layer`` (``nav_msgs/OccupancyGrid``), ``…_raw``
  (``nav2_msgs/Costmap``), ``…_raw_updates`` (``nav2_msgs/CostmapUpdate``) and
  ``…_updates`` (``map_msgs/OccupancyGridUpdate``, where map_msgs is installed): the map,
  in the map frame, again when ``map_server/load_map`` replaces it;
- ``global_costmap/obstacle_layer*`` the same for the laser's marks on the map's cells,
  and ``local_costmap/voxel_layer*`` for them in the local costmap's 3 m window (odom
  frame), every half second: in full when the window moved, else the changed cells;
- ``local_costmap/voxel_grid`` (``nav2_msgs/VoxelGrid``, nav2_bringup's
  ``publish_voxel_map``): the voxel layer's columns; ``local_costmap/clearing_endpoints``
  (``sensor_msgs/PointCloud2``, x y z float32, odom frame): the ends of the rays the
  voxel layer clears along (the laser's hits);
- services ``global_costmap/get_static_layer``, ``global_costmap/get_obstacle_layer``
  and ``local_costmap/get_voxel_layer`` (``nav2_msgs/srv/GetCostmap``, as Nav2's
  ``Costmap2DPublisher`` names them): the layer now.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from geometry_msgs.msg import Point32, Vector3
from nav2_msgs.msg import Costmap as CostmapMsg
from nav2_msgs.msg import CostmapUpdate, VoxelGrid
from nav2_msgs.srv import GetCostmap
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from rclpy.node import Node
from sensor_msgs.msg import PointCloud2, PointField

from navseq.geometry import Pose2D, compose, inverse
from navseq.ros2.costmap_topics import (
    LATCHED,
    LOCAL_PERIOD,
    CostWindow,
    OccupancyGridUpdate,
    changed_bounds,
    costmap_msg,
    costmap_update_msg,
    local_window,
    occupancy_msg,
    occupancy_update_msg,
    same_area,
)
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.costmap_layers import (
    Z_RESOLUTION,
    Z_VOXELS,
    obstacle_layer,
    scan_hits,
    static_layer,
    voxel_columns,
)
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.scan import TURTLEBOT3_LDS, LaserSpec, ray_cast


class LayerPublisher:
    """One layer's four topics and its ``get_…`` service, as Nav2's Costmap2DPublisher."""

    def __init__(
        self, node: Node, topic: str, group: Any, now: Callable[[], CostWindow | None]
    ) -> None:
        self._grid = node.create_publisher(OccupancyGridMsg, topic, LATCHED)
        self._raw = node.create_publisher(CostmapMsg, f"{topic}_raw", LATCHED)
        self._raw_updates = node.create_publisher(CostmapUpdate, f"{topic}_raw_updates", LATCHED)
        self._updates = (
            None
            if OccupancyGridUpdate is None
            else node.create_publisher(OccupancyGridUpdate, f"{topic}_updates", LATCHED)
        )
        self._last: CostWindow | None = None
        self._now = now
        costmap, _, layer = topic.rpartition("/")
        node.create_service(
            GetCostmap, f"{costmap}/get_{layer}", self._answer, callback_group=group
        )
        self.stamp: Callable[[], Any] = lambda: None

    def publish(self, window: CostWindow, stamp: Any) -> None:
        """``window`` in full when it covers other cells than the last one (or is the
        first), else the box of cells that changed, if any — as Nav2's publisher does
        without ``always_send_full_costmap``."""
        previous = self._last
        self._last = CostWindow(window.cost.copy(), window.resolution, window.origin, window.frame)
        if previous is not None and same_area(previous, window):
            bounds = changed_bounds(previous.cost, window.cost)
            if bounds is not None:
                self._raw_updates.publish(costmap_update_msg(window, bounds, stamp))
                if self._updates is not None:
                    self._updates.publish(occupancy_update_msg(window, bounds, stamp))
            return
        self._grid.publish(occupancy_msg(window, stamp))
        self._raw.publish(costmap_msg(window, stamp))

    def _answer(self, _request: Any, response: Any) -> Any:
        window = self._now()
        if window is not None:
            response.map = costmap_msg(window, self.stamp())
        return response


class CostmapLayers:
    """The layers of both costmaps on ``node``, from ``standin``'s world under ``lock``."""

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
        sensor_height: float,
        spec: LaserSpec = TURTLEBOT3_LDS,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._stamp = stamp
        self._map_frame = map_frame
        self._odom_frame = odom_frame
        self._sensor_height = sensor_height
        self._spec = spec
        self._static_grid: OccupancyGrid | None = None  # the map the static layer shows
        self._hits = np.empty((0, 2))  # the last scan's marks (map frame)
        self._layers = {
            "static": LayerPublisher(
                node, "global_costmap/static_layer", group, self._locked(self._static_window)
            ),
            "obstacle": LayerPublisher(
                node, "global_costmap/obstacle_layer", group, self._locked(self._obstacle_window)
            ),
            "voxel": LayerPublisher(
                node, "local_costmap/voxel_layer", group, self._locked(self._voxel_window)
            ),
        }
        for layer in self._layers.values():
            layer.stamp = stamp
        self._voxel_pub = node.create_publisher(VoxelGrid, "local_costmap/voxel_grid", 1)
        self._endpoints_pub = node.create_publisher(
            PointCloud2, "local_costmap/clearing_endpoints", 1
        )
        node.create_timer(LOCAL_PERIOD, self.publish, callback_group=group)

    def publish(self) -> None:
        """The static layer when the map changed; the marks of a new scan."""
        with self._lock:
            world = self._standin.world
            new_map = world.grid is not self._static_grid
            self._static_grid = world.grid
            ranges = ray_cast(world.grid, world.robot.pose, self._spec, world.body.others)
            self._hits = scan_hits(ranges, self._spec, self._standin.localization.believed_pose)
            static = self._static_window() if new_map else None
            marks = obstacle_layer(world.grid, self._hits)
            obstacle = CostWindow(marks, world.grid.resolution, world.grid.origin, self._map_frame)
            voxel = self._voxel_window(marks)
            to_odom = inverse(self._standin.localization.estimate)
            hits = self._hits
        stamp = self._stamp()
        if static is not None:
            self._layers["static"].publish(static, stamp)
        self._layers["obstacle"].publish(obstacle, stamp)
        self._layers["voxel"].publish(voxel, stamp)
        self._voxel_pub.publish(self._voxel_msg(voxel, stamp))
        self._endpoints_pub.publish(self._endpoints_msg(hits, to_odom, stamp))

    def _locked(self, window: Callable[[], CostWindow]) -> Callable[[], CostWindow | None]:
        def now() -> CostWindow | None:
            with self._lock:
                return window()

        return now

    # -- the layers (call with the lock) -----------------------------------------------

    def _static_window(self) -> CostWindow:
        grid = self._standin.world.grid
        return CostWindow(static_layer(grid), grid.resolution, grid.origin, self._map_frame)

    def _obstacle_window(self) -> CostWindow:
        grid = self._standin.world.grid
        cost = obstacle_layer(grid, self._hits)
        return CostWindow(cost, grid.resolution, grid.origin, self._map_frame)

    def _voxel_window(self, marks: np.ndarray | None = None) -> CostWindow:
        """The voxel layer: the marks (``obstacle_layer``'s, made now if not given) in
        the local window."""
        grid = self._standin.world.grid
        if marks is None:
            marks = obstacle_layer(grid, self._hits)
        return local_window(marks, grid, self._standin.localization, self._odom_frame, fill=0)

    # -- messages ----------------------------------------------------------------------

    def _voxel_msg(self, window: CostWindow, stamp: Any) -> VoxelGrid:
        message = VoxelGrid()
        message.header.frame_id = window.frame
        message.header.stamp = stamp
        columns = voxel_columns(window.cost, self._sensor_height)
        message.size_y, message.size_x = (int(n) for n in columns.shape)
        message.size_z = Z_VOXELS
        message.data = [int(c) for c in columns.ravel()]  # index y * size_x + x
        message.origin = Point32(x=float(window.origin.x), y=float(window.origin.y), z=0.0)
        message.resolutions = Vector3(x=window.resolution, y=window.resolution, z=Z_RESOLUTION)
        return message

    def _endpoints_msg(self, hits: np.ndarray, to_odom: Pose2D, stamp: Any) -> PointCloud2:
        points = np.array(
            [
                (at.x, at.y, self._sensor_height)
                for at in (compose(to_odom, Pose2D(float(x), float(y), 0.0)) for x, y in hits)
            ],
            dtype=np.float32,
        ).reshape(-1, 3)
        message = PointCloud2()
        message.header.frame_id = self._odom_frame
        message.header.stamp = stamp
        message.height, message.width = 1, len(points)
        message.fields = [
            PointField(name=axis, offset=4 * index, datatype=PointField.FLOAT32, count=1)
            for index, axis in enumerate("xyz")
        ]
        message.is_bigendian = False
        message.point_step = 12
        message.row_step = 12 * len(points)
        message.is_dense = True
        message.data = points.tobytes()
        return message


__all__ = ["CostmapLayers", "LayerPublisher"]
