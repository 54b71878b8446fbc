"""One mission run as an explicit state machine.

:class:`MissionExecutor` decides what happens next in a mission; it never talks to a
navigator, never blocks, never sleeps and never reads a clock. It is driven from
outside through four inputs, each given the current time ``now`` (seconds on the
navigator's clock):

* :meth:`~MissionExecutor.start` once, to send the first goal;
* :meth:`~MissionExecutor.on_event` for every event the navigator reports;
* :meth:`~MissionExecutor.on_tick` regularly (every 0.1 s is plenty), with the
  latest robot pose, so that timeouts, dwell and back-off can expire;
* :meth:`~MissionExecutor.interrupt` when the run must end now (signal, crash).

Each input returns the commands (:mod:`navseq.executor.commands`) the caller must
apply to the navigator, in order. What happened is told to listeners as mission
events (:mod:`navseq.executor.events`), and :attr:`~MissionExecutor.result`
summarises the run. :func:`navseq.executor.runner.run_mission` is the usual driver.

Navigators are expected to report a vanished server with ``ServerLost`` (or the
goal's ``LOST`` status) and its return with ``ServerBack``; the executor then resends
the active goal without counting it as a failed attempt.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass, replace

from navseq.errors import NavseqError
from navseq.executor.commands import CancelGoal, ClearCostmaps, Command, SendGoal
from navseq.executor.events import (
    AttemptFailed,
    LoopStarted,
    MissionEvent,
    MissionFinished,
    MissionStarted,
    ServerStatusChanged,
    WaypointDwelling,
    WaypointFinished,
    WaypointOutcome,
    WaypointPlan,
    WaypointProgress,
    WaypointStarted,
)
from navseq.executor.result import MissionResult, WaypointResult
from navseq.executor.resume import ResumePoint
from navseq.geometry import Pose2D, normalize_angle
from navseq.mission.model import FailureAction, Mission, Policy, Waypoint
from navseq.navigators.base import (
    Goal,
    GoalDone,
    GoalFeedback,
    GoalPlan,
    GoalStatus,
    NavEvent,
    ServerBack,
    ServerLost,
)

#: Pause between a failed attempt and the next one, so a failing stack is not hammered.
RETRY_BACKOFF = 1.0
#: The distance to the goal must drop this much below its best to count as progress (m).
PROGRESS_DISTANCE = 0.05
#: Near the goal, the yaw error must drop this much below its best to count (rad).
PROGRESS_YAW = 0.05
#: Within this distance of the goal, turning towards the goal yaw counts as progress (m).
YAW_PROGRESS_RADIUS = 0.3
#: Reason recorded when the navigation server stayed away longer than allowed.
SERVER_LOST_REASON = "navigation server lost"

MissionListener = Callable[[MissionEvent], None]


class ExecutorState(enum.Enum):
    """Where the mission run is. Exactly one waypoint visit is current outside IDLE/FINISHED."""

    IDLE = "idle"  # start() not called yet
    ACTIVE = "active"  # a goal is out; waiting for its result, a timeout or pass-through
    DWELLING = "dwelling"  # goal reached; waiting the waypoint's dwell time
    WAITING_RETRY = "waiting_retry"  # attempt failed; back-off before the next attempt
    WAITING_SERVER = "waiting_server"  # server gone; the goal is resent when it is back
    FINISHED = "finished"  # the mission ended (see result.reason)


@dataclass
class _Attempt:
    """The goal currently out for the current visit, and how well it is going."""

    goal: Goal
    sent_at: float
    last_progress_at: float
    best_distance: float | None = None
    best_yaw_error: float | None = None
    plan_distance_seen: bool = False  # feedback gives distance along the plan: trust only it
    feedback_seen: bool = False


@dataclass
class _Visit:
    """One pass at one waypoint (a patrol visits each waypoint once per loop)."""

    loop: int
    index: int
    waypoint: Waypoint
    policy: Policy
    result: WaypointResult
    first_sent_at: float | None = None
    reached_at: float | None = None


class MissionExecutor:
    """The state machine of one mission run; see the module docstring for the protocol.

    ``resume`` starts at an earlier run's active visit instead of the first one
    (see :class:`~navseq.executor.resume.ResumePoint`). Goal ids are unique and
    increasing within a run; events about any other goal than the current one are
    ignored, so late results of replaced or cancelled goals do no harm.
    """

    def __init__(self, mission: Mission, *, resume: ResumePoint | None = None):
        if not mission.waypoints:
            raise NavseqError("the mission has no waypoints", source=mission.source)
        if resume is not None:
            _check_resume_point(mission, resume)
        self._mission = mission
        self._resume = resume
        self._listeners: list[MissionListener] = []
        self._state = ExecutorState.IDLE
        self._visits: dict[tuple[int, int], WaypointResult] = {}
        if resume is not None:
            for done in resume.done:
                self._visits[(done.loop, done.index)] = _result_for(mission, done)
        self._visit: _Visit | None = None
        self._attempt: _Attempt | None = None
        self._next_goal_id = 1
        self._deadline = 0.0  # end of dwell or back-off, by state
        self._clear_costmaps_before_send = False
        self._server_up = True
        self._server_lost_at = 0.0
        self._last_pose: Pose2D | None = None
        self._tick_pose_seen = False
        self._started_at: float | None = None
        self._now = 0.0
        self._loops_completed = 0
        self._success = False
        self._reason = "not started"

    # ------------------------------------------------------------------ public API

    def add_listener(self, listener: MissionListener) -> None:
        """Call ``listener(event)`` for every mission event, in order, synchronously."""
        self._listeners.append(listener)

    @property
    def state(self) -> ExecutorState:
        return self._state

    @property
    def finished(self) -> bool:
        return self._state is ExecutorState.FINISHED

    @property
    def now(self) -> float:
        """The latest time any input gave the executor (navigator clock, seconds)."""
        return self._now

    @property
    def current_goal(self) -> Goal | None:
        """The goal the navigator is pursuing for the mission, if one is out."""
        if self._state in (ExecutorState.ACTIVE, ExecutorState.WAITING_SERVER) and self._attempt:
            return self._attempt.goal
        return None

    @property
    def result(self) -> MissionResult:
        """The run so far: every visit of the mission, NOT_RUN for the ones not tried.

        For a mission that loops forever only the visits that happened are listed.
        """
        visits = [replace(v) for v in self._all_visits()]
        started = self._started_at if self._started_at is not None else self._now
        previous = self._resume.previous_duration if self._resume else 0.0
        return MissionResult(
            success=self._success,
            reason=self._reason,
            visits=visits,
            duration=(self._now - started) + previous,
            distance_driven=sum(v.distance_driven for v in visits),
            loops_completed=self._loops_completed,
        )

    def start(self, now: float) -> list[Command]:
        """Begin the mission (or resume it); returns the first goal to send."""
        if self._state is not ExecutorState.IDLE:
            raise RuntimeError("MissionExecutor.start() called twice")
        self._now = now
        self._started_at = now
        self._reason = "running"
        loop, index = (self._resume.loop, self._resume.index) if self._resume else (0, 0)
        self._loops_completed = loop
        self._emit(
            MissionStarted(
                t=now,
                waypoint_count=len(self._mission),
                loops=self._mission.loops,
                resumed_from=index if self._resume else None,
            )
        )
        return self._begin_visit(now, loop, index, new_loop=True)

    def on_event(self, event: NavEvent, now: float) -> list[Command]:
        """React to one navigator event."""
        self._now = max(self._now, now)
        if self.finished:
            return []
        if isinstance(event, ServerLost):
            return self._on_server_lost(now, event.reason or "server lost")
        if isinstance(event, ServerBack):
            return self._on_server_back(now)
        if self._state is not ExecutorState.ACTIVE or self._attempt is None:
            return []
        if getattr(event, "goal_id", None) != self._attempt.goal.goal_id:
            return []  # about a goal we replaced or gave up on
        if isinstance(event, GoalFeedback):
            return self._on_feedback(now, event)
        if isinstance(event, GoalPlan):
            self._emit(WaypointPlan(t=now, index=self._current.index, path=event.path))
            return []
        if isinstance(event, GoalDone):
            return self._on_goal_done(now, event)
        return []  # GoalAccepted needs no reaction: timeouts run from the send

    def on_tick(self, now: float, pose: Pose2D | None) -> list[Command]:
        """Let time pass: check timeouts, dwell, back-off and pass-through."""
        self._now = max(self._now, now)
        if self._state in (ExecutorState.IDLE, ExecutorState.FINISHED):
            return []
        commands: list[Command] = []
        if pose is not None:
            self._tick_pose_seen = True
            self._accumulate_distance(pose)
            if self._state is ExecutorState.ACTIVE:
                commands = self._observe_pose(now, pose, None)
                attempt = self._attempt
                if attempt is not None and not attempt.feedback_seen and not commands:
                    self._emit_progress(now, pose, pose.distance_to(attempt.goal.pose))
            if commands:
                return commands
        return self._check_clock(now)

    def skip(self, now: float, reason: str = "skipped by operator") -> list[Command]:
        """Give up the current visit (outcome SKIPPED) and go on with the next one.

        An operator's decision, whatever the waypoint's ``on_failure`` says. A visit
        already reached and dwelling just ends its dwell (outcome REACHED). When no
        visit follows, the goal is cancelled and the mission ends.
        """
        self._now = max(self._now, now)
        if self._state in (ExecutorState.IDLE, ExecutorState.FINISHED):
            return []
        if self._state is ExecutorState.DWELLING:
            self._finish_visit(now, WaypointOutcome.REACHED, "")
        else:
            self._finish_visit(now, WaypointOutcome.SKIPPED, reason)
        commands = self._advance(now)
        if self.finished:
            return [CancelGoal(), *commands]  # no next goal replaces the active one
        return commands

    def interrupt(self, now: float, reason: str) -> list[Command]:
        """End the run at once (``reason`` like ``"interrupted: SIGINT"``); cancels the goal."""
        self._now = max(self._now, now)
        if self.finished:
            return []
        if self._state is ExecutorState.IDLE:
            self._started_at = now
            self._finish_mission(now, reason)
            return []
        self._finish_visit(now, WaypointOutcome.FAILED, reason)
        self._finish_mission(now, reason)
        return [CancelGoal()]

    # ------------------------------------------------------------------ visits

    @property
    def _current(self) -> _Visit:
        assert self._visit is not None, "no current visit"
        return self._visit

    def _begin_visit(self, now: float, loop: int, index: int, *, new_loop: bool) -> list[Command]:
        if new_loop:
            self._emit(LoopStarted(t=now, loop=loop))
        waypoint = self._mission.waypoints[index]
        result = WaypointResult(
            index=index, loop=loop, name=waypoint.name, x=waypoint.x, y=waypoint.y, yaw=waypoint.yaw
        )
        self._visits[(loop, index)] = result
        self._visit = _Visit(loop, index, waypoint, self._mission.policy_for(index), result)
        return self._start_attempt(now)

    def _start_attempt(self, now: float) -> list[Command]:
        self._current.result.attempts += 1
        return self._send_goal(now)

    def _send_goal(self, now: float) -> list[Command]:
        """Send the current visit's goal (a fresh goal id), or wait for the server first."""
        if not self._server_up:
            self._state = ExecutorState.WAITING_SERVER
            self._attempt = None
            return self._check_clock(now)
        visit = self._current
        waypoint = visit.waypoint
        goal = Goal(self._next_goal_id, waypoint.pose, z=waypoint.z, frame=self._mission.frame)
        self._next_goal_id += 1
        self._attempt = _Attempt(goal=goal, sent_at=now, last_progress_at=now)
        if visit.first_sent_at is None:
            visit.first_sent_at = now
        self._state = ExecutorState.ACTIVE
        commands: list[Command] = []
        if self._clear_costmaps_before_send:
            commands.append(ClearCostmaps())
            self._clear_costmaps_before_send = False
        commands.append(SendGoal(goal))
        self._emit(
            WaypointStarted(
                t=now,
                index=visit.index,
                loop=visit.loop,
                attempt=visit.result.attempts,
                goal_id=goal.goal_id,
                x=waypoint.x,
                y=waypoint.y,
                yaw=waypoint.yaw,
            )
        )
        return commands

    def _is_last_visit(self, loop: int, index: int) -> bool:
        loops = self._mission.loops
        return loops is not None and loop == loops - 1 and index == len(self._mission) - 1

    def _next_position(self, loop: int, index: int) -> tuple[int, int] | None:
        if index + 1 < len(self._mission):
            return loop, index + 1
        if self._mission.loops is None or loop + 1 < self._mission.loops:
            return loop + 1, 0
        return None

    def _reached(self, now: float, *, passed_through: bool) -> list[Command]:
        visit = self._current
        visit.reached_at = now
        self._attempt = None
        if not passed_through and visit.policy.dwell > 0:
            self._state = ExecutorState.DWELLING
            self._deadline = now + visit.policy.dwell
            self._emit(WaypointDwelling(t=now, index=visit.index, seconds=visit.policy.dwell))
            return []
        self._finish_visit(now, WaypointOutcome.REACHED, "", passed_through=passed_through)
        return self._advance(now)

    def _advance(self, now: float) -> list[Command]:
        visit = self._current
        following = self._next_position(visit.loop, visit.index)
        if following is None:
            self._loops_completed += 1
            reached = all(v.outcome is WaypointOutcome.REACHED for v in self._all_visits())
            if reached:
                self._finish_mission(now, "completed")
            else:
                missed = sum(v.outcome is not WaypointOutcome.REACHED for v in self._all_visits())
                self._finish_mission(now, f"completed: {missed} waypoint visit(s) not reached")
            return []
        loop, index = following
        if loop != visit.loop:
            self._loops_completed += 1
        return self._begin_visit(now, loop, index, new_loop=loop != visit.loop)

    def _finish_visit(
        self, now: float, outcome: WaypointOutcome, reason: str, *, passed_through: bool = False
    ) -> None:
        visit = self._current
        result = visit.result
        end = visit.reached_at if outcome is WaypointOutcome.REACHED else now
        start = visit.first_sent_at
        result.outcome = outcome
        result.reason = reason
        result.passed_through = passed_through
        result.duration = (end - start) if (start is not None and end is not None) else 0.0
        self._attempt = None
        self._emit(
            WaypointFinished(
                t=now,
                index=visit.index,
                loop=visit.loop,
                outcome=outcome,
                attempts=result.attempts,
                duration=result.duration,
                distance_driven=result.distance_driven,
                reason=reason,
                passed_through=passed_through,
            )
        )

    def _finish_mission(self, now: float, reason: str) -> None:
        self._state = ExecutorState.FINISHED
        self._visit = None
        self._attempt = None
        self._reason = reason
        self._success = all(v.outcome is WaypointOutcome.REACHED for v in self._all_visits())
        self._emit(MissionFinished(t=now, success=self._success, reason=reason))

    def _all_visits(self) -> list[WaypointResult]:
        """Every visit in mission order; for finite missions also the ones not tried."""
        if self._mission.loops is None:
            return [self._visits[key] for key in sorted(self._visits)]
        visits = []
        for loop in range(self._mission.loops):
            for index, waypoint in enumerate(self._mission.waypoints):
                visit = self._visits.get((loop, index))
                if visit is None:
                    visit = WaypointResult(
                        index=index,
                        loop=loop,
                        name=waypoint.name,
                        x=waypoint.x,
                        y=waypoint.y,
                        yaw=waypoint.yaw,
                    )
                visits.append(visit)
        return visits

    # ------------------------------------------------------------------ failures

    def _attempt_failed(self, now: float, reason: str, *, cancel: bool) -> list[Command]:
        visit = self._current
        commands: list[Command] = [CancelGoal()] if cancel else []
        attempts = visit.result.attempts
        policy = visit.policy
        will_retry = policy.on_failure is FailureAction.RETRY or attempts <= policy.retries
        self._attempt = None
        visit.result.reason = reason
        self._emit(
            AttemptFailed(
                t=now, index=visit.index, attempt=attempts, reason=reason, will_retry=will_retry
            )
        )
        if will_retry:
            self._state = ExecutorState.WAITING_RETRY
            self._deadline = now + RETRY_BACKOFF
            self._clear_costmaps_before_send = policy.clear_costmaps_on_retry
            return commands
        if policy.on_failure is FailureAction.SKIP:
            self._finish_visit(now, WaypointOutcome.SKIPPED, reason)
            return commands + self._advance(now)
        label = visit.waypoint.label(visit.index)
        self._finish_visit(now, WaypointOutcome.FAILED, reason)
        self._finish_mission(now, f"stopped: {label} failed ({reason})")
        return commands

    def _on_goal_done(self, now: float, event: GoalDone) -> list[Command]:
        if event.status is GoalStatus.SUCCEEDED:
            return self._reached(now, passed_through=False)
        if event.status is GoalStatus.LOST:
            # Not the waypoint's fault: the stack lost track of the goal. Treat it as
            # a vanished server and resend once it reports back.
            self._mark_server_lost(now, event.text or "goal LOST")
            self._state = ExecutorState.WAITING_SERVER
            self._attempt = None
            return self._check_clock(now)
        return self._attempt_failed(now, event.status.value, cancel=False)

    def _mark_server_lost(self, now: float, reason: str) -> None:
        if self._server_up:
            self._server_up = False
            self._server_lost_at = now
            self._emit(ServerStatusChanged(t=now, available=False, reason=reason))

    def _on_server_lost(self, now: float, reason: str) -> list[Command]:
        self._mark_server_lost(now, reason)
        if self._state is ExecutorState.ACTIVE:
            self._state = ExecutorState.WAITING_SERVER
            self._attempt = None
        return []

    def _on_server_back(self, now: float) -> list[Command]:
        if not self._server_up:
            self._server_up = True
            self._emit(ServerStatusChanged(t=now, available=True))
        if self._state is ExecutorState.WAITING_SERVER:
            return self._send_goal(now)  # same attempt: the loss was not the waypoint's fault
        return []

    # ------------------------------------------------------------------ clock

    def _check_clock(self, now: float) -> list[Command]:
        state = self._state
        if state is ExecutorState.ACTIVE:
            attempt = self._attempt
            policy = self._current.policy
            assert attempt is not None
            if policy.goal_timeout is not None and now - attempt.sent_at >= policy.goal_timeout:
                return self._attempt_failed(now, "timeout", cancel=True)
            stalled_for = now - attempt.last_progress_at
            if policy.stall_timeout is not None and stalled_for >= policy.stall_timeout:
                return self._attempt_failed(now, "stalled", cancel=True)
        elif state is ExecutorState.DWELLING:
            if now >= self._deadline:
                self._finish_visit(now, WaypointOutcome.REACHED, "")
                return self._advance(now)
        elif state is ExecutorState.WAITING_RETRY:
            if now >= self._deadline:
                return self._start_attempt(now)
        elif state is ExecutorState.WAITING_SERVER:
            timeout = self._mission.server_timeout
            if timeout is not None and now - self._server_lost_at >= timeout:
                self._finish_visit(now, WaypointOutcome.FAILED, SERVER_LOST_REASON)
                self._finish_mission(now, SERVER_LOST_REASON)
                return [CancelGoal()]  # in case it comes back remembering the goal
        return []

    # ------------------------------------------------------------------ poses

    def _on_feedback(self, now: float, event: GoalFeedback) -> list[Command]:
        attempt = self._attempt
        assert attempt is not None
        attempt.feedback_seen = True
        if not self._tick_pose_seen:
            self._accumulate_distance(event.pose)
        commands = self._observe_pose(now, event.pose, event.distance_remaining)
        if not commands and self._attempt is attempt:
            remaining = event.distance_remaining
            if remaining is None:
                remaining = event.pose.distance_to(attempt.goal.pose)
            self._emit_progress(now, event.pose, remaining)
        return commands

    def _accumulate_distance(self, pose: Pose2D) -> None:
        if self._last_pose is not None and self._visit is not None:
            self._visit.result.distance_driven += self._last_pose.distance_to(pose)
        self._last_pose = pose

    def _observe_pose(self, now: float, pose: Pose2D, plan_distance: float | None) -> list[Command]:
        """Update progress from a pose; pass through the waypoint when close enough."""
        attempt = self._attempt
        visit = self._current
        assert attempt is not None
        goal = attempt.goal.pose
        straight = pose.distance_to(goal)
        radius = visit.policy.pass_through
        if (
            radius is not None
            and visit.policy.dwell == 0
            and straight <= radius
            and not self._is_last_visit(visit.loop, visit.index)
        ):
            # The next goal replaces this one at once, without a cancel: the robot
            # keeps rolling instead of braking at every intermediate point.
            return self._reached(now, passed_through=True)

        if plan_distance is not None:
            attempt.plan_distance_seen = True
            distance: float | None = plan_distance
        else:
            # Straight-line and along-the-plan distances are not comparable.
            distance = None if attempt.plan_distance_seen else straight
        progressed = False
        if distance is not None:
            if attempt.best_distance is None:
                attempt.best_distance = distance
            elif distance <= attempt.best_distance - PROGRESS_DISTANCE:
                attempt.best_distance = distance
                progressed = True
        if straight <= YAW_PROGRESS_RADIUS:
            # Turning in place to the goal yaw is progress too.
            yaw_error = abs(normalize_angle(goal.yaw - pose.yaw))
            if attempt.best_yaw_error is None:
                attempt.best_yaw_error = yaw_error
            elif yaw_error <= attempt.best_yaw_error - PROGRESS_YAW:
                attempt.best_yaw_error = yaw_error
                progressed = True
        if progressed:
            attempt.last_progress_at = now
        return []

    def _emit_progress(self, now: float, pose: Pose2D, remaining: float | None) -> None:
        visit = self._current
        self._emit(
            WaypointProgress(
                t=now,
                index=visit.index,
                x=pose.x,
                y=pose.y,
                yaw=pose.yaw,
                distance_remaining=remaining,
                distance_driven=visit.result.distance_driven,
            )
        )

    def _emit(self, event: MissionEvent) -> None:
        for listener in self._listeners:
            listener(event)


def _check_resume_point(mission: Mission, resume: ResumePoint) -> None:
    count = len(mission)
    if not 0 <= resume.index < count:
        raise NavseqError(
            f"the journal resumes at waypoint {resume.index + 1}, "
            f"but the mission has only {count} waypoint(s)",
            source=mission.source,
        )
    if resume.loop < 0 or (mission.loops is not None and resume.loop >= mission.loops):
        raise NavseqError(
            f"the journal resumes in loop {resume.loop + 1}, "
            f"but the mission runs {mission.loops} loop(s)",
            source=mission.source,
        )
    for done in resume.done:
        if not 0 <= done.index < count:
            raise NavseqError(
                f"the journal records waypoint {done.index + 1}, "
                f"but the mission has only {count} waypoint(s)",
                source=mission.source,
            )


def _result_for(mission: Mission, done: WaypointResult) -> WaypointResult:
    """An earlier run's visit, with the waypoint's details taken from the mission."""
    waypoint = mission.waypoints[done.index]
    return replace(done, name=waypoint.name, x=waypoint.x, y=waypoint.y, yaw=waypoint.yaw)


__all__ = [
    "PROGRESS_DISTANCE",
    "PROGRESS_YAW",
    "RETRY_BACKOFF",
    "SERVER_LOST_REASON",
    "YAW_PROGRESS_RADIUS",
    "ExecutorState",
    "MissionExecutor",
    "MissionListener",
]
