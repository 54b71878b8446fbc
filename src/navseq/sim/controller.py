"""Local controller: regulated pure pursuit along a global plan, then turn to the goal yaw.

Pure pursuit steers the robot along the circular arc that passes through a "carrot",
the point of the plan one lookahead distance ahead; the arc's curvature is
``2 * lateral_offset / distance²`` in the robot frame. The regulated variant (Nav2's
``RegulatedPurePursuitController``, Macenski et al. 2023) adapts the speed:

- the lookahead grows with speed (``lookahead_time``), so the robot cuts less at low speed;
- sharp arcs (radius below ``regulated_min_radius``) are driven proportionally slower;
- near obstacles (costmap cost above the one at ``cost_slowdown_distance`` from a wall)
  the speed drops in proportion to the clearance;
- approaching the goal the speed follows a braking profile ``sqrt(2 * a * d)``, which
  arrives as fast as a constant deceleration ``approach_decel`` allows (Nav2 ramps
  linearly instead, which costs seconds per stop for no gain in precision).

When the carrot lies far off the robot's heading (more than
``rotate_to_heading_angle``), the robot first turns in place toward it. Once the robot
will come to rest within ``xy_tolerance`` of the goal, position is latched (like Nav2's
stateful goal checker) and the robot turns in place to the goal yaw until it will rest
within ``yaw_tolerance``.

The controller only proposes velocities. Collision checking, replanning and goal
status belong to :class:`navseq.sim.navserver.NavigationServer`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from navseq.geometry import Pose2D, normalize_angle
from navseq.sim.costmap import INSCRIBED, Costmap, CostmapParams
from navseq.sim.robot import DiffDriveLimits

# How many plan points past the current closest one are searched each step: the robot
# moves about one centimetre per step and plan points are a cell (5 cm) apart, so a
# small window suffices and keeps the per-step cost constant on long plans.
_CLOSEST_SEARCH_WINDOW = 8


@dataclass(frozen=True)
class ControllerParams:
    """Tuning of the regulated pure pursuit controller (TurtleBot3 burger defaults).

    Speeds in m/s and rad/s, distances in metres, angles in radians, times in seconds.
    """

    xy_tolerance: float = 0.05
    yaw_tolerance: float = 0.17
    limits: DiffDriveLimits = field(default_factory=DiffDriveLimits)
    lookahead_time: float = 1.5  # lookahead = speed * time, clamped to the two below
    min_lookahead: float = 0.25
    max_lookahead: float = 0.6
    rotate_to_heading_angle: float = 0.785  # turn in place when the carrot is further off
    rotate_to_heading_done: float = 0.3  # ... until it is within this angle
    rotate_speed: float = 2.0  # top turn rate when turning in place
    rotate_decel: float = 2.0  # rad/s² braking profile when a turn in place ends
    regulated_min_radius: float = 0.3  # arcs tighter than this are driven slower
    cost_slowdown_distance: float = 0.25  # slow down when an obstacle is closer than this
    min_regulated_speed: float = 0.05  # regulation never slows below this
    approach_decel: float = 0.5  # m/s² braking profile before the goal


class RegulatedPurePursuit:
    """Follows one plan to one goal pose; feed it the robot state every control step.

    After :meth:`compute`, ``distance_to_path``, ``distance_remaining`` and
    ``goal_reached`` describe where the robot stands relative to the plan.
    """

    def __init__(self, params: ControllerParams, costmap: Costmap) -> None:
        self.params = params
        self._xs: list[float] = []
        self._ys: list[float] = []
        self._remaining_after: list[float] = []  # path length from point i to the goal
        self._goal = Pose2D(0.0, 0.0)
        self._closest = 0
        self._carrot = 0
        self._locate_on_whole_path = True
        self._rotating = False
        self._long_way_sign = 0.0
        self._xy_reached = False
        self.distance_to_path = 0.0
        self.distance_remaining = 0.0
        self.goal_reached = False
        self._factors_for: CostmapParams | None = None
        self.set_costmap(costmap)

    @property
    def closest_index(self) -> int:
        """Index of the plan point nearest the robot at the last :meth:`compute`."""
        return self._closest

    def set_costmap(self, costmap: Costmap) -> None:
        """Use ``costmap`` for the obstacle slowdown (after a costmap is rebuilt)."""
        if costmap.params != self._factors_for:
            # They depend on the inflation only, which costmaps with robots in share.
            self._speed_factor_by_cost = speed_factors_by_cost(self.params, costmap)
            self._factors_for = costmap.params
        self.costmap = costmap

    def set_path(self, points: np.ndarray, goal: Pose2D) -> None:
        """Start following ``points`` (N, 2) toward ``goal``; the last point should be the goal.

        Everything about the previous path is forgotten, including a reached position.
        """
        if len(points) == 0:
            points = np.array([[goal.x, goal.y]])
        self._xs = [float(x) for x in points[:, 0]]
        self._ys = [float(y) for y in points[:, 1]]
        steps = np.hypot(np.diff(points[:, 0]), np.diff(points[:, 1]))
        after = np.concatenate((np.cumsum(steps[::-1])[::-1], [0.0]))
        self._remaining_after = [float(d) for d in after]
        self._goal = goal
        self._xy_reached = False
        self.goal_reached = False
        self.distance_to_path = 0.0
        self._closest = 0
        self._carrot = 0
        self._locate_on_whole_path = True
        self._rotating = False
        self._long_way_sign = 0.0

    def compute(self, pose: Pose2D, v: float, w: float) -> tuple[float, float]:
        """Velocity command ``(v, w)`` for a robot at ``pose`` moving at ``(v, w)``."""
        params = self.params
        limits = params.limits
        x, y, yaw = pose.x, pose.y, pose.yaw
        goal = self._goal
        distance_to_goal = math.hypot(goal.x - x, goal.y - y)
        self._track_progress(x, y)

        if self._xy_reached and distance_to_goal > params.xy_tolerance:
            self._xy_reached = False  # pushed away (by an evasive move): approach again
        if not self._xy_reached:
            braking = v * v / (2.0 * limits.acc_v)
            self._xy_reached = distance_to_goal + braking <= params.xy_tolerance
        if self._xy_reached:
            self.distance_remaining = distance_to_goal
            return 0.0, self._turn_to_goal_yaw(yaw, w)

        lookahead = min(
            max(abs(v) * params.lookahead_time, params.min_lookahead), params.max_lookahead
        )
        carrot_x, carrot_y = self._carrot_point(x, y, lookahead)
        dx, dy = carrot_x - x, carrot_y - y
        cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
        ahead = dx * cos_yaw + dy * sin_yaw
        left = -dx * sin_yaw + dy * cos_yaw
        bearing = math.atan2(left, ahead)

        if self._rotating:
            self._rotating = abs(bearing) > params.rotate_to_heading_done
        else:
            self._rotating = abs(bearing) > params.rotate_to_heading_angle
        if self._rotating:
            return 0.0, self._turn_rate_toward(bearing)

        squared = ahead * ahead + left * left
        curvature = 2.0 * left / squared if squared > 1e-12 else 0.0
        speed = limits.max_v
        if abs(curvature) * params.regulated_min_radius > 1.0:
            speed /= abs(curvature) * params.regulated_min_radius
        speed *= self._speed_factor_by_cost[self.costmap.cost_at(x, y)]
        speed = max(speed, params.min_regulated_speed)
        zones = self.costmap.grid.filters
        if zones is not None:  # Nav2's speed filter: the controller's speed limit,
            # even below the regulation's floor
            speed = min(speed, zones.speed_cap(self.costmap.grid, x, y, limits.max_v))
        approach = (
            distance_to_goal
            if self.distance_remaining < params.max_lookahead
            else self.distance_remaining
        )
        speed = min(speed, math.sqrt(2.0 * params.approach_decel * approach), limits.max_v)
        turn = speed * curvature
        if abs(turn) > limits.max_w:  # keep the arc, drive it slower
            speed *= limits.max_w / abs(turn)
            turn = math.copysign(limits.max_w, turn)
        return speed, turn

    def _track_progress(self, x: float, y: float) -> None:
        """Advance the closest plan point; update distance to the plan and remaining."""
        xs, ys = self._xs, self._ys
        best = self._closest
        best_squared = (xs[best] - x) ** 2 + (ys[best] - y) ** 2
        # On a new path the robot may be anywhere along it (a plan made from elsewhere).
        window = len(xs) if self._locate_on_whole_path else _CLOSEST_SEARCH_WINDOW
        self._locate_on_whole_path = False
        for i in range(best + 1, min(best + window, len(xs))):
            squared = (xs[i] - x) ** 2 + (ys[i] - y) ** 2
            if squared < best_squared:
                best, best_squared = i, squared
        self._closest = best
        self.distance_to_path = math.sqrt(best_squared)
        self.distance_remaining = self._remaining_after[best] + self.distance_to_path
        if best + 1 < len(xs):
            # Past the closest point already: measure via the next one, so the figure
            # shrinks smoothly instead of in cell-sized steps.
            next_x, next_y = xs[best + 1], ys[best + 1]
            along = (x - xs[best]) * (next_x - xs[best]) + (y - ys[best]) * (next_y - ys[best])
            if along > 0.0:
                self.distance_remaining = self._remaining_after[best + 1] + math.hypot(
                    next_x - x, next_y - y
                )

    def _carrot_point(self, x: float, y: float, lookahead: float) -> tuple[float, float]:
        """The point where a circle of radius ``lookahead`` about the robot leaves the plan."""
        xs, ys = self._xs, self._ys
        last = len(xs) - 1
        squared_lookahead = lookahead * lookahead
        j = max(self._carrot, self._closest)
        while j <= last and (xs[j] - x) ** 2 + (ys[j] - y) ** 2 < squared_lookahead:
            j += 1
        if j > last:
            self._carrot = last
            return xs[last], ys[last]
        self._carrot = j
        if j == self._closest:
            return xs[j], ys[j]
        # Intersect the segment (j-1 inside the circle, j outside) with the circle.
        ax, ay = xs[j - 1] - x, ys[j - 1] - y
        sx, sy = xs[j] - xs[j - 1], ys[j] - ys[j - 1]
        a = sx * sx + sy * sy
        b = 2.0 * (ax * sx + ay * sy)
        c = ax * ax + ay * ay - squared_lookahead
        t = (-b + math.sqrt(max(b * b - 4.0 * a * c, 0.0))) / (2.0 * a) if a > 0 else 1.0
        return xs[j - 1] + t * sx, ys[j - 1] + t * sy

    def _turn_to_goal_yaw(self, yaw: float, w: float) -> float:
        """Turn rate toward the goal yaw; sets ``goal_reached`` once the robot will rest in it."""
        params = self.params
        error = normalize_angle(self._goal.yaw - yaw)
        resting_error = normalize_angle(error - w * abs(w) / (2.0 * params.limits.acc_w))
        if abs(error) <= params.yaw_tolerance and abs(resting_error) <= params.yaw_tolerance:
            self.goal_reached = True
            return 0.0
        return self._turn_rate_toward(error)

    def turn_the_long_way(self, turn_rate: float) -> None:
        """Make the turn in place now under way (``turn_rate``) go round the other way.

        Used when the short way round is blocked. Holds until the remaining angle has
        come round to the other side, where the short way is the way the robot turns.
        """
        self._long_way_sign = math.copysign(1.0, turn_rate)

    def _turn_rate_toward(self, angle: float) -> float:
        """Turn in place by ``angle``: top speed, then brake so as to stop on it."""
        params = self.params
        if self._long_way_sign:
            if math.copysign(1.0, angle) == self._long_way_sign:
                angle -= math.copysign(2.0 * math.pi, angle)
            else:
                self._long_way_sign = 0.0
        rate = min(
            params.rotate_speed,
            params.limits.max_w,
            math.sqrt(2.0 * params.rotate_decel * abs(angle)),
        )
        return math.copysign(rate, angle)


def speed_factors_by_cost(params: ControllerParams, costmap: Costmap) -> list[float]:
    """Speed multiplier for each cost byte: clearance / ``cost_slowdown_distance`` when short.

    The clearance is read back from the cost the way Nav2 does, by inverting the
    inflation decay ``cost = 252 * exp(-factor * (d - inscribed))``.
    """
    inflation = costmap.params
    factors = [1.0] * 256
    for cost in range(1, 256):
        if cost >= INSCRIBED:
            factors[cost] = 0.0
            continue
        clearance = inflation.inscribed_radius - math.log(cost / (INSCRIBED - 1)) / max(
            inflation.cost_scaling_factor, 1e-9
        )
        if clearance < params.cost_slowdown_distance:
            factors[cost] = clearance / params.cost_slowdown_distance
    return factors
