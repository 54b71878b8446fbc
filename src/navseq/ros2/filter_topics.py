"""Nav2's costmap-filter topics on the ROS 2 simulator node (``--keepout``,
``--speed-mask``, ``--filters``).

The stand-in's planner, costmaps and controller read the masks from the map
(:mod:`navseq.sim.filters`); this module publishes what a Nav2 bringup with costmap
filters publishes around them, so that RViz and a Nav2 client see the same zones:

- per filter, its ``filter_mask_server`` (a ``map_server``) and
  ``costmap_filter_info_server``, lifecycle nodes as Nav2's, each publishing when it is
  activated, transient local: the mask (``nav_msgs/OccupancyGrid``) and its filter info
  (``nav2_msgs/CostmapFilterInfo``: type, mask topic, base, multiplier); the mask server
  answers ``<name>/map`` (``nav_msgs/srv/GetMap``) while active. Names as nav2_bringup's
  after Jazzy (``keepout_zone_launch.py``, ``speed_zone_launch.py``; a default Jazzy
  bringup has no filter): the nodes ``keepout_filter_mask_server`` and
  ``keepout_costmap_filter_info_server`` under ``lifecycle_manager_keepout_zone``, the
  topics ``keepout_filter_mask`` and ``keepout_costmap_filter_info``; ``speed_...`` and
  ``lifecycle_manager_speed_zone`` likewise. A second filter of a kind gets ``_2`` on its
  nodes and topics, and so on, under the same manager. The nodes carry the parameters
  Nav2's take (``topic_name`` and ``yaml_filename``; ``type``, ``filter_info_topic``,
  ``mask_topic``, ``base``, ``multiplier``);
- ``speed_limit`` (``nav2_msgs/SpeedLimit``), as Nav2's SpeedFilter publishes it: the
  limit under the robot (percent or m/s, as the filter's type says; 0 for none),
  published when it changes, checked five times a second. The node's own controller
  server hears it like any other ``speed_limit``.

Simplified: a mask is loaded once, at start: an activation publishes it again as loaded
(``load_map`` on a mask server is not served), and a cleanup does not withdraw a message
already published (Nav2 destroys its publishers there: a late subscriber gets nothing).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from nav2_msgs.msg import CostmapFilterInfo, SpeedLimit
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.srv import GetMap
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from navseq.mission.costmap_filters import CostmapFilter, FilterType
from navseq.ros2.lifecycle import Nav2Lifecycle
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


#: The lifecycle manager of each kind's servers, as nav2_bringup names it.
FILTER_MANAGERS = {
    "keepout": "lifecycle_manager_keepout_zone",
    "speed": "lifecycle_manager_speed_zone",
}


@dataclass(frozen=True)
class FilterNames:
    """One filter's topics and servers, as nav2_bringup names them."""

    kind: str  # "keepout" or "speed"
    mask_topic: str
    info_topic: str
    mask_server: str
    info_server: str


def filter_names(filters: Sequence[CostmapFilter]) -> list[FilterNames]:
    """Each filter's names (a second of a kind ``_2`` and so on)."""
    names: list[FilterNames] = []
    seen: dict[str, int] = {}
    for spec in filters:
        kind = "keepout" if spec.type is FilterType.KEEPOUT else "speed"
        seen[kind] = seen.get(kind, 0) + 1
        suffix = "" if seen[kind] == 1 else f"_{seen[kind]}"
        names.append(
            FilterNames(
                kind,
                f"{kind}_filter_mask{suffix}",
                f"{kind}_costmap_filter_info{suffix}",
                f"{kind}_filter_mask_server{suffix}",
                f"{kind}_costmap_filter_info_server{suffix}",
            )
        )
    return names


def filter_topic_names(filters: Sequence[CostmapFilter]) -> list[tuple[str, str]]:
    """Each filter's (mask topic, filter info topic), as nav2_bringup names them."""
    return [(n.mask_topic, n.info_topic) for n in filter_names(filters)]


def filter_lifecycle_groups(filters: Sequence[CostmapFilter]) -> list[tuple[str, list[str]]]:
    """(lifecycle manager, the servers it manages, mask server before its info server)
    per kind of filter given, keepout first, as nav2_bringup's launch files pair them."""
    groups: dict[str, list[str]] = {}
    for n in filter_names(filters):
        groups.setdefault(n.kind, []).extend([n.mask_server, n.info_server])
    return [(FILTER_MANAGERS[kind], groups[kind]) for kind in FILTER_MANAGERS if kind in groups]


def filter_server_parameters(
    filters: Sequence[CostmapFilter], namespace: str | None
) -> dict[str, list[Parameter]]:
    """The parameters Nav2's filter servers take, by server name (topics fully named)."""
    ns = f"/{namespace.strip('/')}" if namespace and namespace.strip("/") else ""
    parameters: dict[str, list[Parameter]] = {}
    for spec, n in zip(filters, filter_names(filters), strict=True):
        parameters[n.mask_server] = [
            Parameter("topic_name", value=n.mask_topic),
            Parameter("yaml_filename", value=str(spec.mask)),
        ]
        parameters[n.info_server] = [
            Parameter("type", value=int(spec.type)),
            Parameter("filter_info_topic", value=f"{ns}/{n.info_topic}"),
            Parameter("mask_topic", value=f"{ns}/{n.mask_topic}"),
            Parameter("base", value=float(spec.base)),
            Parameter("multiplier", value=float(spec.multiplier)),
        ]
    return parameters


def speed_limit_message_fields(limit: float, filter_type: FilterType | None) -> tuple[bool, float]:
    """SpeedLimit's (percentage, speed_limit) for one cell's limit (NaN: none)."""
    percentage = filter_type is not FilterType.SPEED_ABSOLUTE
    return percentage, NO_SPEED_LIMIT if math.isnan(limit) else float(limit)


class FilterTopics:
    """The filter servers' masks and filter info (published by the servers in
    ``lifecycle`` when activated), and the speed filter's ``speed_limit`` on ``node``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        lifecycle: Nav2Lifecycle,
        *,
        filters: Sequence[CostmapFilter],
        stamp: Callable[[], Any],
        frame: str,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._log = node.get_logger()
        self._publishers: list[Any] = []  # kept: a latched message lives with its publisher
        for spec, names in zip(filters, filter_names(filters), strict=True):
            self._serve(lifecycle, group, spec, names, stamp, frame)
        speed_types = [spec.type for spec in filters if spec.type is not FilterType.KEEPOUT]
        # The map's filters hold one speed limit per cell: the last speed filter's type.
        self._speed_type = speed_types[-1] if speed_types else None
        self._last_limit: float | None = None
        self._speed_pub = None
        if self._speed_type is not None:
            self._speed_pub = node.create_publisher(SpeedLimit, "speed_limit", 10)
            node.create_timer(SPEED_CHECK_PERIOD, self._check_speed_zone, callback_group=group)

    def _serve(
        self,
        lifecycle: Nav2Lifecycle,
        group: Any,
        spec: CostmapFilter,
        names: FilterNames,
        stamp: Callable[[], Any],
        frame: str,
    ) -> None:
        """One filter's two servers: each publishes at its activation, as Nav2's
        map_server and costmap_filter_info_server do in on_activate."""
        mask_server = lifecycle.servers[names.mask_server]
        info_server = lifecycle.servers[names.info_server]
        mask = load_map(spec.mask)
        mask_pub = mask_server.create_publisher(OccupancyGridMsg, names.mask_topic, _LATCHED)
        info_pub = info_server.create_publisher(CostmapFilterInfo, names.info_topic, _LATCHED)
        mask_topic = mask_server.resolve_topic_name(names.mask_topic)

        def publish_mask() -> None:
            mask_pub.publish(grid_msg(mask, frame, stamp()))

        def publish_info() -> None:
            info = CostmapFilterInfo()
            info.header.frame_id = frame
            info.header.stamp = stamp()
            info.type = int(spec.type)
            info.filter_mask_topic = mask_topic
            info.base = float(spec.base)
            info.multiplier = float(spec.multiplier)
            info_pub.publish(info)

        def get_mask(_request: Any, response: Any) -> Any:
            # Nav2's map_server fills nothing in while it is not active.
            if not lifecycle.is_active(names.mask_server):
                mask_server.get_logger().warning(
                    "Received GetMap request but not in ACTIVE state, ignoring!"
                )
                return response
            response.map = grid_msg(mask, frame, stamp())
            return response

        mask_server.when_activated(publish_mask)
        info_server.when_activated(publish_info)
        mask_server.create_service(
            GetMap, f"{names.mask_server}/map", get_mask, callback_group=group
        )
        self._publishers += [mask_pub, info_pub]

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


__all__ = [
    "FILTER_MANAGERS",
    "FilterNames",
    "FilterTopics",
    "filter_lifecycle_groups",
    "filter_names",
    "filter_server_parameters",
    "filter_topic_names",
    "speed_limit_message_fields",
]
