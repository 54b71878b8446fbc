"""The time still to go while the mission runs, and how far off each prediction was.

:class:`EtaEstimator` is a mission listener (it sees the executor's events, whatever the
navigator): on each progress event the time to go is

    the current leg's time left (from the distance left along the current plan, on the
    leg's predicted speed profile) + the dwell and tasks still to come at this waypoint
    + the predicted time of every visit after it,

with the driving part scaled by how fast the robot has actually been so far: the
driving time it has taken over the driving time predicted for the same ground (clamped
to :data:`RATIO_LIMITS`, and only once :data:`RATIO_AFTER_S` of driving was predicted).
The upper bound is the same with every task taking its timeout.

Each estimate is kept (elapsed, predicted end); when the mission ends,
:meth:`EtaEstimator.accuracy` gives the prediction before the start and the ones at
25, 50 and 75 % of the mission's actual duration against its actual end.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from navseq.eta.predict import MissionPrediction, VisitPrediction
from navseq.executor.events import (
    MissionEvent,
    MissionFinished,
    MissionPaused,
    MissionResumed,
    MissionStarted,
    TaskFinished,
    TaskStarted,
    WaypointDwelling,
    WaypointFinished,
    WaypointProgress,
    WaypointStarted,
)
from navseq.geometry import Pose2D

#: The achieved-over-predicted driving time is trusted within these limits.
RATIO_LIMITS = (0.5, 3.0)
#: ... and only once this much driving was predicted for the ground covered (s).
RATIO_AFTER_S = 5.0
#: Seconds between the estimates kept for :meth:`EtaEstimator.accuracy` (bounded memory).
KEEP_EVERY_S = 1.0
#: Fractions of the actual mission duration at which the report checks the prediction.
CHECKPOINTS = (0.0, 0.25, 0.5, 0.75)


@dataclass
class _Estimate:
    elapsed_s: float
    end_s: float  # predicted mission duration, from its start


@dataclass
class EtaEstimator:
    """Time to go for one run of ``prediction``'s mission; feed it every mission event.

    ``from_pose``: for a prediction made without a start pose (a ROS node does not know
    where the robot is before it runs), the prediction from the robot's first pose; it
    is made once, on the first progress event, and is the run's "before the start".
    """

    prediction: MissionPrediction
    from_pose: Callable[[Pose2D], MissionPrediction] | None = None
    # False: the prediction's driving times as they are (benchmarks compare the two).
    correct_by_achieved_speed: bool = True
    eta_s: float | None = None
    eta_upper_s: float | None = None
    _start: float | None = None
    _visit: VisitPrediction | None = None
    _loop_index: tuple[int, int] | None = None
    _drive_done_s: float = 0.0  # predicted driving of the visits finished
    _drive_left_s: float = 0.0  # predicted driving still to go on the current leg
    _waiting_s: float = 0.0  # dwell and pause time of the visits finished (not driving)
    _dwell_from: float | None = None
    _dwell_until: float | None = None
    # The visit's tasks: time spent in them so far (not driving), and since when the
    # one running runs.
    _tasks_done_s: float = 0.0
    _task_from: float | None = None
    _paused_at: float | None = None
    _finished_at: float | None = None
    _resumed = False  # a resumed run: its actual duration is only what was left
    _estimates: list[_Estimate] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.eta_s = self.prediction.expected_s
        self.eta_upper_s = self.prediction.upper_s

    def __call__(self, event: MissionEvent) -> None:
        if isinstance(event, MissionStarted):
            self._start = event.t
            self._resumed = event.resumed_from is not None
        elif isinstance(event, WaypointStarted):
            self._dwell_from = self._dwell_until = None
            if (event.loop, event.index) != self._loop_index:
                self._loop_index = (event.loop, event.index)
                self._visit = self._visit_at(event.loop, event.index)
                self._drive_left_s = self._visit.drive_s if self._visit else 0.0
            self._update(event.t)
        elif isinstance(event, WaypointProgress):
            if self.from_pose is not None:
                self._predict_from(Pose2D(event.x, event.y, event.yaw))
            visit = self._visit
            remaining = event.distance_remaining
            known = remaining is not None and math.isfinite(remaining)
            if visit is not None and visit.leg is not None and known:
                assert remaining is not None
                self._drive_left_s = visit.leg.time_left(remaining)
            self._update(event.t)
        elif isinstance(event, WaypointDwelling):
            self._drive_left_s = 0.0
            self._dwell_from = event.t
            self._dwell_until = event.t + event.seconds
            self._update(event.t)
        elif isinstance(event, TaskStarted):
            self._drive_left_s = 0.0
            if self._dwell_from is not None:  # the dwell is over once a task starts
                self._waiting_s += event.t - self._dwell_from
                self._dwell_from = self._dwell_until = None
            self._task_from = event.t
            self._update(event.t)
        elif isinstance(event, TaskFinished):
            if self._task_from is not None:
                self._tasks_done_s += event.t - self._task_from
                self._waiting_s += event.t - self._task_from
                self._task_from = None
            self._update(event.t)
        elif isinstance(event, WaypointFinished):
            if self._visit is not None:
                self._drive_done_s += self._visit.drive_s
            if self._dwell_from is not None:  # the dwell as it was (an operator may cut it)
                self._waiting_s += event.t - self._dwell_from
            if self._task_from is not None:  # a task cut short by the visit's end
                self._waiting_s += event.t - self._task_from
            self._visit, self._loop_index, self._drive_left_s = None, None, 0.0
            self._dwell_from = self._dwell_until = None
            self._tasks_done_s, self._task_from = 0.0, None
        elif isinstance(event, MissionPaused):
            self._paused_at = event.t
        elif isinstance(event, MissionResumed):
            self._waiting_s += event.paused_for
            self._paused_at = None
        elif isinstance(event, MissionFinished):
            self._finished_at = event.t
            self.eta_s = self.eta_upper_s = 0.0

    def _predict_from(self, pose: Pose2D) -> None:
        """The prediction from the robot's first pose (its first leg counted now)."""
        assert self.from_pose is not None
        from_pose, self.from_pose = self.from_pose, None
        if self._drive_done_s > 0.0 or self._loop_index != (0, 0):
            return  # too late: the first leg is behind
        self.prediction = from_pose(pose)
        self._visit = self._visit_at(0, 0)
        self._drive_left_s = self._visit.drive_s if self._visit else 0.0

    def _visit_at(self, loop: int, index: int) -> VisitPrediction | None:
        visits = self.prediction.first_loop if loop == 0 else self.prediction.later_loop
        return self.prediction.visit(loop, index) if 0 <= index < len(visits) else None

    def _update(self, now: float) -> None:
        """The time to go at ``now`` (mission clock) from what is known so far."""
        if self._start is None or self._loop_index is None:
            return
        loop, index = self._loop_index
        after = self.prediction.after(loop, index)
        after_upper = self.prediction.after(loop, index, "upper")
        if after is None or after_upper is None:
            self.eta_s = self.eta_upper_s = None  # a patrol that loops forever has no end
            return
        visit = self._visit
        elapsed = now - self._start
        # Driving achieved against predicted: the ground covered so far, both ways.
        predicted = self._drive_done_s + (visit.drive_s - self._drive_left_s if visit else 0.0)
        dwelt = now - self._dwell_from if self._dwell_from is not None else 0.0
        in_task = now - self._task_from if self._task_from is not None else 0.0
        driven = elapsed - self._waiting_s - dwelt - in_task
        ratio = 1.0
        if self.correct_by_achieved_speed and predicted >= RATIO_AFTER_S and driven > 0.0:
            ratio = min(max(driven / predicted, RATIO_LIMITS[0]), RATIO_LIMITS[1])
        dwell_left = 0.0
        tasks_begun = self._tasks_done_s > 0.0 or self._task_from is not None
        if self._dwell_until is not None:
            dwell_left = max(self._dwell_until - now, 0.0)
        elif visit is not None and not tasks_begun:
            dwell_left = visit.dwell_s
        tasks = visit.tasks if visit is not None else None
        spent = self._tasks_done_s + in_task
        task_s = max(tasks.expected_s - spent, 0.0) if tasks is not None else 0.0
        task_upper_s = max(tasks.upper_s - spent, task_s) if tasks is not None else 0.0
        later_drive = self.prediction.after(loop, index, "drive") or 0.0
        drive_left = (self._drive_left_s + later_drive) * ratio
        here = dwell_left + task_s
        self.eta_s = drive_left + here + (after - later_drive)
        self.eta_upper_s = drive_left + dwell_left + task_upper_s + (after_upper - later_drive)
        if not self._estimates or elapsed - self._estimates[-1].elapsed_s >= KEEP_EVERY_S:
            self._estimates.append(_Estimate(elapsed, elapsed + self.eta_s))

    def accuracy(self) -> dict[str, Any] | None:
        """The predictions against the actual duration (the report's ``eta``), or None
        before the mission has ended, when it loops forever or was resumed (the prediction
        is the whole mission's)."""
        expected = self.prediction.expected_s
        if self._start is None or self._finished_at is None or expected is None:
            return None
        if self._resumed:
            return None
        actual = self._finished_at - self._start
        checks = []
        for fraction in CHECKPOINTS:
            at = fraction * actual
            if fraction == 0.0:
                estimate = _Estimate(0.0, expected)
            else:
                earlier = [e for e in self._estimates if e.elapsed_s <= at]
                if not earlier:
                    continue
                estimate = earlier[-1]
            error = estimate.end_s - actual
            checks.append(
                {
                    "at_percent": round(fraction * 100),
                    "elapsed_s": round(estimate.elapsed_s, 1),
                    "predicted_s": round(estimate.end_s, 1),
                    "error_s": round(error, 1),
                    "error_percent": round(100.0 * error / actual, 1) if actual > 0 else None,
                }
            )
        upper = self.prediction.upper_s
        return {
            "expected_s": round(expected, 1),
            # None too when a task has no time limit (an input task): no upper bound.
            "upper_s": round(upper, 1) if upper is not None and math.isfinite(upper) else None,
            "actual_s": round(actual, 1),
            "planned": self.prediction.planned,
            "checkpoints": checks,
        }


__all__ = ["CHECKPOINTS", "EtaEstimator"]
