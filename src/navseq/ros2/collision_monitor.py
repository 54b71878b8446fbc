"""Nav2's collision monitor on the ROS 2 simulator node.

The rules are :mod:`navseq.sim.collision_monitor` (in the stand-in's velocity chain,
between ``cmd_vel_smoothed`` and ``cmd_vel``); this module gives them Nav2's interface,
on the ``collision_monitor`` lifecycle node:

- ``collision_monitor_state`` (``nav2_msgs/CollisionMonitorState``): the action and the
  polygon that acts, each time that polygon changes (``FootprintApproach`` / APPROACH
  when the robot slows before an obstacle, "" / DO_NOTHING when it goes on freely);
- ``collision_monitor/collision_points_marker`` (``visualization_msgs/MarkerArray``): the
  points the monitor checked, one ``POINTS`` marker per source
  (``collision_points_scan``) in the robot's base frame, while commands go through and
  someone listens — as Nav2 publishes it;
- ``collision_monitor/toggle`` (``nav2_msgs/srv/Toggle``): ``enable`` false lets every
  command through unchanged, true checks them again;
- ``cmd_vel_smoothed`` from outside while no goal or behaviour drives: teleop through
  the monitor (Nav2's monitor subscribes that topic; ``cmd_vel`` goes past it).

The polygons are the node's parameters under Nav2's names (``polygons``, and for each
``type`` polygon / circle, ``action_type``, ``points`` or ``footprint_topic``,
``radius``, ``min_points``, ``slowdown_ratio``, ``linear_limit``, ``angular_limit``,
``time_before_collision``, ``simulation_time_step``, ``enabled``), so a Nav2 params
file given to ``python -m navseq.ros2.sim_node`` with ``--ros-args --params-file``
configures it; without them,
nav2_bringup's ``FootprintApproach``. A circle is checked as a 32-sided polygon. While
the node is not active nothing passes on: the robot stops, as without Nav2's monitor.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import yaml
from geometry_msgs.msg import Point, Twist
from nav2_msgs.msg import CollisionMonitorState
from nav2_msgs.srv import Toggle
from rclpy.node import Node
from visualization_msgs.msg import Marker, MarkerArray

from navseq.ros2.standin import Nav2StandIn
from navseq.sim.collision_monitor import (
    ACTION_NAMES,
    ActionType,
    MonitorPolygon,
    Verdict,
    nav2_bringup_polygons,
)

CIRCLE_SIDES = 32
QUIET = 0.5  # s of wall time after our own cmd_vel_smoothed before outside commands count


class CollisionMonitorTopics:
    """The monitor's state, markers, toggle and ``cmd_vel_smoothed`` input on ``node``
    (the ``collision_monitor`` lifecycle node)."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        active: Callable[[], bool],
        own_smoothed: Callable[[], float],
        base_frame: str,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._own_smoothed = own_smoothed
        self._base_frame = base_frame
        self._log = node.get_logger()
        stage = standin.monitor
        stage.active = active
        stage.monitor.polygons = polygons_of(node, self._log.error)
        enabled = node.get_parameter_or("enabled", None).value
        stage.monitor.enabled = True if enabled is None else bool(enabled)
        self._state_pub = node.create_publisher(
            CollisionMonitorState, "collision_monitor_state", 10
        )
        self._marker_pub = node.create_publisher(MarkerArray, "~/collision_points_marker", 10)
        node.create_service(Toggle, "~/toggle", self._toggle, callback_group=group)
        node.create_subscription(
            Twist, "cmd_vel_smoothed", self._on_smoothed, 10, callback_group=group
        )

    def publish(self) -> None:
        """The state when the acting polygon changed; the points when commands went
        through (call after a simulation step)."""
        with self._lock:
            stage = self._standin.monitor
            changes, stage.monitor.changes = stage.monitor.changes, []
            polygons = stage.monitor.polygons
            points = stage.points if stage.checked else None
            stage.checked = False
        for verdict in changes:
            self._state_pub.publish(state_msg(verdict))
            self._log.info(said(verdict, polygons))
        if points is not None and self._marker_pub.get_subscription_count() > 0:
            self._marker_pub.publish(points_marker(points, self._base_frame))

    def _toggle(self, request: Any, response: Any) -> Any:
        with self._lock:
            self._standin.monitor.monitor.enabled = bool(request.enable)
        response.success = True
        response.message = (
            f"Collision monitor toggled {'on' if request.enable else 'off'} successfully"
        )
        self._log.info(response.message)
        return response

    def _on_smoothed(self, message: Twist) -> None:
        if time.monotonic() - self._own_smoothed() < QUIET:
            return  # our own chain's command, heard back
        with self._lock:
            self._standin.command_smoothed(float(message.linear.x), float(message.angular.z))


def said(verdict: Verdict, polygons: tuple[MonitorPolygon, ...]) -> str:
    """Nav2's log line for a new state."""
    polygon = next((p for p in polygons if p.name == verdict.polygon), None)
    if polygon is None:
        return "Robot to continue normal operation"
    if verdict.action is ActionType.SLOWDOWN:
        return (
            f"Robot to slowdown for {polygon.slowdown_ratio * 100:f} percents due to "
            f"{polygon.name} polygon"
        )
    if verdict.action is ActionType.APPROACH:
        return (
            f"Robot to approach for {polygon.time_before_collision:f} seconds away from collision"
        )
    verb = "limit speed" if verdict.action is ActionType.LIMIT else "stop"
    return f"Robot to {verb} due to {polygon.name} polygon"


def state_msg(verdict: Verdict) -> CollisionMonitorState:
    message = CollisionMonitorState()
    message.action_type = int(verdict.action)
    message.polygon_name = verdict.polygon
    return message


def points_marker(points: np.ndarray, frame: str) -> MarkerArray:
    """Nav2's ``collision_points_marker``: the scan's points, red, 2 cm."""
    marker = Marker()
    marker.header.frame_id = frame
    marker.ns = "collision_points_scan"
    marker.id = 0
    marker.type = Marker.POINTS
    marker.action = Marker.ADD
    marker.scale.x = marker.scale.y = 0.02
    marker.color.r = marker.color.a = 1.0
    marker.frame_locked = True
    marker.points = [Point(x=float(x), y=float(y), z=0.0) for x, y in points]
    return MarkerArray(markers=[marker])


def polygons_of(node: Node, error: Callable[[str], None]) -> tuple[MonitorPolygon, ...]:
    """The polygons the node's parameters describe; nav2_bringup's without any (and,
    logged, when they cannot be read)."""
    names = node.get_parameter_or("polygons", None).value
    if not names:
        return nav2_bringup_polygons()
    try:
        return tuple(_polygon(node, str(name)) for name in names)
    except ValueError as problem:
        error(f"collision_monitor: {problem}; using nav2_bringup's FootprintApproach")
        return nav2_bringup_polygons()


def _polygon(node: Node, name: str) -> MonitorPolygon:
    def value(key: str, default: Any) -> Any:
        found = node.get_parameter_or(f"{name}.{key}", None).value
        return default if found is None else found

    kind = value("type", "polygon")
    action = ACTION_NAMES.get(str(value("action_type", "")))
    if action is None:
        raise ValueError(f"{name}.action_type must be one of {', '.join(ACTION_NAMES)}")
    outline: np.ndarray | None
    if kind == "circle":
        radius = float(value("radius", 0.0))
        if radius <= 0.0:
            raise ValueError(f"{name}.radius must be positive")
        angles = np.linspace(0.0, 2.0 * math.pi, CIRCLE_SIDES, endpoint=False)
        outline = np.column_stack((radius * np.cos(angles), radius * np.sin(angles)))
    elif kind == "polygon":
        outline = _outline(name, value("points", None), value("footprint_topic", ""))
    else:
        raise ValueError(f"{name}.type {kind!r} is not polygon or circle")
    return MonitorPolygon(
        name,
        action,
        outline,
        min_points=int(value("min_points", 4)),
        slowdown_ratio=float(value("slowdown_ratio", 0.5)),
        linear_limit=float(value("linear_limit", 0.5)),
        angular_limit=float(value("angular_limit", 0.5)),
        time_before_collision=float(value("time_before_collision", 2.0)),
        simulation_time_step=float(value("simulation_time_step", 0.1)),
        enabled=bool(value("enabled", True)),
    )


def _outline(name: str, points: Any, footprint_topic: str) -> np.ndarray | None:
    """``points`` as Jazzy writes it (a string "[[x, y], ...]") or as a flat list of
    numbers; None (the robot's footprint) with a ``footprint_topic`` instead."""
    if points is None:
        if footprint_topic:
            return None
        raise ValueError(f"{name} has neither points nor footprint_topic")
    if isinstance(points, str):
        try:
            points = yaml.safe_load(points)
        except yaml.YAMLError:
            points = None
    try:
        outline = np.asarray(points, dtype=float).reshape(-1, 2)
    except (TypeError, ValueError):
        raise ValueError(f"{name}.points is not a list of [x, y] pairs") from None
    if len(outline) < 3:
        raise ValueError(f"{name}.points needs at least 3 points")
    return outline


__all__ = ["CollisionMonitorTopics", "points_marker", "polygons_of", "state_msg"]
