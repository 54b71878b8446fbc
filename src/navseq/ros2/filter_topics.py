"""Nav2's costmap-filter topics on the ROS 2 simulator node (``--keepout``,
``--speed-mask``, ``--filters``).

The stand-in's planner, costmaps and controller read the masks from the map
(:mod:`navseq.sim.filters`); this module publishes what a Nav2 bringup with costmap
filters publishes around them, so that RViz and a Nav2 client see the same zones:

- per filter, what its ``filter_mask_server`` (a ``map_server``) and
  ``costmap_filter_info_server`` publish, both transient local as Nav2's: the mask
  (``nav_msgs/OccupancyGrid``) and its filter info (``nav2_msgs/CostmapFilterInfo``:
  type, mask topic, base, multiplier). Names as nav2_bringup's after Jazzy, whose
  params have a keepout and a speed filter (a default Jazzy bringup has none):
  ``keepout_filter_mask`` / ``keepout_costmap_filter_info`` and ``speed_filter_mask`` /
  ``speed_costmap_filter_info``; a second filter of a kind gets ``_2`` and so on;
- ``speed_limit`` (``nav2_msgs/SpeedLimit``), as Nav2's SpeedFilter publishes it: the
  limit under the robot (percent or m/s, as the filter's type says; 0 for none),
  published when it changes, checked five times a second. The node's own controller
  server hears it like any other ``speed_limit``.

Simplified: no lifecycle nodes of these servers' names (the topics come from the
simulator's node), and a mask is published once, as loaded, not re-read.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence
from typing import Any

from nav2_msgs.msg import CostmapFilterInfo, SpeedLimit
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from navseq.mission.costmap_filters import CostmapFilter, FilterType
from navseq.ros2.messages import grid_msg
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.occupancy import load_map

#: Seconds between two looks at the robot's speed zone (Nav2's SpeedFilter looks in its
#: costmap's updates: 5 Hz in nav2_bringup's local costmap, 1 Hz in the global one).
SPEED_CHECK_PERIOD = 0.2
#: SpeedLimit's "no limit", as Nav2's SpeedFilter publishes it.
NO_SPEED_LIMIT = 0.0
_LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def filter_topic_names(filters: Sequence[CostmapFilter]) -> list[tuple[str, str]]:
    """Each filter's (mask topic, filter info topic), as nav2_bringup names them."""
    names: list[tuple[str, str]] = []
    seen: dict[str, int] = {}
    for spec in filters:
        kind = "keepout" if spec.type is FilterType.KEEPOUT else "speed"
        seen[kind] = seen.get(kind, 0) + 1
        suffix = "" if seen[kind] == 1 else f"_{seen[kind]}"
        names.append((f"{kind}_filter_mask{suffix}", f"{kind}_costmap_filter_info{suffix}"))
    return names


def speed_limit_message_fields(limit: float, filter_type: FilterType | None) -> tuple[bool, float]:
    """SpeedLimit's (percentage, speed_limit) for one cell's limit (NaN: none)."""
    percentage = filter_type is not FilterType.SPEED_ABSOLUTE
    return percentage, NO_SPEED_LIMIT if math.isnan(limit) else float(limit)


class FilterTopics:
    """The masks, their filter info and the speed filter's ``speed_limit`` on ``node``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        filters: Sequence[CostmapFilter],
        stamp: Callable[[], Any],
        frame: str,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._log = node.get_logger()
        self._publishers: list[Any] = []  # kept: a latched message lives with its publisher
        stamped = stamp()
        for spec, (mask_topic, info_topic) in zip(
            filters, filter_topic_names(filters), strict=True
        ):
            mask_pub = node.create_publisher(OccupancyGridMsg, mask_topic, _LATCHED)
            info_pub = node.create_publisher(CostmapFilterInfo, info_topic, _LATCHED)
            mask_pub.publish(grid_msg(load_map(spec.mask), frame, stamped))
            info = CostmapFilterInfo()
            info.header.frame_id = frame
            info.header.stamp = stamped
            info.type = int(spec.type)
            info.filter_mask_topic = node.resolve_topic_name(mask_topic)
            info.base = float(spec.base)
            info.multiplier = float(spec.multiplier)
            info_pub.publish(info)
            self._publishers += [mask_pub, info_pub]
        speed_types = [spec.type for spec in filters if spec.type is not FilterType.KEEPOUT]
        # The map's filters hold one speed limit per cell: the last speed filter's type.
        self._speed_type = speed_types[-1] if speed_types else None
        self._last_limit: float | None = None
        self._speed_pub = None
        if self._speed_type is not None:
            self._speed_pub = node.create_publisher(SpeedLimit, "speed_limit", 10)
            node.create_timer(SPEED_CHECK_PERIOD, self._check_speed_zone, callback_group=group)

    def _check_speed_zone(self) -> None:
        """Publish the limit under the robot when it is not the last one published."""
        with self._lock:
            world = self._standin.world
            grid, pose = world.grid, world.robot.pose
        zones = grid.filters
        if zones is None or zones.speed_limit is None or self._speed_pub is None:
            return
        row, col = grid.world_to_cell(pose.x, pose.y)
        limit = float(zones.speed_limit[row, col]) if grid.in_bounds(row, col) else math.nan
        percentage, value = speed_limit_message_fields(limit, self._speed_type)
        if value == self._last_limit or (self._last_limit is None and value == NO_SPEED_LIMIT):
            return
        self._last_limit = value
        message = SpeedLimit()
        message.percentage = percentage
        message.speed_limit = value
        self._speed_pub.publish(message)


__all__ = ["FilterTopics", "filter_topic_names", "speed_limit_message_fields"]
