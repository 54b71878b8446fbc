"""Nav2's collision monitor between the velocity smoother and the base, without ROS.

Nav2's ``collision_monitor`` takes ``cmd_vel_smoothed``, looks at the points its sources
(nav2_bringup: the ``scan``) put around the robot and passes on ``cmd_vel`` — unchanged,
slowed or stopped by the first polygons those points fall in. :class:`CollisionMonitor`
holds the same rules for the stand-in's simulated robot:

- a polygon (:class:`MonitorPolygon`) is an outline in the robot frame, or the robot's
  footprint (Nav2's ``footprint_topic``: the local costmap's published footprint), with
  an action: ``stop`` (zero), ``slowdown`` (times ``slowdown_ratio``), ``limit`` (to
  ``linear_limit`` / ``angular_limit``, keeping the curvature) when at least
  ``min_points`` points are inside it, or ``approach``: the outline is driven ahead with
  the command in ``simulation_time_step`` steps up to ``time_before_collision``, and the
  command is scaled by *time to collision / time_before_collision*, so the robot keeps
  that much time away from what it would hit (zero: it stops);
- of the polygons, the one asking for the slowest command acts, a ``stop`` at once, as
  in Nav2's ``CollisionMonitor::process``; its name and action are the monitor's state,
  reported when the polygon that acts changes (Nav2's ``collision_monitor_state``);
- ``enabled`` is Nav2's ``toggle`` service: off, commands pass unchanged.

nav2_bringup's configuration is one polygon, ``FootprintApproach`` (approach, the
footprint, 1.2 s ahead in 0.1 s steps, 6 points): :func:`nav2_bringup_polygons`. The
points are the scan's hits in the robot frame (:func:`scan_points`); the stand-in takes
them from the simulated laser at its own rate, as Nav2 takes the last scan heard.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from navseq.sim.scan import TURTLEBOT3_LDS, LaserSpec, ray_cast
from navseq.sim.world import SimWorld


class ActionType(enum.IntEnum):
    """``nav2_msgs/CollisionMonitorState``'s action types."""

    DO_NOTHING = 0
    STOP = 1
    SLOWDOWN = 2
    APPROACH = 3
    LIMIT = 4


#: Nav2's ``action_type`` parameter values.
ACTION_NAMES = {
    "stop": ActionType.STOP,
    "slowdown": ActionType.SLOWDOWN,
    "approach": ActionType.APPROACH,
    "limit": ActionType.LIMIT,
}


@dataclass(frozen=True)
class MonitorPolygon:
    """One of the monitor's polygons, with Nav2's parameter names and defaults.

    ``points``: the outline in the robot frame, shape (K, 2); None for the robot's
    footprint (Nav2's ``footprint_topic``), whatever it is when a command is checked.
    """

    name: str
    action: ActionType
    points: np.ndarray | None = None
    min_points: int = 4
    slowdown_ratio: float = 0.5
    linear_limit: float = 0.5
    angular_limit: float = 0.5
    time_before_collision: float = 2.0
    simulation_time_step: float = 0.1
    enabled: bool = True


def nav2_bringup_polygons() -> tuple[MonitorPolygon, ...]:
    """nav2_bringup's (Jazzy) ``collision_monitor.polygons``: ``FootprintApproach``."""
    return (
        MonitorPolygon(
            "FootprintApproach",
            ActionType.APPROACH,
            None,
            min_points=6,
            time_before_collision=1.2,
            simulation_time_step=0.1,
        ),
    )


@dataclass(frozen=True)
class Verdict:
    """What the monitor passes on, and which polygon made it so ("" for none)."""

    v: float
    w: float
    action: ActionType = ActionType.DO_NOTHING
    polygon: str = ""


def scan_points(ranges: np.ndarray, spec: LaserSpec) -> np.ndarray:
    """The scan's hits (finite ranges) in the robot frame, shape (N, 2)."""
    hit = np.isfinite(ranges)
    angles, distances = spec.angles[hit], np.asarray(ranges, dtype=float)[hit]
    return np.column_stack((spec.mount_x + distances * np.cos(angles), distances * np.sin(angles)))


def points_inside(outline: np.ndarray, points: np.ndarray) -> int:
    """How many ``points`` lie inside ``outline`` (the crossing rule, as Nav2's
    ``Polygon::isPointInside``)."""
    if len(points) == 0:
        return 0
    x, y = points[:, 0:1], points[:, 1:2]  # (N, 1) against the K edges
    x1, y1 = outline[:, 0], outline[:, 1]
    x2, y2 = np.roll(x1, -1), np.roll(y1, -1)
    straddles = (y1 > y) != (y2 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        crossing_x = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
    crossings = straddles & (x < crossing_x)
    return int(np.count_nonzero(np.count_nonzero(crossings, axis=1) % 2))


def _placed(outline: np.ndarray, x: float, y: float, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return outline @ np.array([[c, s], [-s, c]]) + (x, y)


def collision_time(polygon: MonitorPolygon, outline: np.ndarray, points: np.ndarray,
                   v: float, w: float) -> float | None:  # fmt: skip
    """Seconds until ``outline`` driven with (v, w) holds ``min_points`` points (0: it
    does now, or within the first step), None if not within ``time_before_collision``."""
    if points_inside(outline, points) >= polygon.min_points:
        return 0.0
    step = polygon.simulation_time_step
    x = y = yaw = 0.0
    elapsed = 0.0
    while elapsed <= polygon.time_before_collision + 1e-9:
        x += v * math.cos(yaw) * step
        y += v * math.sin(yaw) * step
        yaw += w * step
        if points_inside(_placed(outline, x, y, yaw), points) >= polygon.min_points:
            return elapsed
        elapsed += step
    return None


Velocity = tuple[float, float]


def _slower(first: Velocity, second: Velocity) -> bool:
    """Nav2's ``Velocity::operator<``: by linear speed, then by turn rate."""
    return abs(first[0]) < abs(second[0]) or (
        abs(first[0]) == abs(second[0]) and abs(first[1]) < abs(second[1])
    )


def _stop(polygon: MonitorPolygon, outline: np.ndarray, points: np.ndarray,
          v: float, w: float) -> Velocity | None:  # fmt: skip
    return (0.0, 0.0) if points_inside(outline, points) >= polygon.min_points else None


def _slowdown(polygon: MonitorPolygon, outline: np.ndarray, points: np.ndarray,
              v: float, w: float) -> Velocity | None:  # fmt: skip
    if points_inside(outline, points) < polygon.min_points:
        return None
    return v * polygon.slowdown_ratio, w * polygon.slowdown_ratio


def _limit(polygon: MonitorPolygon, outline: np.ndarray, points: np.ndarray,
           v: float, w: float) -> Velocity | None:  # fmt: skip
    if points_inside(outline, points) < polygon.min_points:
        return None
    ratio = 1.0
    if v != 0.0:
        ratio = min(ratio, polygon.linear_limit / abs(v))
    if w != 0.0:
        ratio = min(ratio, polygon.angular_limit / abs(w))
    ratio = min(max(ratio, 0.0), 1.0)
    return v * ratio, w * ratio


def _approach(polygon: MonitorPolygon, outline: np.ndarray, points: np.ndarray,
              v: float, w: float) -> Velocity | None:  # fmt: skip
    seconds = collision_time(polygon, outline, points, v, w)
    if seconds is None:
        return None
    ratio = seconds / polygon.time_before_collision
    return v * ratio, w * ratio


#: What each action asks for when its polygon is triggered (None: not triggered).
ACTIONS: dict[ActionType, Callable[..., Velocity | None]] = {
    ActionType.STOP: _stop,
    ActionType.SLOWDOWN: _slowdown,
    ActionType.LIMIT: _limit,
    ActionType.APPROACH: _approach,
}


class CollisionMonitor:
    """The monitor's rules; see the module docstring.

    ``footprint``: the robot's outline (robot frame) the footprint polygons take.
    ``state`` is the last verdict's polygon and action; :meth:`check` appends a verdict
    to ``changes`` whenever the polygon that acts changes while the monitor is enabled
    (what Nav2 publishes on ``collision_monitor_state``).
    """

    def __init__(self, polygons: tuple[MonitorPolygon, ...], footprint: np.ndarray) -> None:
        self.polygons = polygons
        self.footprint = np.asarray(footprint, dtype=float)
        self.enabled = True
        self.state = Verdict(0.0, 0.0)
        self.changes: list[Verdict] = []

    def check(self, v: float, w: float, points: np.ndarray) -> Verdict:
        """The command to pass on for (v, w) with ``points`` (robot frame) around."""
        verdict = Verdict(v, w)
        if self.enabled:
            for polygon in self.polygons:
                if not polygon.enabled:
                    continue
                outline = self.footprint if polygon.points is None else polygon.points
                safe = ACTIONS[polygon.action](polygon, outline, points, v, w)
                if safe is not None and (
                    polygon.action is ActionType.STOP or _slower(safe, (verdict.v, verdict.w))
                ):
                    verdict = Verdict(safe[0], safe[1], polygon.action, polygon.name)
                if verdict.action is ActionType.STOP:
                    break
            if verdict.polygon != self.state.polygon:
                self.changes.append(verdict)
        self.state = verdict
        return verdict


class MonitorStage:
    """The monitor in the stand-in's velocity chain, fed by the simulated laser.

    ``active``: whether the ``collision_monitor`` node is active; an inactive one passes
    nothing on (Nav2's publishes no ``cmd_vel``), so the robot stops. The points are the
    laser's hits from the robot's true pose, refreshed at the laser's rate.
    """

    def __init__(self, monitor: CollisionMonitor, spec: LaserSpec = TURTLEBOT3_LDS) -> None:
        self.monitor = monitor
        self.spec = spec
        self.active: Callable[[], bool] = lambda: True
        self.points = np.empty((0, 2))
        self.checked = False  # a command went through since the node last published
        self._next_scan = -math.inf

    def filter(self, v: float, w: float, world: SimWorld, now: float) -> Velocity:
        """The command the base gets for (v, w) at simulated time ``now``."""
        if not self.active():
            return 0.0, 0.0
        if now + 1e-9 >= self._next_scan:
            self._next_scan = now + 1.0 / self.spec.rate
            body = world.body
            ranges = ray_cast(world.grid, body.robot.pose, self.spec, body.others)
            self.points = scan_points(ranges, self.spec)
        self.checked = True
        verdict = self.monitor.check(v, w, self.points)
        return verdict.v, verdict.w


__all__ = [
    "ACTIONS",
    "ACTION_NAMES",
    "ActionType",
    "CollisionMonitor",
    "MonitorPolygon",
    "MonitorStage",
    "Verdict",
    "collision_time",
    "nav2_bringup_polygons",
    "points_inside",
    "scan_points",
]
