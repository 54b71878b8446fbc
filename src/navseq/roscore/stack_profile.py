"""The robot as a navigation stack's parameters describe it: one rule set for both ROS.

ROS 1's move_base keeps the robot on the parameter server under the action's namespace;
Nav2 keeps it in its nodes' parameters, which :mod:`navseq.ros2.nav2_params` turns into
the same tree. :func:`profile_from_navstack_params` reads that tree (a plain dict, no ROS):

- outline: ``footprint`` (a list of [x, y] points, or costmap_2d's string form
  ``"[[x, y], ...]"``) or else ``robot_radius``, looked up in ``global_costmap``, then
  ``local_costmap``, then the namespace itself (costmap_2d searches upwards the same way);
- inflation: ``inflation_radius`` and ``cost_scaling_factor``, in a costmap's
  ``inflation_layer`` or at its top level;
- local planner (the one ``base_local_planner`` names, else the first present of
  ``DWAPlannerROS``, ``TrajectoryPlannerROS``, ``TebLocalPlannerROS``):
  ``xy_goal_tolerance``, ``yaw_goal_tolerance``, ``max_vel_x``, ``max_vel_theta`` (or
  ``max_rot_vel``), ``acc_lim_x``, ``acc_lim_theta``.

What is found replaces the base profile's value (:func:`dataclasses.replace`); what is
missing keeps it. A value of the wrong kind is a :class:`NavseqError` naming the
parameter.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.robot import DEFAULT_PROFILE, GoalTolerance, RobotProfile, circle_footprint

Point = tuple[float, float]

COSTMAPS = ("global_costmap", "local_costmap", "")
LOCAL_PLANNERS = ("DWAPlannerROS", "TrajectoryPlannerROS", "TebLocalPlannerROS")
_PAIR = re.compile(r"\[([^\[\]]*)\]")


def profile_from_navstack_params(
    params: Mapping[str, Any],
    action_ns: str,
    base: RobotProfile = DEFAULT_PROFILE,
    *,
    where: str | None = None,
) -> tuple[RobotProfile, str]:
    """``base`` with what ``params`` (the tree under ``action_ns``) says; and a one-line note.

    The note says what was read, e.g. ``robot from /move_base parameters: footprint 4
    points, circumscribed 0.25 m, tolerance 0.05 m / 10°``; ``where`` names the
    parameters otherwise (Nav2's are read into the same tree by ``navseq.ros2.nav2_params``).
    """
    reader = _Reader(params, action_ns.rstrip("/") or "/")
    changes: dict[str, Any] = {}
    read: list[str] = []

    footprint = reader.footprint()
    if footprint is not None:
        points, described = footprint
        changes["footprint"] = points
        circumscribed = max(math.hypot(x, y) for x, y in points)
        read.append(f"{described}, circumscribed {circumscribed:.2f} m")

    inflation = reader.costmap_number("inflation_radius", minimum=0.0)
    if inflation is not None:
        changes["inflation_radius"] = inflation
    scaling = reader.costmap_number("cost_scaling_factor", minimum=0.0)
    if scaling is not None:
        changes["cost_scaling_factor"] = scaling
    if inflation is not None or scaling is not None:
        radius = changes.get("inflation_radius", base.inflation_radius)
        factor = changes.get("cost_scaling_factor", base.cost_scaling_factor)
        read.append(f"inflation {radius:g} m x {factor:g}")

    planner = reader.local_planner()
    if planner is not None:
        xy = reader.planner_number(planner, "xy_goal_tolerance", positive=True)
        yaw = reader.planner_number(planner, "yaw_goal_tolerance", positive=True)
        if xy is not None or yaw is not None:
            tolerance = GoalTolerance(
                xy if xy is not None else base.goal_tolerance.xy_m,
                yaw if yaw is not None else base.goal_tolerance.yaw_rad,
            )
            changes["goal_tolerance"] = tolerance
            read.append(f"tolerance {tolerance.xy_m:g} m / {math.degrees(tolerance.yaw_rad):.0f}°")
        speeds = {
            "max_linear_speed": reader.planner_number(planner, "max_vel_x", positive=True),
            "max_angular_speed": reader.planner_number(planner, "max_vel_theta", positive=True)
            or reader.planner_number(planner, "max_rot_vel", positive=True),
            "max_linear_accel": reader.planner_number(planner, "acc_lim_x", positive=True),
            "max_angular_accel": reader.planner_number(planner, "acc_lim_theta", positive=True),
        }
        found = {name: value for name, value in speeds.items() if value is not None}
        changes.update(found)
        if "max_linear_speed" in found or "max_angular_speed" in found:
            v = found.get("max_linear_speed", base.max_linear_speed)
            w = found.get("max_angular_speed", base.max_angular_speed)
            read.append(f"max {v:g} m/s / {w:g} rad/s")

    where = where if where is not None else f"{reader.ns} parameters"
    if not changes:
        return base, (
            f"no robot parameters in {where} (footprint, robot_radius, goal tolerance): "
            f"assuming {base.name}"
        )
    try:
        profile = dataclasses.replace(base, name=f"navstack:{reader.ns}", source=where, **changes)
    except ValueError as error:
        raise NavseqError(str(error), source=where) from None
    return profile, f"robot from {where}: " + ", ".join(read)


class _Reader:
    """Looks parameters up in the tree under the action namespace; names them in errors."""

    def __init__(self, params: Mapping[str, Any], ns: str):
        self.params = params
        self.ns = ns

    def _get(self, path: str) -> Any:
        node: Any = self.params
        for part in filter(None, path.split("/")):
            if not isinstance(node, Mapping) or part not in node:
                return None
            node = node[part]
        return node

    def _name(self, path: str) -> str:
        return f"param {self.ns.rstrip('/')}/{path}"

    def _number(self, path: str, *, minimum: float = 0.0, positive: bool = False) -> float | None:
        value = self._get(path)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise NavseqError(f"expected a number, got {value!r}", source=self._name(path))
        number = float(value)
        if not math.isfinite(number) or number < minimum or (positive and number <= 0):
            bound = "> 0" if positive else f">= {minimum:g}"
            raise NavseqError(f"expected a number {bound}, got {value!r}", source=self._name(path))
        return number

    def footprint(self) -> tuple[tuple[Point, ...], str] | None:
        for costmap in COSTMAPS:
            path = f"{costmap}/footprint" if costmap else "footprint"
            value = self._get(path)
            # costmap_2d's default footprint is "[]": it means "use robot_radius".
            if value is not None and value != [] and str(value).strip() != "[]":
                points = parse_footprint(value, self._name(path))
                return points, f"footprint {len(points)} points"
            radius_path = f"{costmap}/robot_radius" if costmap else "robot_radius"
            radius = self._number(radius_path, positive=True)
            if radius is not None:
                return circle_footprint(radius), f"robot_radius {radius:g} m"
        return None

    def costmap_number(self, name: str, *, minimum: float) -> float | None:
        for costmap in COSTMAPS:
            for layer in ("inflation_layer", ""):
                path = "/".join(part for part in (costmap, layer, name) if part)
                value = self._number(path, minimum=minimum)
                if value is not None:
                    return value
        return None

    def local_planner(self) -> str | None:
        chosen = self._get("base_local_planner")
        if isinstance(chosen, str) and "/" in chosen:
            name = chosen.rsplit("/", 1)[1]
            if isinstance(self._get(name), Mapping):
                return name
        for name in LOCAL_PLANNERS:
            if isinstance(self._get(name), Mapping):
                return name
        return None

    def planner_number(self, planner: str, name: str, *, positive: bool) -> float | None:
        return self._number(f"{planner}/{name}", positive=positive)


def parse_footprint(value: Any, where: str) -> tuple[Point, ...]:
    """costmap_2d's ``footprint``: a list of [x, y] or the string ``"[[x, y], ...]"``."""
    hint = "expected at least 3 points as [[x, y], [x, y], [x, y], ...] in metres"
    if isinstance(value, str):
        body = value.strip()
        if not (body.startswith("[") and body.endswith("]")) or _PAIR.sub("", body[1:-1]).strip(
            " ,\t\n"
        ):
            raise NavseqError(f"{hint}, got {value!r}", source=where)
        pairs: list[Any] = [pair.split(",") for pair in _PAIR.findall(body[1:-1])]
    elif isinstance(value, list):
        pairs = value
    else:
        raise NavseqError(f"{hint}, got {value!r}", source=where)
    points: list[Point] = []
    for pair in pairs:
        if not isinstance(pair, (list, tuple)) or len(pair) != 2:
            raise NavseqError(f"{hint}; {pair!r} is not one [x, y] point", source=where)
        try:
            x, y = (_coordinate(v) for v in pair)
        except ValueError:
            raise NavseqError(f"{hint}; {pair!r} is not one [x, y] point", source=where) from None
        points.append((x, y))
    if len(points) < 3:
        raise NavseqError(f"{hint}, got {len(points)} point(s)", source=where)
    return tuple(points)


def _coordinate(value: Any) -> float:
    if isinstance(value, bool):
        raise ValueError(value)
    number = float(value.strip() if isinstance(value, str) else value)
    if not math.isfinite(number):
        raise ValueError(value)
    return number
