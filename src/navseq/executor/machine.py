"""One mission run as an explicit state machine.

:class:`MissionExecutor` decides what happens next in a mission; it never talks to a
navigator, never blocks, never sleeps and never reads a clock. It is driven from
outside through four inputs, each given the current time ``now`` (seconds on the
navigator's clock):

* :meth:`~MissionExecutor.start` once, to send the first goal;
* :meth:`~MissionExecutor.on_event` for every event the navigator reports, with the
  robot's pose when known (the arrival check on SUCCEEDED needs it);
* :meth:`~MissionExecutor.on_tick` regularly (every 0.1 s is plenty), with the
  latest robot pose (and odometry pose, when known), so that timeouts, dwell and
  back-off can expire and distance driven adds up;
* :meth:`~MissionExecutor.skip`, :meth:`~MissionExecutor.pause`,
  :meth:`~MissionExecutor.resume` and :meth:`~MissionExecutor.cancel`: operator
  requests (one path for the ROS nodes and the CLI, see
  :class:`~navseq.executor.control.MissionControl`);
* :meth:`~MissionExecutor.interrupt` when the run must end now (signal, crash).

Pausing cancels the active goal (the robot stops) and holds the run in
:attr:`ExecutorState.PAUSED`, where no deadline runs: on resume the goal timeout, the
stall timeout, a dwell, a retry back-off and the server wait all move on by the time
spent paused, and an interrupted goal is sent again (a fresh goal id, the same
attempt). Durations in the result stay what they were on the clock, pauses included.

Each input returns the commands (:mod:`navseq.executor.commands`) the caller must
apply to the navigator, in order. What happened is told to listeners as mission
events (:mod:`navseq.executor.events`), and :attr:`~MissionExecutor.result`
summarises the run. :func:`navseq.executor.runner.run_mission` is the usual driver.

Navigators are expected to report a vanished server with ``ServerLost`` (or the
goal's ``LOST`` status) and its return with ``ServerBack``; the executor then resends
the active goal without counting it as a failed attempt.

The executor believes the robot, not only the navigation stack:

* **Arrival.** Every SUCCEEDED is checked against the robot's pose (move_base can end
  a fresh goal SUCCEEDED with the robot metres away, ros-planning/navigation #949; Nav2
  can end a goal that preempted another SUCCEEDED where the old one ended). Farther
  than the goal tolerance (a pass-through visit: its radius) plus
  :data:`ARRIVAL_SLACK_M` (or, where the robot stops, turned more than the yaw
  tolerance plus :data:`ARRIVAL_SLACK_RAD`), the attempt fails with a reason like
  ``succeeded far from goal (2.38 m)`` and the waypoint's policy decides what follows.
* **Progress** (the stall timeout) is judged on one measure per attempt, the best
  one available: the navigator's distance remaining along its plan, else the
  distance along the latest ``GoalPlan`` from the robot's projection onto it, else
  the straight-line distance. Switching to a better measure restarts the best
  distance from the new measure's value; a re-plan shifts it by how much longer or
  shorter the new plan is from where the robot stands, so neither counts as
  progress nor as its loss. The stall clock itself is never restarted by either.
* **Distance driven** adds up odometry poses when the navigator gives them
  (continuous, free of localisation jumps), map poses otherwise.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

from navseq.errors import NavseqError
from navseq.executor.commands import CancelGoal, ClearCostmaps, Command, SendGoal
from navseq.executor.events import (
    AttemptFailed,
    LoopStarted,
    MissionEvent,
    MissionFinished,
    MissionPaused,
    MissionResumed,
    MissionStarted,
    ServerStatusChanged,
    WaypointDwelling,
    WaypointFinished,
    WaypointOutcome,
    WaypointPlan,
    WaypointProgress,
    WaypointStarted,
)
from navseq.executor.result import AttemptResult, MissionResult, VisitLog, WaypointResult
from navseq.executor.resume import ResumePoint
from navseq.geometry import Pose2D, normalize_angle, remaining_along_path
from navseq.mission.model import FailureAction, Mission, Policy, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE, GoalTolerance, RobotProfile
from navseq.navigators.base import (
    Goal,
    GoalDone,
    GoalFeedback,
    GoalOutcome,
    GoalPlan,
    NavEvent,
    ServerBack,
    ServerLost,
)
from navseq.track import simplify_path

#: Pause between a failed attempt and the next one, so a failing stack is not hammered.
RETRY_BACKOFF = 1.0
#: The distance to the goal must drop this much below its best to count as progress (m).
PROGRESS_DISTANCE = 0.05
#: Near the goal, the yaw error must drop this much below its best to count (rad).
PROGRESS_YAW = 0.05
#: Within this distance of the goal, turning towards the goal yaw counts as progress (m).
YAW_PROGRESS_RADIUS = 0.3
#: Planned paths are told to sinks simplified to within this distance (m).
PLAN_TOLERANCE = 0.01
#: Reason recorded when the navigation server stayed away longer than allowed.
SERVER_LOST_REASON = "navigation server lost"
#: Added to the goal's xy tolerance when checking a SUCCEEDED against the robot's pose
#: (m): amcl's pose jitters by a few centimetres, and the pose the executor sees may be
#: a tick (0.1 s, 0.02 m at TurtleBot3 speed) older than the stack's own.
ARRIVAL_SLACK_M = 0.10
#: Added to the goal's yaw tolerance in the same check (rad, about 6°), for the same
#: reasons (amcl's heading jitter, a robot still settling its last turn).
ARRIVAL_SLACK_RAD = 0.10

MissionListener = Callable[[MissionEvent], None]


class ExecutorState(enum.Enum):
    """Where the mission run is. Exactly one waypoint visit is current outside IDLE/FINISHED."""

    IDLE = "idle"  # start() not called yet
    ACTIVE = "active"  # a goal is out; waiting for its result, a timeout or pass-through
    DWELLING = "dwelling"  # goal reached; waiting the waypoint's dwell time
    WAITING_RETRY = "waiting_retry"  # attempt failed; back-off before the next attempt
    WAITING_SERVER = "waiting_server"  # server gone; the goal is resent when it is back
    PAUSED = "paused"  # the operator paused: no goal out, no deadline running
    FINISHED = "finished"  # the mission ended (see result.reason)


class _Measure(enum.IntEnum):
    """How the distance still to go is measured; a higher value is a better measure."""

    STRAIGHT = 1  # straight line to the goal: no plan known
    PLAN = 2  # along the latest GoalPlan, from the robot's projection onto it
    NAVIGATOR = 3  # the navigator's own distance remaining (along its plan)


@dataclass
class _Attempt:
    """The goal currently out for the current visit, and how well it is going."""

    goal: Goal
    sent_at: float
    last_progress_at: float
    best_distance: float | None = None  # on ``measure``; None: the next value sets it
    best_yaw_error: float | None = None
    measure: _Measure | None = None  # the best measure seen for this goal so far
    plan: tuple[tuple[float, float], ...] | None = None  # the latest GoalPlan's path
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
    attempt_sent_at: float = 0.0  # when the current attempt's goal was first sent
    attempt_start_distance: float = 0.0  # the visit's distance driven at that moment
    # The stack's count of recovery behaviours for the current attempt's goal, when the
    # stack gives one (Nav2's number_of_recoveries); None: not known.
    attempt_recoveries: int | None = None


class MissionExecutor:
    """The state machine of one mission run; see the module docstring for the protocol.

    ``resume`` starts at an earlier run's active visit instead of the first one
    (see :class:`~navseq.executor.resume.ResumePoint`). Goal ids are unique and
    increasing within a run; events about any other goal than the current one are
    ignored, so late results of replaced or cancelled goals do no harm.

    ``robot`` gives the goal tolerance for the arrival check where a waypoint's
    policy sets none (``xy_tolerance_m`` / ``yaw_tolerance_rad``); without it the mission's
    ``robot:`` profile, else :data:`~navseq.mission.robot.DEFAULT_PROFILE`.
    """

    def __init__(
        self,
        mission: Mission,
        *,
        resume: ResumePoint | None = None,
        robot: RobotProfile | None = None,
    ):
        if not mission.waypoints:
            raise NavseqError("the mission has no waypoints", source=mission.source)
        if resume is not None:
            _check_resume_point(mission, resume)
        self._mission = mission
        self._resume = resume
        self._robot = robot or mission.robot or DEFAULT_PROFILE
        self._listeners: list[MissionListener] = []
        self._state = ExecutorState.IDLE
        # Finished visits: counted per waypoint, the latest kept in full (bounded memory).
        self._log = VisitLog(mission.waypoints, mission.loops)
        if resume is not None:
            if resume.earlier is not None:  # a copy: the point may be used again
                self._log = resume.earlier.relabelled(mission.waypoints, mission.loops)
            for done in sorted(resume.done, key=lambda v: (v.loop, v.index)):
                self._log.add(_result_for(mission, done))
        self._visit: _Visit | None = None
        self._attempt: _Attempt | None = None
        self._next_goal_id = 1
        self._deadline = 0.0  # end of dwell or back-off, by state
        self._clear_costmaps_before_send = False
        self._server_up = True
        self._server_lost_at = 0.0
        self._last_pose: Pose2D | None = None  # of the distance driven, map frame
        self._last_odom_pose: Pose2D | None = None  # of the distance driven, odom frame
        self._latest_pose: Pose2D | None = None  # any input's, for the arrival check
        self._start_pose: Pose2D | None = None  # the first robot pose of the run
        self._tick_pose_seen = False
        self._started_at: float | None = None
        # While PAUSED: the state to go back to, when the pause began, and the attempt
        # whose goal the pause cancelled (to send again on resume).
        self._paused_from: ExecutorState | None = None
        self._paused_at = 0.0
        self._paused_attempt: _Attempt | None = None
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
    def paused(self) -> bool:
        return self._state is ExecutorState.PAUSED

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
        """The run so far: every visit counted per waypoint, the latest listed in full.

        A small finite mission lists every visit, NOT_RUN for the ones not tried; a
        patrol or a huge mission lists what :class:`~navseq.executor.result.VisitLog`
        keeps. The visit under way is listed as NOT_RUN with its attempts so far.
        """
        started = self._started_at if self._started_at is not None else self._now
        previous = self._resume.previous_duration if self._resume else 0.0
        return self._log.result(
            success=self._success,
            reason=self._reason,
            duration=(self._now - started) + previous,
            loops_completed=self._loops_completed,
            start_pose=self._start_pose,
            active=self._active_result(),
        )

    def _active_result(self) -> WaypointResult | None:
        """The current visit's result while it is not finished (not yet in the log)."""
        visit = self._visit
        if visit is None or (visit.loop, visit.index) in self._log:
            return None
        return visit.result

    @property
    def robot(self) -> RobotProfile:
        """The robot profile whose goal tolerance the arrival check uses by default."""
        return self._robot

    def goal_tolerance(self, policy: Policy) -> GoalTolerance:
        """The arrival tolerance of a visit: its policy's, else the robot profile's."""
        default = self._robot.goal_tolerance
        return GoalTolerance(
            default.xy_m if policy.xy_tolerance_m is None else policy.xy_tolerance_m,
            default.yaw_rad if policy.yaw_tolerance_rad is None else policy.yaw_tolerance_rad,
        )

    def start(self, now: float, pose: Pose2D | None = None) -> list[Command]:
        """Begin the mission (or resume it); returns the first goal to send.

        ``pose`` is the robot's pose now, if known: the run's start pose in the result
        (otherwise the first pose any later input gives).
        """
        if self._state is not ExecutorState.IDLE:
            raise RuntimeError("MissionExecutor.start() called twice")
        self._see_pose(pose)
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

    def on_event(self, event: NavEvent, now: float, pose: Pose2D | None = None) -> list[Command]:
        """React to one navigator event.

        ``pose`` is the robot's pose (mission frame) when the event is handled, if the
        navigator knows it. A SUCCEEDED is checked against it, else against the latest
        pose any input gave; with no pose at all the SUCCEEDED is believed.
        """
        self._now = max(self._now, now)
        if self.finished:
            return []
        self._see_pose(pose)
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
            self._on_plan(event)
            # Sinks get the plan's corners only: a journal, a picture and markers need no
            # point every grid cell, and a patrol's journal must not grow by whole plans.
            path = simplify_path(event.path, PLAN_TOLERANCE)
            self._emit(WaypointPlan(t=now, index=self._current.index, path=path))
            return []
        if isinstance(event, GoalDone):
            return self._on_goal_done(now, event)
        return []  # GoalAccepted needs no reaction: timeouts run from the send

    def on_tick(
        self, now: float, pose: Pose2D | None, odom_pose: Pose2D | None = None
    ) -> list[Command]:
        """Let time pass: check timeouts, dwell, back-off and pass-through.

        ``pose`` is the robot's pose in the mission frame, ``odom_pose`` its pose in
        the odometry frame (either None when unknown). Distance driven adds up
        successive odometry poses when given, map poses otherwise.
        """
        self._now = max(self._now, now)
        if self._state in (ExecutorState.IDLE, ExecutorState.FINISHED):
            return []
        commands: list[Command] = []
        if pose is not None or odom_pose is not None:
            self._tick_pose_seen = True
            self._accumulate_distance(pose, odom_pose)
        if pose is not None:
            self._see_pose(pose)
            if self._state is ExecutorState.ACTIVE:
                commands = self._observe_pose(now, pose, None)
                attempt = self._attempt
                if attempt is not None and not attempt.feedback_seen and not commands:
                    self._emit_progress(now, pose, self._remaining(attempt, pose))
            if commands:
                return commands
        return self._check_clock(now)

    def skip(self, now: float, reason: str = "skipped by operator") -> list[Command]:
        """Give up the current visit (outcome SKIPPED) and go on with the next one.

        An operator's decision, whatever the waypoint's ``on_failure`` says. A visit
        already reached and dwelling just ends its dwell (outcome REACHED). When no
        visit follows, the goal is cancelled and the mission ends. A paused mission is
        resumed by a skip: the next waypoint's goal goes out.
        """
        self._now = max(self._now, now)
        if self._state in (ExecutorState.IDLE, ExecutorState.FINISHED):
            return []
        if self._state is ExecutorState.PAUSED:
            self._end_pause(now)
        if self._state is ExecutorState.DWELLING:
            self._finish_visit(now, WaypointOutcome.REACHED, "")
        else:
            self._finish_visit(now, WaypointOutcome.SKIPPED, reason)
        commands = self._advance(now)
        if self.finished:
            return [CancelGoal(), *commands]  # no next goal replaces the active one
        return commands

    def pause(self, now: float, reason: str = "paused by operator") -> list[Command]:
        """Stop the robot and hold the run until :meth:`resume` (no deadline runs).

        Cancels the active goal, if one is out. Pausing a paused, finished or not yet
        started run does nothing.
        """
        self._now = max(self._now, now)
        if self._state in (ExecutorState.IDLE, ExecutorState.FINISHED, ExecutorState.PAUSED):
            return []
        commands: list[Command] = []
        if self._state is ExecutorState.ACTIVE:
            commands.append(CancelGoal())
        self._paused_from = self._state
        self._paused_at = now
        self._paused_attempt = self._attempt
        self._attempt = None  # the cancelled goal's last words are not the mission's
        self._state = ExecutorState.PAUSED
        self._emit(
            MissionPaused(
                t=now, index=self._current.index, reason=reason, state=self._paused_from.value
            )
        )
        return commands

    def resume(self, now: float) -> list[Command]:
        """End a pause: deadlines move on by the time paused; a cancelled goal is resent.

        Does nothing when the run is not paused.
        """
        self._now = max(self._now, now)
        if self._state is not ExecutorState.PAUSED:
            return []
        attempt = self._paused_attempt
        resumed = self._end_pause(now)
        if resumed is ExecutorState.ACTIVE:
            # Same attempt, fresh goal id: late events of the cancelled goal are ignored.
            commands = self._send_goal(now)
            if self._attempt is not None and attempt is not None:
                shift = now - self._paused_at
                self._attempt.sent_at = attempt.sent_at + shift
                self._attempt.last_progress_at = attempt.last_progress_at + shift
            return commands
        if resumed is ExecutorState.WAITING_SERVER and self._server_up:
            return self._send_goal(now)  # the server came back while paused
        return self._check_clock(now)

    def cancel(self, now: float, reason: str = "cancelled by operator") -> list[Command]:
        """The operator ends the mission: the goal is cancelled, the visit FAILED.

        The mission's reason is ``reason`` (sinks tell it from an interruption by
        its ``cancelled`` start).
        """
        return self._end_now(now, reason)

    def interrupt(self, now: float, reason: str) -> list[Command]:
        """End the run at once (``reason`` like ``"interrupted: SIGINT"``); cancels the goal."""
        return self._end_now(now, reason)

    def _end_now(self, now: float, reason: str) -> list[Command]:
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

    def _end_pause(self, now: float) -> ExecutorState:
        """Leave PAUSED for the state it interrupted, with its deadlines moved on."""
        resumed = self._paused_from
        assert resumed is not None
        shift = max(0.0, now - self._paused_at)
        self._deadline += shift  # dwell or back-off
        if not self._server_up and self._server_lost_at <= self._paused_at:
            self._server_lost_at += shift
        self._state = resumed
        self._attempt = None
        self._paused_from = None
        self._paused_attempt = None
        self._emit(MissionResumed(t=now, index=self._current.index, paused_for=shift))
        return resumed

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
            index=index,
            loop=loop,
            name=waypoint.name,
            x=waypoint.x,
            y=waypoint.y,
            yaw_rad=waypoint.yaw_rad,
        )
        self._visit = _Visit(loop, index, waypoint, self._mission.policy_for(index), result)
        return self._start_attempt(now)

    def _start_attempt(self, now: float) -> list[Command]:
        visit = self._current
        visit.result.attempts += 1
        visit.attempt_sent_at = now
        visit.attempt_start_distance = visit.result.distance_driven
        visit.attempt_recoveries = None
        return self._send_goal(now)

    def _passes_through(self, visit: _Visit) -> bool:
        """Whether the visit ends when the robot comes near, without stopping there."""
        return (
            visit.policy.pass_through_m is not None
            and visit.policy.dwell_s == 0
            and not self._is_last_visit(visit.loop, visit.index)
        )

    def _close_attempt(
        self, now: float, *, reached: bool, status: str | None, reason: str, text: str = ""
    ) -> AttemptResult:
        """Record how the current attempt ended in the visit's result."""
        visit = self._current
        record = AttemptResult(
            number=visit.result.attempts,
            reached=reached,
            status=status,
            reason=reason,
            text=text,
            duration=max(0.0, now - visit.attempt_sent_at),
            distance_driven=visit.result.distance_driven - visit.attempt_start_distance,
            recoveries=visit.attempt_recoveries,
        )
        visit.result.attempt_results.append(record)
        return record

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
                yaw=waypoint.yaw_rad,
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

    def _reached(
        self, now: float, *, passed_through: bool, status: str | None = None, text: str = ""
    ) -> list[Command]:
        visit = self._current
        visit.reached_at = now
        self._close_attempt(now, reached=True, status=status, reason="", text=text)
        self._attempt = None
        if not passed_through and visit.policy.dwell_s > 0:
            self._state = ExecutorState.DWELLING
            self._deadline = now + visit.policy.dwell_s
            self._emit(WaypointDwelling(t=now, index=visit.index, seconds=visit.policy.dwell_s))
            return []
        self._finish_visit(now, WaypointOutcome.REACHED, "", passed_through=passed_through)
        return self._advance(now)

    def _advance(self, now: float) -> list[Command]:
        visit = self._current
        following = self._next_position(visit.loop, visit.index)
        if following is None:
            self._loops_completed += 1
            if self._log.all_reached(self._active_result()):
                self._finish_mission(now, "completed")
            else:
                missed = self._log.not_reached(self._active_result())
                visits = "waypoint visit" if missed == 1 else "waypoint visits"
                self._finish_mission(now, f"completed: {missed} {visits} not reached")
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
        if outcome is not WaypointOutcome.REACHED and len(result.attempt_results) < result.attempts:
            # Ended by navseq while a goal was out (interrupt, operator skip, server gone).
            self._close_attempt(now, reached=False, status=None, reason=reason)
        end = visit.reached_at if outcome is WaypointOutcome.REACHED else now
        start = visit.first_sent_at
        result.outcome = outcome
        result.reason = reason
        result.passed_through = passed_through
        result.duration = (end - start) if (start is not None and end is not None) else 0.0
        if (visit.loop, visit.index) not in self._log:
            self._log.add(result)
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
        self._success = self._log.all_reached(self._active_result())
        self._emit(MissionFinished(t=now, success=self._success, reason=reason))

    # ------------------------------------------------------------------ failures

    def _attempt_failed(
        self,
        now: float,
        reason: str,
        *,
        cancel: bool,
        status: str | None = None,
        text: str = "",
    ) -> list[Command]:
        visit = self._current
        commands: list[Command] = [CancelGoal()] if cancel else []
        attempts = visit.result.attempts
        policy = visit.policy
        will_retry = policy.on_failure is FailureAction.RETRY or attempts <= policy.retries
        self._attempt = None
        visit.result.reason = reason
        record = self._close_attempt(
            now,
            reached=False,
            status=status,
            reason=reason,
            text=text,
        )
        self._emit(
            AttemptFailed(
                t=now,
                index=visit.index,
                attempt=attempts,
                reason=reason,
                will_retry=will_retry,
                status=record.status,
                text=text,
                duration=record.duration,
                distance_driven=record.distance_driven,
                loop=visit.loop,
                recoveries=record.recoveries,
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
        label = self._mission.waypoint_label(visit.index)
        self._finish_visit(now, WaypointOutcome.FAILED, reason)
        self._finish_mission(now, f"stopped: {label} failed ({reason})")
        return commands

    def _on_goal_done(self, now: float, event: GoalDone) -> list[Command]:
        # The stack's own name for how the goal ended goes into the record as is.
        if event.outcome is GoalOutcome.SUCCEEDED:
            status = event.status or "SUCCEEDED"
            miss = self._arrival_miss()
            if miss is None:
                return self._reached(now, passed_through=False, status=status, text=event.text)
            return self._attempt_failed(now, miss, cancel=False, status=status, text=event.text)
        if event.outcome is GoalOutcome.LOST:
            # Not the waypoint's fault: the stack lost track of the goal. Treat it as
            # a vanished server and resend once it reports back.
            self._mark_server_lost(now, event.text or f"goal {event.status or 'LOST'}")
            self._state = ExecutorState.WAITING_SERVER
            self._attempt = None
            return self._check_clock(now)
        status = event.status or "FAILED"
        return self._attempt_failed(now, status, cancel=False, status=status, text=event.text)

    def _arrival_miss(self) -> str | None:
        """Why a SUCCEEDED is not believed (the robot is not there), or None.

        Every SUCCEEDED is checked. A visit where the robot stops allows the goal
        tolerance plus :data:`ARRIVAL_SLACK_M`, and the yaw tolerance plus
        :data:`ARRIVAL_SLACK_RAD`. A pass-through visit allows its radius (or the goal
        tolerance, if larger: the stack may legitimately end the goal there before the
        robot comes within the radius) plus the same slack, and no yaw: passing through
        does not turn to the goal's heading. Nav2 can end a goal that preempted another
        SUCCEEDED with the robot still at the preempted goal (its tree keeps following
        the old path until the next re-plan), so pass-through visits need the check as
        much as stops. Without any robot pose the SUCCEEDED is believed.
        """
        visit = self._current
        attempt = self._attempt
        pose = self._latest_pose
        if pose is None or attempt is None:
            return None
        tolerance = self.goal_tolerance(visit.policy)
        goal = attempt.goal.pose
        off = pose.distance_to(goal)
        passes = self._passes_through(visit)
        radius = visit.policy.pass_through_m if passes else None
        allowed = tolerance.xy_m if radius is None else max(radius, tolerance.xy_m)
        if off > allowed + ARRIVAL_SLACK_M:
            return f"succeeded far from goal ({off:.2f} m)"
        if passes:
            return None
        yaw_off = abs(normalize_angle(goal.yaw - pose.yaw))
        if yaw_off > tolerance.yaw_rad + ARRIVAL_SLACK_RAD:
            return f"succeeded {math.degrees(yaw_off):.0f}° off the goal yaw"
        return None

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
            if policy.goal_timeout_s is not None and now - attempt.sent_at >= policy.goal_timeout_s:
                return self._attempt_failed(now, "timeout", cancel=True)
            stalled_for = now - attempt.last_progress_at
            if policy.stall_timeout_s is not None and stalled_for >= policy.stall_timeout_s:
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
        if event.recoveries is not None:
            self._current.attempt_recoveries = event.recoveries
        if not self._tick_pose_seen:
            self._accumulate_distance(event.pose)
        self._see_pose(event.pose)
        commands = self._observe_pose(now, event.pose, event.distance_remaining)
        if not commands and self._attempt is attempt:
            remaining = event.distance_remaining
            if remaining is None:
                remaining = self._remaining(attempt, event.pose)
            self._emit_progress(now, event.pose, remaining, event.recoveries, event.navigation_time)
        return commands

    @staticmethod
    def _remaining(attempt: _Attempt, pose: Pose2D) -> float:
        """Distance to go for display: along the known plan, else straight."""
        if attempt.plan is not None:
            return remaining_along_path(attempt.plan, pose.x, pose.y)
        return pose.distance_to(attempt.goal.pose)

    def _see_pose(self, pose: Pose2D | None) -> None:
        if pose is not None:
            self._latest_pose = pose
            if self._start_pose is None:
                self._start_pose = pose

    def _accumulate_distance(self, pose: Pose2D | None, odom_pose: Pose2D | None = None) -> None:
        step = 0.0
        if odom_pose is not None:
            if self._last_odom_pose is not None:
                step = self._last_odom_pose.distance_to(odom_pose)
        elif pose is not None and self._last_pose is not None:
            step = self._last_pose.distance_to(pose)
        if self._visit is not None:
            self._visit.result.distance_driven += step
        if pose is not None:
            self._last_pose = pose
        # Forgotten when missing, so that odometry coming back does not count the gap
        # a second time (the map poses counted it).
        self._last_odom_pose = odom_pose

    def _on_plan(self, event: GoalPlan) -> None:
        """Adopt a new plan for the attempt; keep the best distance on its measure.

        A re-plan moves the best distance by how much the remaining path changed
        where the robot stands, so a longer detour is not a lost progress and a
        shorter one not a gained one. Where the change cannot be measured (no
        earlier plan or no pose), the next value restarts the best distance.
        """
        attempt = self._attempt
        assert attempt is not None
        if not event.path:
            return
        old, attempt.plan = attempt.plan, event.path
        if attempt.best_distance is None or attempt.measure not in (
            _Measure.PLAN,
            _Measure.NAVIGATOR,
        ):
            return  # a straight-line measure gives way to the plan at the next pose
        pose = self._latest_pose
        if old is None or pose is None:
            attempt.best_distance = None
            return
        attempt.best_distance += remaining_along_path(
            event.path, pose.x, pose.y
        ) - remaining_along_path(old, pose.x, pose.y)

    def _observe_pose(
        self, now: float, pose: Pose2D, navigator_distance: float | None
    ) -> list[Command]:
        """Update progress from a pose; pass through the waypoint when close enough."""
        attempt = self._attempt
        visit = self._current
        assert attempt is not None
        goal = attempt.goal.pose
        straight = pose.distance_to(goal)
        radius = visit.policy.pass_through_m
        if radius is not None and straight <= radius and self._passes_through(visit):
            # The next goal replaces this one at once, without a cancel: the robot
            # keeps rolling instead of braking at every intermediate point.
            return self._reached(now, passed_through=True)

        progressed = self._distance_progressed(attempt, pose, straight, navigator_distance)
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

    @staticmethod
    def _distance_progressed(
        attempt: _Attempt, pose: Pose2D, straight: float, navigator_distance: float | None
    ) -> bool:
        """Whether the distance to go dropped, judged on the attempt's best measure."""
        if navigator_distance is not None:
            measure, distance = _Measure.NAVIGATOR, navigator_distance
        elif attempt.measure is _Measure.NAVIGATOR:
            return False  # a pose alone says nothing on the navigator's measure
        elif attempt.plan is not None:
            measure = _Measure.PLAN
            distance = remaining_along_path(attempt.plan, pose.x, pose.y)
        elif attempt.measure is None or attempt.measure is _Measure.STRAIGHT:
            measure, distance = _Measure.STRAIGHT, straight
        else:
            return False
        if attempt.measure is None or measure > attempt.measure:
            # Different measures are not comparable: start afresh on the better one.
            attempt.measure, attempt.best_distance = measure, distance
            return False
        if attempt.best_distance is None:
            attempt.best_distance = distance
            return False
        if distance <= attempt.best_distance - PROGRESS_DISTANCE:
            attempt.best_distance = distance
            return True
        return False

    def _emit_progress(
        self,
        now: float,
        pose: Pose2D,
        remaining: float | None,
        recoveries: int | None = None,
        navigation_time: float | None = None,
    ) -> None:
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
                recoveries=recoveries,
                navigation_time=navigation_time,
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
    if resume.earlier is not None and resume.earlier.waypoint_count != count:
        raise NavseqError(
            f"the journal records a mission of {resume.earlier.waypoint_count} waypoint(s), "
            f"but the mission has {count}",
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
    return replace(done, name=waypoint.name, x=waypoint.x, y=waypoint.y, yaw_rad=waypoint.yaw_rad)


__all__ = [
    "ARRIVAL_SLACK_M",
    "ARRIVAL_SLACK_RAD",
    "PROGRESS_DISTANCE",
    "PROGRESS_YAW",
    "RETRY_BACKOFF",
    "SERVER_LOST_REASON",
    "YAW_PROGRESS_RADIUS",
    "ExecutorState",
    "MissionExecutor",
    "MissionListener",
]
