"""Reading a robot profile: a mission's ``robot:`` section or a ``--robot`` name or file.

Either a built-in name (``turtlebot3_waffle``) or a mapping::

    robot:
      base: turtlebot3_waffle      # optional; the default profile otherwise
      footprint: [[-0.2, -0.15], [-0.2, 0.15], [0.08, 0.15], [0.08, -0.15]]
      # or radius: 0.2             (a round robot)
      inflation_radius: 0.8        # m
      cost_scaling_factor: 3.0     # 1/m
      clearance_margin: 0.03       # m kept beyond the outline where the robot must turn
      max_linear_speed: 0.3        # m/s
      max_angular_speed: 90        # deg/s (degrees in files, like yaw)
      max_linear_accel: 2.5        # m/s²
      max_angular_accel: 180       # deg/s²
      xy_goal_tolerance: 0.05      # m
      yaw_goal_tolerance: 10       # degrees

A ``--robot`` file holds the same mapping (or a name). Every bad value is reported
with file:line and field; an unknown name names the closest known one.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.mission import fields
from navseq.mission.located import Located, describe
from navseq.mission.problems import Problems, closest_hint
from navseq.mission.reading import read_mission_text
from navseq.mission.robot import (
    BUILTIN_PROFILES,
    DEFAULT_PROFILE,
    GoalTolerance,
    RobotProfile,
    circle_footprint,
)
from navseq.mission.yaml_doc import parse_yaml

if TYPE_CHECKING:
    from navseq.mission.model import Mission

# file key -> (RobotProfile field, unit shown in messages, factor from file to profile units)
_NUMBER_KEYS: dict[str, tuple[str, str, float]] = {
    "inflation_radius": ("inflation_radius", " m", 1.0),
    "cost_scaling_factor": ("cost_scaling_factor", " 1/m", 1.0),
    "clearance_margin": ("clearance_margin_m", " m", 1.0),
    "max_linear_speed": ("max_linear_speed", " m/s", 1.0),
    "max_angular_speed": ("max_angular_speed", " deg/s", math.pi / 180.0),
    "max_linear_accel": ("max_linear_accel", " m/s²", 1.0),
    "max_angular_accel": ("max_angular_accel", " deg/s²", math.pi / 180.0),
}
# Limits the robot cannot move without: zero would leave it standing.
_POSITIVE_KEYS = {
    "max_linear_speed",
    "max_angular_speed",
    "max_linear_accel",
    "max_angular_accel",
}
ROBOT_KEYS = (
    "base",
    "name",
    "footprint",
    "radius",
    *_NUMBER_KEYS,
    "xy_goal_tolerance",
    "yaw_goal_tolerance",
)


def read_robot(node: Located, subject: str = "field robot") -> RobotProfile:
    """The profile a ``robot:`` value describes; NavseqError (all problems) if bad."""
    if isinstance(node.value, str):
        return builtin_profile(node.value, node.where, subject, node.where)
    if not node.is_mapping:
        raise NavseqError(
            f"must be a robot name ({', '.join(BUILTIN_PROFILES)}) or a mapping "
            f"with base: and overrides, got {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
    problems = Problems()
    fields.check_keys(node, ROBOT_KEYS, "robot", problems)
    base = DEFAULT_PROFILE
    base_node = node.get("base")
    if base_node is not None:
        read = fields.attempt(
            problems,
            lambda: builtin_profile(
                fields.text(base_node, "robot, field base"),
                base_node.where,
                "robot, field base",
                node.where,
            ),
        )
        base = read or base
    changes: dict[str, Any] = {"source": node.where}
    name_node = node.get("name")
    if name_node is not None:
        name = fields.attempt(problems, lambda: fields.text(name_node, "robot, field name"))
        if name is not None:
            changes["name"] = name
    elif len(node.value) > (1 if base_node is not None else 0):
        changes["name"] = f"{base.name} (modified)"
    footprint = _read_outline(node, problems)
    if footprint is not None:
        changes["footprint"] = footprint
    for key, (attribute, unit, factor) in _NUMBER_KEYS.items():
        entry = node.get(key)
        if entry is None:
            continue
        value = fields.attempt(
            problems,
            functools.partial(
                fields.bounded_number,
                entry,
                f"robot, field {key}",
                minimum=0.0,
                inclusive=key not in _POSITIVE_KEYS,
                unit=unit,
            ),
        )
        if value is not None:
            changes[attribute] = value * factor
    tolerance = _read_tolerance(node, base.goal_tolerance, problems)
    if tolerance is not None:
        changes["goal_tolerance"] = tolerance
    problems.raise_if_any()
    return base.with_changes(**changes)


def builtin_profile(name: str, where: str | None, subject: str, source: str | None) -> RobotProfile:
    """The built-in profile called ``name``, or an error naming the closest known one."""
    profile = BUILTIN_PROFILES.get(name.strip())
    if profile is None:
        # A likely typo is named; the list of robots is given once, after it. A long
        # "name" (a file that is not a robot file) is shown cut short.
        typo = closest_hint(name, BUILTIN_PROFILES)
        typo = typo if "did you mean" in typo else ""
        shown = name if len(name) <= 60 else f"{name[:57]}..."
        raise NavseqError(
            f"unknown robot {shown!r}{typo}; built-in robots: "
            f"{', '.join(BUILTIN_PROFILES)} (or give a mapping with base: and overrides)",
            source=where,
            subject=subject,
        )
    return profile.with_changes(source=source or "built-in")


def robot_from_option(text: str) -> RobotProfile:
    """``--robot NAME|FILE``: a built-in name, else a YAML file holding a name or a mapping."""
    if text.strip() in BUILTIN_PROFILES:
        return builtin_profile(text, None, "--robot", "--robot")
    path = Path(text)
    looks_like_file = path.suffix.lower() in (".yaml", ".yml") or path.exists()
    if not looks_like_file:
        raise NavseqError(
            f"{text!r} is neither a built-in robot{closest_hint(text, BUILTIN_PROFILES)} "
            "nor a robot YAML file",
            source="--robot",
        )
    return read_robot_file(path)


def choose_robot(option: str | RobotProfile | None, mission: Mission | None) -> RobotProfile:
    """The robot to plan and check for: ``--robot`` > the mission's ``robot:`` > default.

    ``--robot`` (a built-in name or a file) is read here, not by argparse, so that a bad
    name or file is one NavseqError (exit 2) like every other input problem. The Python
    API may pass a :class:`RobotProfile` itself.
    """
    if isinstance(option, RobotProfile):
        return option
    if option is not None:
        return robot_from_option(option)
    if mission is not None and mission.robot is not None:
        return mission.robot
    return DEFAULT_PROFILE


def read_robot_file(path: Path) -> RobotProfile:
    """A robot YAML file: the mapping of a ``robot:`` section (or a name), or a document
    with a ``robot:`` key (a mission's section copied as it is)."""
    source = str(path)
    problems = Problems()
    doc = parse_yaml(read_mission_text(path), source, problems)
    problems.raise_if_any()
    if doc is None:
        raise NavseqError(
            "is empty; a robot file holds a robot name or a mapping (base:, footprint: ...)",
            source=source,
        )
    if doc.is_mapping and set(doc.value) == {"robot"}:
        doc = doc.value["robot"]
    return read_robot(doc, "robot")


def _read_outline(node: Located, problems: Problems) -> tuple[tuple[float, float], ...] | None:
    footprint_node, radius_node = node.get("footprint"), node.get("radius")
    if footprint_node is not None and radius_node is not None:
        problems.add(
            "give either footprint: (a polygon) or radius: (a round robot), not both",
            source=radius_node.where,
            subject="robot, field radius",
        )
        return None
    if radius_node is not None:
        radius = fields.attempt(
            problems,
            lambda: fields.bounded_number(
                radius_node, "robot, field radius", minimum=0.0, inclusive=False, unit=" m"
            ),
        )
        return None if radius is None else circle_footprint(radius)
    if footprint_node is not None:
        return fields.attempt(problems, lambda: read_footprint(footprint_node))
    return None


def read_footprint(
    node: Located, subject: str = "robot, field footprint"
) -> tuple[tuple[float, float], ...]:
    """``[[x, y], ...]``: at least 3 points (robot frame, metres) enclosing the centre."""
    items = fields.sequence(node, subject)
    if len(items) < 3:
        raise NavseqError(
            f"a footprint needs at least 3 points [[x, y], ...], got {len(items)}",
            source=node.where,
            subject=subject,
        )
    points: list[tuple[float, float]] = []
    for number, item in enumerate(items, start=1):
        point_subject = f"{subject}, point {number}"
        if not item.is_list or len(item.value) != 2:
            raise NavseqError(
                f"must be a point [x, y] in metres, got {describe(item.value)}",
                source=item.where,
                subject=point_subject,
            )
        x, y = (fields.number(value, point_subject) for value in item.value)
        points.append((x, y))
    if not _encloses_origin(points):
        raise NavseqError(
            "the polygon must enclose the robot centre (0, 0) with some area: points are "
            "in the robot frame, x forward, y left, metres",
            source=node.where,
            subject=subject,
        )
    return tuple(points)


def _read_tolerance(node: Located, base: GoalTolerance, problems: Problems) -> GoalTolerance | None:
    xy_node, yaw_node = node.get("xy_goal_tolerance"), node.get("yaw_goal_tolerance")
    if xy_node is None and yaw_node is None:
        return None
    xy, yaw = base.xy_m, base.yaw_rad
    if xy_node is not None:
        xy = (
            fields.attempt(
                problems,
                lambda: fields.bounded_number(
                    xy_node,
                    "robot, field xy_goal_tolerance",
                    minimum=0.0,
                    inclusive=False,
                    unit=" m",
                ),
            )
            or xy
        )
    if yaw_node is not None:
        degrees = fields.attempt(
            problems,
            lambda: fields.bounded_number(
                yaw_node,
                "robot, field yaw_goal_tolerance",
                minimum=0.0,
                inclusive=False,
                unit=" degrees",
            ),
        )
        if degrees is not None and degrees > 180.0:
            problems.add(
                f"must be <= 180 degrees, got {degrees:g}",
                source=yaw_node.where,
                subject="robot, field yaw_goal_tolerance",
            )
        elif degrees is not None:
            yaw = math.radians(degrees)
    return GoalTolerance(xy, yaw)


def _encloses_origin(points: list[tuple[float, float]]) -> bool:
    """True if the robot centre (0, 0) lies inside the polygon, which has some area."""
    count = len(points)
    area = 0.0
    inside = False
    for index in range(count):
        (ax, ay), (bx, by) = points[index], points[(index + 1) % count]
        area += ax * by - bx * ay
        if (ay > 0.0) != (by > 0.0) and ax + (0.0 - ay) * (bx - ax) / (by - ay) > 0.0:
            inside = not inside  # a ray from the origin along +x crosses this edge
    return inside and abs(area) > 1e-12


__all__ = [
    "ROBOT_KEYS",
    "builtin_profile",
    "choose_robot",
    "read_robot",
    "read_robot_file",
    "robot_from_option",
]
