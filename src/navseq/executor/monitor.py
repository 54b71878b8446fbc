"""How one goal is going: progress towards it, and how long since the last progress.

The executor makes an :class:`AttemptMonitor` for every goal it sends and asks it
whether the goal ran out of time (the goal timeout) or stalled (the stall timeout).

Progress is judged on one measure per goal, the best one available: the navigator's
distance remaining along its plan, else the distance along the latest plan from the
robot's projection onto it, else the straight-line distance. Switching to a better
measure restarts the best distance from the new measure's value; a re-plan shifts it
by how much longer or shorter the new plan is from where the robot stands, so neither
counts as progress nor as its loss. The stall clock itself is never restarted by
either. Near the goal, turning towards the goal's yaw is progress too.

While the fleet holds the robot back (:meth:`AttemptMonitor.hold` to
:meth:`AttemptMonitor.release`: it waits, or gives way to another robot) both clocks
stand still, and progress is judged afresh after it: the robot was moved off its way.
"""

from __future__ import annotations

import enum

from navseq.geometry import Pose2D, normalize_angle, remaining_along_path
from navseq.navigators.base import Goal

#: The distance to the goal must drop this much below its best to count as progress (m).
PROGRESS_DISTANCE = 0.05
#: Near the goal, the yaw error must drop this much below its best to count (rad).
PROGRESS_YAW = 0.05
#: Within this distance of the goal, turning towards the goal yaw counts as progress (m).
YAW_PROGRESS_RADIUS = 0.3

Path = tuple[tuple[float, float], ...]


class Measure(enum.IntEnum):
    """How the distance still to go is measured; a higher value is a better measure."""

    STRAIGHT = 1  # straight line to the goal: no plan known
    PLAN = 2  # along the latest plan, from the robot's projection onto it
    NAVIGATOR = 3  # the navigator's own distance remaining (along its plan)


class AttemptMonitor:
    """Progress and deadlines of one goal, from the moment it was sent.

    ``sent_at`` and ``last_progress_at`` are times on the navigator's clock; a pause
    moves both on (see :meth:`resumed`).
    """

    def __init__(self, goal: Goal, sent_at: float):
        self.goal = goal
        self.sent_at = sent_at
        self.last_progress_at = sent_at
        self.plan: Path | None = None  # the latest plan's path
        self.feedback_seen = False  # the navigator reports feedback for this goal
        self.measure: Measure | None = None  # the best measure seen so far
        self.best_distance: float | None = None  # on ``measure``; None: the next value sets it
        self.best_yaw_error: float | None = None
        self.held_since: float | None = None  # while the fleet holds the robot back

    def resumed(self, goal: Goal, paused_for: float) -> AttemptMonitor:
        """A monitor for ``goal``, sent again after a pause of ``paused_for`` seconds.

        Its deadlines are this one's moved on by the pause; its progress starts afresh
        (the robot stood still, and the stack plans the new goal anew).
        """
        monitor = AttemptMonitor(goal, self.sent_at + paused_for)
        monitor.last_progress_at = self.last_progress_at + paused_for
        return monitor

    def hold(self, now: float) -> None:
        """The fleet holds the robot back from now on: the clocks stand still."""
        if self.held_since is None:
            self.held_since = now

    def release(self, now: float) -> float | None:
        """The hold ended at ``now``: the deadlines move on by its length (returned;
        None when the robot was not held), and progress is judged afresh."""
        since, self.held_since = self.held_since, None
        if since is None:
            return None
        held = max(0.0, now - since)
        self.sent_at += held
        self.last_progress_at += held
        self.measure, self.best_distance, self.best_yaw_error = None, None, None
        return held

    def overdue(
        self, now: float, goal_timeout_s: float | None, stall_timeout_s: float | None
    ) -> str | None:
        """``"timeout"`` or ``"stalled"`` when the goal ran out of time, else None
        (never while the robot is held back: its clocks stand still)."""
        if self.held_since is not None:
            return None
        if goal_timeout_s is not None and now - self.sent_at >= goal_timeout_s:
            return "timeout"
        if stall_timeout_s is not None and now - self.last_progress_at >= stall_timeout_s:
            return "stalled"
        return None

    def remaining(self, pose: Pose2D) -> float:
        """Distance to go for display: along the known plan, else straight."""
        if self.plan is not None:
            return remaining_along_path(self.plan, pose.x, pose.y)
        return pose.distance_to(self.goal.pose)

    def adopt_plan(self, path: Path, pose: Pose2D | None) -> None:
        """Take a new plan; keep the best distance on its measure.

        A re-plan moves the best distance by how much the remaining path changed
        where the robot stands (``pose``), so a longer detour is not a lost progress
        and a shorter one not a gained one. Where the change cannot be measured (no
        earlier plan or no pose), the next value restarts the best distance.
        """
        if not path:
            return
        old, self.plan = self.plan, path
        if self.best_distance is None or self.measure not in (Measure.PLAN, Measure.NAVIGATOR):
            return  # a straight-line measure gives way to the plan at the next pose
        if old is None or pose is None:
            self.best_distance = None
            return
        self.best_distance += remaining_along_path(path, pose.x, pose.y) - remaining_along_path(
            old, pose.x, pose.y
        )

    def observe(self, now: float, pose: Pose2D, navigator_distance: float | None = None) -> bool:
        """Judge a pose (and the navigator's distance remaining, if it gave one).

        Returns whether it is progress; the stall clock restarts at ``now`` if so.
        Nothing is judged while the robot is held back (it drives aside, or waits).
        """
        if self.held_since is not None:
            return False
        goal = self.goal.pose
        straight = pose.distance_to(goal)
        progressed = self._distance_progressed(pose, straight, navigator_distance)
        if straight <= YAW_PROGRESS_RADIUS:
            # Turning in place to the goal yaw is progress too.
            yaw_error = abs(normalize_angle(goal.yaw - pose.yaw))
            if self.best_yaw_error is None:
                self.best_yaw_error = yaw_error
            elif yaw_error <= self.best_yaw_error - PROGRESS_YAW:
                self.best_yaw_error = yaw_error
                progressed = True
        if progressed:
            self.last_progress_at = now
        return progressed

    def _distance_progressed(
        self, pose: Pose2D, straight: float, navigator_distance: float | None
    ) -> bool:
        """Whether the distance to go dropped, judged on the best measure so far."""
        if navigator_distance is not None:
            measure, distance = Measure.NAVIGATOR, navigator_distance
        elif self.measure is Measure.NAVIGATOR:
            return False  # a pose alone says nothing on the navigator's measure
        elif self.plan is not None:
            measure = Measure.PLAN
            distance = remaining_along_path(self.plan, pose.x, pose.y)
        elif self.measure is None or self.measure is Measure.STRAIGHT:
            measure, distance = Measure.STRAIGHT, straight
        else:
            return False
        if self.measure is None or measure > self.measure:
            # Different measures are not comparable: start afresh on the better one.
            self.measure, self.best_distance = measure, distance
            return False
        if self.best_distance is None:
            self.best_distance = distance
            return False
        if distance <= self.best_distance - PROGRESS_DISTANCE:
            self.best_distance = distance
            return True
        return False


__all__ = [
    "PROGRESS_DISTANCE",
    "PROGRESS_YAW",
    "YAW_PROGRESS_RADIUS",
    "AttemptMonitor",
    "Measure",
]
