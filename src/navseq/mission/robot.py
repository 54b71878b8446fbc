"""The robot a mission is run with: outline, clearance, speeds and goal tolerances.

Every rule that depends on the robot's size or speed — pre-flight, the planner, the
"nearest free spot" hint, the simulator, the ETA, the picture and the arrival check —
takes a :class:`RobotProfile` instead of assuming the TurtleBot3 burger. Profiles are
plain data (no numpy, no ROS): built-in ones are listed in :data:`BUILTIN_PROFILES`,
a mission's ``robot:`` section, a ``--robot`` file or a running move_base's parameters
make others.

Units: metres, seconds, radians. The footprint is a polygon in the robot frame (x
forward, y left), as costmap_2d's ``footprint`` parameter; a round robot is given by
its radius and gets a polygon that circumscribes nothing larger than that radius.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

Point = tuple[float, float]


@dataclass(frozen=True)
class GoalTolerance:
    """How close counts as arrived: position (m) and heading (rad), as move_base's
    ``xy_goal_tolerance`` / ``yaw_goal_tolerance``."""

    xy_m: float = 0.05
    yaw_rad: float = 0.17


@dataclass(frozen=True)
class RobotProfile:
    """One robot's geometry and limits.

    ``footprint`` is the outline (at least 3 points, robot frame, metres).
    ``inflation_radius`` and ``cost_scaling_factor`` are costmap_2d's inflation layer
    settings; ``clearance_margin_m`` is extra room kept beyond the circumscribed radius
    where a pose must be safe (suggested spots, goals the robot must turn at).
    ``source`` says where the profile came from, for messages and the report.
    """

    name: str
    footprint: tuple[Point, ...]
    max_linear_speed: float = 0.22  # m/s
    max_angular_speed: float = 2.75  # rad/s
    max_linear_accel: float = 2.5  # m/s²
    max_angular_accel: float = 3.2  # rad/s²
    goal_tolerance: GoalTolerance = field(default_factory=GoalTolerance)
    inflation_radius: float = 1.0  # m
    cost_scaling_factor: float = 3.0  # 1/m
    clearance_margin_m: float = 0.02
    source: str = field(default="built-in", compare=False)

    def __post_init__(self) -> None:
        if len(self.footprint) < 3:
            raise ValueError("a footprint needs at least 3 points")
        for name in (
            "max_linear_speed",
            "max_angular_speed",
            "max_linear_accel",
            "max_angular_accel",
            "inflation_radius",
            "cost_scaling_factor",
            "clearance_margin_m",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")

    @property
    def circumscribed_radius(self) -> float:
        """Distance from the robot centre to its farthest footprint point (m)."""
        return max(math.hypot(x, y) for x, y in self.footprint)

    @property
    def inscribed_radius(self) -> float:
        """Distance from the robot centre to the nearest footprint edge (m)."""
        return min(
            _distance_to_segment(a, b)
            for a, b in zip(self.footprint, self.footprint[1:] + self.footprint[:1], strict=True)
        )

    def with_changes(self, **changes: Any) -> RobotProfile:
        return replace(self, **changes)


def circle_footprint(radius: float, sides: int = 16) -> tuple[Point, ...]:
    """A regular polygon with its vertices on a circle of ``radius`` (a round robot)."""
    return tuple(
        (radius * math.cos(2.0 * math.pi * k / sides), radius * math.sin(2.0 * math.pi * k / sides))
        for k in range(sides)
    )


def _distance_to_segment(a: Point, b: Point) -> float:
    """Distance from the origin to the segment a-b."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    length_squared = ex * ex + ey * ey
    t = (
        0.0
        if length_squared == 0.0
        else max(0.0, min(1.0, -(a[0] * ex + a[1] * ey) / length_squared))
    )
    return math.hypot(a[0] + t * ex, a[1] + t * ey)


# ROBOTIS' turtlebot3_navigation parameters (costmap_common_params_*.yaml and
# dwa_local_planner_params_*.yaml).
TURTLEBOT3_BURGER = RobotProfile(
    name="turtlebot3_burger",
    footprint=((-0.105, -0.105), (-0.105, 0.105), (0.041, 0.105), (0.041, -0.105)),
    max_linear_speed=0.22,
    max_angular_speed=2.75,
    max_linear_accel=2.5,
    max_angular_accel=3.2,
    goal_tolerance=GoalTolerance(0.05, 0.17),
    inflation_radius=1.0,
    cost_scaling_factor=3.0,
)
TURTLEBOT3_WAFFLE = RobotProfile(
    name="turtlebot3_waffle",
    footprint=((-0.205, -0.155), (-0.205, 0.155), (0.077, 0.155), (0.077, -0.155)),
    max_linear_speed=0.26,
    max_angular_speed=1.82,
    max_linear_accel=2.5,
    max_angular_accel=3.2,
    goal_tolerance=GoalTolerance(0.05, 0.17),
    inflation_radius=1.0,
    cost_scaling_factor=3.0,
)
TURTLEBOT3_WAFFLE_PI = replace(TURTLEBOT3_WAFFLE, name="turtlebot3_waffle_pi")

DEFAULT_PROFILE = TURTLEBOT3_BURGER

BUILTIN_PROFILES: dict[str, RobotProfile] = {
    profile.name: profile
    for profile in (TURTLEBOT3_BURGER, TURTLEBOT3_WAFFLE, TURTLEBOT3_WAFFLE_PI)
}
"""Profiles known by name (``--robot NAME``, ``robot: NAME``). Add one here to add a robot."""


__all__ = [
    "BUILTIN_PROFILES",
    "DEFAULT_PROFILE",
    "TURTLEBOT3_BURGER",
    "TURTLEBOT3_WAFFLE",
    "TURTLEBOT3_WAFFLE_PI",
    "GoalTolerance",
    "RobotProfile",
    "circle_footprint",
]
