"""How long a robot takes to drive one planned path: a speed profile along it.

The model follows what a regulated pure pursuit controller (Nav2's, and the embedded
simulator's :mod:`navseq.sim.controller`) does with a differential-drive robot:

1. **Turn in place** at the start when the path leaves far off the robot's heading
   (more than ``rotate_above``), until it is within ``rotate_until`` of it; the rest of
   that angle is turned while driving. A turn accelerates at the robot's angular
   acceleration up to the turn rate and brakes on the controller's braking profile.
2. **Drive** the path — averaged over one lookahead, as pure pursuit cuts a grid
   planner's zigzags and corners — at the top speed, except where it bends (pure pursuit
   drives an arc through the carrot one lookahead ahead; arcs tighter than
   ``regulated_min_radius`` are driven proportionally slower) and near obstacles (an
   optional speed cap from the costmap). Speed changes at the robot's linear
   acceleration, both ways: a cap ahead is braked for.
3. **Stop** at a waypoint that is not passed through: braking on the profile
   ``sqrt(2 * approach_decel * d)``, arrived once the robot will rest within the goal
   tolerance; then turn in place to the goal's yaw until within the yaw tolerance.
   A pass-through waypoint keeps the speed: its leg ends where the robot comes within
   the pass-through radius, and the next leg starts from there, moving.

The path is sampled every :data:`STEP_M` and the speed profile found with a forward pass
(acceleration) and a backward pass (braking), as in any time-optimal profile along a
fixed path. What it ignores: replanning, recovery behaviours, other robots, the
controller's lag behind the path (the averaged path stands for what it drives).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from navseq.geometry import normalize_angle

if TYPE_CHECKING:
    from navseq.mission.robot import RobotProfile

#: Metres between the samples of a path's speed profile.
STEP_M = 0.02

Point = tuple[float, float]
#: Top speed (m/s) allowed at each of a set of points ``(N, 2)`` (obstacles near).
SpeedCap = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class DriveModel:
    """The limits and controller settings the duration depends on (m, s, rad).

    Made from a robot profile by :meth:`of`; the controller's settings are the embedded
    simulator's (Nav2's regulated pure pursuit defaults, where navseq follows them).
    """

    max_speed: float
    accel: float
    approach_decel: float
    turn_rate: float
    turn_accel: float
    turn_decel: float
    rotate_above: float
    rotate_until: float
    lookahead: float
    regulated_min_radius: float
    min_regulated_speed: float
    xy_tolerance: float
    yaw_tolerance: float

    @classmethod
    def of(cls, profile: RobotProfile) -> DriveModel:
        """The model of the robot ``profile`` (a :class:`~navseq.mission.robot.RobotProfile`)
        driven the way the simulator drives it."""
        from navseq.sim.profile import nav_params_of

        params = nav_params_of(profile)
        limits = params.limits
        return cls(
            max_speed=limits.max_v,
            accel=limits.acc_v,
            approach_decel=params.approach_decel,
            turn_rate=min(params.rotate_speed, limits.max_w),
            turn_accel=limits.acc_w,
            turn_decel=params.rotate_decel,
            rotate_above=params.rotate_to_heading_angle,
            rotate_until=params.rotate_to_heading_done,
            # The lookahead at cruising speed: most of a path is driven at it.
            lookahead=min(
                max(limits.max_v * params.lookahead_time, params.min_lookahead),
                params.max_lookahead,
            ),
            regulated_min_radius=params.regulated_min_radius,
            min_regulated_speed=params.min_regulated_speed,
            xy_tolerance=params.xy_tolerance,
            yaw_tolerance=params.yaw_tolerance,
        )


def turn_time(angle: float, model: DriveModel) -> float:
    """Seconds to turn in place by ``angle`` (rad), from rest to rest.

    A trapezoid in turn rate: up at ``turn_accel``, flat at ``turn_rate``, down at
    ``turn_decel``; a triangle when the angle is too small to reach the top rate.
    """
    angle = abs(angle)
    if angle <= 0.0:
        return 0.0
    up, down, top = model.turn_accel, model.turn_decel, model.turn_rate
    ramps = top * top / (2.0 * up) + top * top / (2.0 * down)
    if angle >= ramps:
        return top / up + top / down + (angle - ramps) / top
    peak = math.sqrt(2.0 * angle * up * down / (up + down))
    return peak / up + peak / down


def turn_until(angle: float, within: float, model: DriveModel) -> float:
    """Seconds of a turn in place by ``angle`` that ends once within ``within`` of it.

    The controller stops turning in place when the angle left is small enough; the
    last ``within`` radians of the braking profile are not waited for.
    """
    angle = abs(angle)
    if angle <= within:
        return 0.0
    last = math.sqrt(2.0 * within / model.turn_decel)  # the braking profile's last stretch
    return max(turn_time(angle, model) - last, 0.0)


@dataclass(frozen=True)
class DrivenPath:
    """One path driven: its duration, and the time left from any distance left.

    ``remaining_m`` and ``time_left_s`` run from the start to the end of the driven part
    (decreasing distance, decreasing time), so :meth:`time_left` interpolates.
    """

    duration_s: float  # turns and stops included
    length_m: float  # driven (a pass-through leg ends short of its waypoint)
    end_speed: float  # m/s when the leg ends (0 when it stops)
    end_heading: float  # rad: the direction the robot drives (or last drove) at the end
    end_point: Point
    remaining_m: np.ndarray  # along the plan to the goal, as a navigation stack says it
    time_left_s: np.ndarray

    def time_left(self, remaining_m: float) -> float:
        """Seconds still to go with ``remaining_m`` metres of the plan left to the goal.

        Past the end of the driving (arrived, turning to the goal's yaw) it is the time
        the end takes: how much of that turn is done, the distance does not say.
        """
        if remaining_m >= float(self.remaining_m[0]):
            return float(self.time_left_s[0])
        return float(np.interp(remaining_m, self.remaining_m[::-1], self.time_left_s[::-1]))


def drive_path(
    points: Sequence[Point],
    model: DriveModel,
    *,
    start_heading: float | None,
    start_speed: float = 0.0,
    goal_yaw: float | None = None,
    pass_radius: float | None = None,
    goal: Point | None = None,
    speed_cap: SpeedCap | None = None,
) -> DrivenPath:
    """The robot driving ``points`` (a polyline, metres) from rest or at ``start_speed``.

    ``start_heading`` None: the robot already faces the path. With ``pass_radius`` the
    leg ends, at speed, where the robot comes within that radius of ``goal`` (the last
    point when not given); otherwise it stops there and turns to ``goal_yaw`` (if given).
    """
    planned = _resample(points)
    xy = _smoothed(planned, model.lookahead)
    # A navigation stack reports the distance left along its plan to the goal: the
    # planned path, not the smoothed one, and to the goal, not to where a pass-through
    # leg ends. ``per_metre`` converts, for :meth:`DrivenPath.time_left`.
    smoothed_m = _length(xy)
    per_metre = _length(planned) / smoothed_m if smoothed_m > 0.0 else 1.0
    goal_xy = np.asarray(goal if goal is not None else points[-1], dtype=float)
    if pass_radius is not None:
        near = np.hypot(xy[:, 0] - goal_xy[0], xy[:, 1] - goal_xy[1]) <= pass_radius
        end = int(np.argmax(near)) if near.any() else len(xy) - 1
        xy = xy[: max(end, 1) + 1]
    steps = np.hypot(np.diff(xy[:, 0]), np.diff(xy[:, 1]))
    along = np.concatenate(([0.0], np.cumsum(steps)))
    length = float(along[-1])
    headings = _headings(xy)
    # The direction the robot last drove: of the last step that moved; on a leg of no
    # length, the heading it had (or the goal's, when neither is known: no turn).
    moved = headings[steps > 1e-9]
    heading_at_end = (
        float(moved[-1])
        if len(moved)
        else (start_heading if start_heading is not None else (goal_yaw or 0.0))
    )

    before = 0.0
    speed0 = start_speed
    if start_heading is not None and length > 0.0:
        off = abs(normalize_angle(_heading_to(xy, along, model.lookahead) - start_heading))
        if off > model.rotate_above:
            before += start_speed / model.accel if model.accel > 0 else 0.0  # stop first
            before += turn_until(off, model.rotate_until, model)
            speed0 = 0.0

    caps, sharp = _bend_caps(xy, along, model)
    if speed_cap is not None:
        caps = np.minimum(caps, np.maximum(speed_cap(xy), model.min_regulated_speed))
    stops = pass_radius is None
    if stops:
        # The braking profile to the goal, and arrival once the robot will rest within
        # the tolerance: the leg ends that much short of its end.
        latch = model.xy_tolerance / (1.0 + model.approach_decel / model.accel)
        left = np.maximum(length - along, 0.0)
        caps = np.minimum(caps, np.sqrt(2.0 * model.approach_decel * left))
        # The last sample moved to where the robot latches (samples are STEP_M apart).
        keep = left > latch
        keep[0] = True
        arrive_at = max(length - latch, 0.0)
        last = int(np.count_nonzero(keep))
        xy = np.vstack((xy[:last], _point_at(xy, along, np.array([arrive_at]))))
        caps = np.append(caps[:last], math.sqrt(2.0 * model.approach_decel * latch))
        sharp = np.append(sharp[:last], 0.0)
        along = np.append(along[:last], arrive_at)
    speeds = _speed_profile(caps, np.diff(along), speed0, model.accel)
    times = _times(np.diff(along), speeds, model.accel) + _bend_turns(sharp, model)
    after = 0.0
    if stops:
        after += speeds[-1] / model.accel if model.accel > 0 else 0.0
        if goal_yaw is not None:
            turn = normalize_angle(goal_yaw - heading_at_end)
            after += turn_until(turn, model.yaw_tolerance, model)
    duration = before + float(times[-1]) + after
    end_speed = 0.0 if stops else float(speeds[-1])
    end_heading = heading_at_end
    if stops and goal_yaw is not None:
        end_heading = goal_yaw
    return DrivenPath(
        duration_s=duration,
        length_m=float(along[-1]),
        end_speed=end_speed,
        end_heading=end_heading,
        end_point=(float(xy[-1, 0]), float(xy[-1, 1])),
        remaining_m=(smoothed_m - along) * per_metre,
        # Still at the start, the turn in place is still to come; once moving, it is done.
        time_left_s=np.concatenate(([duration], (duration - before - times)[1:])),
    )


def _resample(points: Sequence[Point]) -> np.ndarray:
    """The polyline as points :data:`STEP_M` apart (its corners kept)."""
    array = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(array) == 1:
        return np.vstack((array, array))
    pieces = [array[:1]]
    for a, b in itertools.pairwise(array):
        count = max(math.ceil(math.dist(a, b) / STEP_M), 1)
        fractions = np.linspace(0.0, 1.0, count + 1)[1:, None]
        pieces.append(a + fractions * (b - a))
    return np.vstack(pieces)


def _length(xy: np.ndarray) -> float:
    return float(np.hypot(np.diff(xy[:, 0]), np.diff(xy[:, 1])).sum())


def _smoothed(xy: np.ndarray, window_m: float) -> np.ndarray:
    """The path as pure pursuit drives it: averaged over ``window_m``, ends kept.

    A grid planner's path zigzags between the 8 directions of its cells; the controller,
    steering toward a point one lookahead ahead, drives the average and cuts corners.
    """
    half = int(window_m / STEP_M / 2)
    if half < 1 or len(xy) < 3:
        return xy
    padded = np.pad(xy, ((half, half), (0, 0)), mode="edge")
    kernel = np.ones(2 * half + 1) / (2 * half + 1)
    smooth = np.column_stack([np.convolve(padded[:, k], kernel, mode="valid") for k in range(2)])
    smooth[0], smooth[-1] = xy[0], xy[-1]
    # Averaging bunches the points near the ends: space them evenly again.
    along = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(smooth, axis=0).T))))
    if along[-1] <= 0.0:
        return smooth
    even = np.append(np.arange(0.0, along[-1], STEP_M), along[-1])
    return _point_at(smooth, along, even)


def _headings(xy: np.ndarray) -> np.ndarray:
    """The direction of each step (rad)."""
    steps = np.diff(xy, axis=0)
    return np.arctan2(steps[:, 1], steps[:, 0])


def _point_at(xy: np.ndarray, along: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points at arc lengths ``s`` (clamped to the path)."""
    s = np.clip(s, 0.0, along[-1])
    return np.column_stack((np.interp(s, along, xy[:, 0]), np.interp(s, along, xy[:, 1])))


def _heading_to(xy: np.ndarray, along: np.ndarray, lookahead: float) -> float:
    """The direction from the path's start to its point one lookahead along."""
    carrot = _point_at(xy, along, np.array([lookahead]))[0]
    dx, dy = carrot[0] - xy[0, 0], carrot[1] - xy[0, 1]
    if dx == 0.0 and dy == 0.0:
        return 0.0
    return math.atan2(dy, dx)


def _bend_caps(
    xy: np.ndarray, along: np.ndarray, model: DriveModel
) -> tuple[np.ndarray, np.ndarray]:
    """Top speed at each sample where the path bends.

    Pure pursuit drives through a bend of the path on an arc; looking one lookahead back
    and ahead, the bend turns the heading by ``delta`` and the arc's bearing to the
    carrot is about half of it, so its curvature is ``2 sin(delta / 2) / lookahead``.
    Arcs tighter than ``regulated_min_radius`` are driven proportionally slower; a bend
    past ``2 * rotate_above`` is turned in place (speed 0 there). Returns the caps and
    each sample's heading change where it is turned in place (0 elsewhere).
    """
    look = model.lookahead
    behind = _point_at(xy, along, along - look)
    ahead = _point_at(xy, along, along + look)
    back = np.arctan2(xy[:, 1] - behind[:, 1], xy[:, 0] - behind[:, 0])
    forth = np.arctan2(ahead[:, 1] - xy[:, 1], ahead[:, 0] - xy[:, 0])
    delta = np.abs((forth - back + np.pi) % (2.0 * np.pi) - np.pi)
    # No bend measured where the path has not started or has ended.
    delta[(along < 1e-9) | (along > along[-1] - 1e-9)] = 0.0
    bearing = delta / 2.0
    curvature = 2.0 * np.sin(bearing) / look
    caps = np.full(len(xy), model.max_speed)
    tight = curvature * model.regulated_min_radius > 1.0
    caps[tight] = model.max_speed / (curvature[tight] * model.regulated_min_radius)
    caps = np.maximum(caps, model.min_regulated_speed)
    sharp = np.where(bearing > model.rotate_above, delta, 0.0)
    caps[sharp > 0.0] = 0.0
    return np.minimum(caps, model.max_speed), sharp


def _bend_turns(sharp: np.ndarray, model: DriveModel) -> np.ndarray:
    """Seconds spent turning in place at sharp bends, added up from the start.

    Each run of samples at a sharp bend is one turn, of the run's largest heading change.
    """
    extra = np.zeros(len(sharp))
    at_bend = sharp > 0.0
    if at_bend.any():
        edges = np.diff(np.concatenate(([0], at_bend.astype(np.int8), [0])))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        for start, end in zip(starts, ends, strict=True):
            turn = float(sharp[start:end].max())
            extra[start] = turn_until(turn, model.rotate_until, model)
    return np.cumsum(extra)


def _speed_profile(caps: np.ndarray, steps: np.ndarray, start: float, accel: float) -> np.ndarray:
    """Speed at each sample: within the caps, changing at most ``accel`` both ways.

    Speeding up from sample j, the robot has ``v² = v_j² + 2 a (s - s_j)`` at ``s``; the
    speed at a sample is the least over every sample behind it (and, braking, ahead of
    it), which a running minimum gives without a loop.
    """
    along = np.concatenate(([0.0], np.cumsum(steps)))
    squared = caps * caps
    squared[0] = min(start, caps[0]) ** 2 if start > 0.0 else 0.0
    reach = 2.0 * accel * along
    ahead = np.minimum.accumulate(squared - reach) + reach  # accelerating
    behind = np.minimum.accumulate((ahead + reach)[::-1])[::-1] - reach  # braking for what comes
    behind[0] = ahead[0]  # the robot starts at the speed it has
    speeds: np.ndarray = np.sqrt(np.maximum(np.minimum(ahead, behind), 0.0))
    return speeds


def _times(steps: np.ndarray, speeds: np.ndarray, accel: float) -> np.ndarray:
    """Seconds from the start to each sample at these speeds.

    Speeding up, the robot accelerates at ``accel`` until it has the next sample's speed
    and keeps it (a step from rest is mostly driven at the new speed); slowing down, it
    brakes evenly over the step (the braking profiles are constant decelerations).
    """
    v0, v1 = speeds[:-1], speeds[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        even = np.where(v0 + v1 > 1e-9, 2.0 * steps / np.maximum(v0 + v1, 1e-9), 0.0)
        ramp = (v1 * v1 - v0 * v0) / (2.0 * accel)
        speeding = (v1 > v0) & (ramp < steps)
        ramp_then_cruise = (v1 - v0) / accel + (steps - ramp) / np.maximum(v1, 1e-9)
    each = np.where(speeding, ramp_then_cruise, even)
    return np.concatenate(([0.0], np.cumsum(each)))
