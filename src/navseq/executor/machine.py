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
* :meth:`~MissionExecutor.interrupt` when the run must end now (signal, crash);
* :meth:`~MissionExecutor.on_task_done` when a task it started (``StartTask``) ended
  by itself: a reached waypoint's tasks run in order, after its dwell, each timed out
  from ``now`` by the executor (``CancelTask``) and its failure handled by the
  waypoint's ``retries`` / ``on_failure``.

Recoveries: when an attempt failed and another follows, the waypoint's ``recovery:``
list runs first, in order, after the back-off (``RunRecovery``; the navigator reports
the end as ``RecoveryDone`` among its events). Each is timed out by the executor
(``CancelRecovery``); a failed one is recorded and the next goes ahead, and the retry
goes ahead after the last, as Nav2's recovery subtree does. A pause stops the running
recovery (it runs again from its start on resume); skip, cancel and interrupt stop it.

Its states and the only ways between them are the table in
:mod:`navseq.executor.states`; every state change goes through it.

Pausing cancels the active goal (the robot stops) and holds the run in
:attr:`ExecutorState.PAUSED`, where no deadline runs: on resume the goal timeout, the
stall timeout, a dwell, a retry back-off and the server wait all move on by the time
spent paused, and an interrupted goal is sent again (a fresh goal id, the same
attempt). A running task is cancelled and runs again from its start on resume.
Durations in the result stay what they were on the clock, pauses included.

Each input returns the commands (:mod:`navseq.executor.commands`) the caller must
apply to the navigator, in order. What happened is told to listeners as mission
events (:mod:`navseq.executor.events`), and :attr:`~MissionExecutor.result`
summarises the run. :func:`navseq.executor.runner.run_mission` is the usual driver.

Fleets: a navigator whose robot the fleet holds back (it waits, or gives way to another
robot) says so with ``GoalHeld`` and ``GoalReleased`` about the goal out. In between the
goal's timeout and stall clocks stand still (the wait is the fleet's doing; the fleet
bounds it), and :class:`~navseq.executor.events.WaypointHeld` /
:class:`~navseq.executor.events.WaypointReleased` tell the sinks; each attempt's result
keeps the seconds held (``held``), part of its duration as a pause's are.

Navigators are expected to report a vanished server with ``ServerLost`` (or the
goal's ``LOST`` status) and its return with ``ServerBack``; the executor then resends
the active goal without counting it as a failed attempt.

The executor believes the robot, not only the navigation stack:

* **Arrival.** Every SUCCEEDED is checked against the robot's pose
  (:mod:`navseq.executor.arrival`); a robot that is not there fails the attempt with
  a reason like ``succeeded far from goal (2.38 m)``, and the waypoint's policy
  decides what follows.
* **Progress** (the stall timeout) is judged per goal by an
  :class:`~navseq.executor.monitor.AttemptMonitor`, on the best measure of the
  distance to go that the navigator allows.
* **Distance driven** adds up odometry poses when the navigator gives them
  (continuous, free of localisation jumps), map poses otherwise
  (:class:`~navseq.executor.odometer.Odometer`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from navseq.errors import NavseqError
from navseq.executor.arrival import arrival_miss, goal_tolerance
from navseq.executor.backoff import RETRY_BACKOFF, rejection_limit, retry_wait
from navseq.executor.commands import (
    CancelGoal,
    CancelRecovery,
    CancelTask,
    ClearCostmaps,
    Command,
    RunRecovery,
    SendGoal,
    StartTask,
)
from navseq.executor.events import (
    AttemptFailed,
    LoopStarted,
    MissionEvent,
    MissionFinished,
    MissionPaused,
    MissionResumed,
    MissionStarted,
    RecoveryFinished,
    RecoveryStarted,
    ServerStatusChanged,
    TaskFinished,
    TaskStarted,
    WaypointDwelling,
    WaypointFinished,
    WaypointHeld,
    WaypointOutcome,
    WaypointPlan,
    WaypointProgress,
    WaypointReleased,
    WaypointStarted,
)
from navseq.executor.monitor import AttemptMonitor
from navseq.executor.odometer import Odometer
from navseq.executor.result import MissionResult, RecoveryResult, TaskResult, WaypointResult
from navseq.executor.resume import ResumePoint, check_resume_point, visit_log
from navseq.executor.states import ExecutorState, Trigger, next_state
from navseq.executor.visit import Visit, next_position
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction, Mission, Policy
from navseq.mission.recovery import Recovery
from navseq.mission.robot import DEFAULT_PROFILE, GoalTolerance, RobotProfile
from navseq.mission.tasks import Task
from navseq.navigators.base import (
    REJECTED_STATUS,
    Goal,
    GoalDone,
    GoalFeedback,
    GoalHeld,
    GoalOutcome,
    GoalPlan,
    GoalReleased,
    NavEvent,
    RecoveryDone,
    ServerBack,
    ServerLost,
)
from navseq.tasks.base import TaskDone, TaskOutcome
from navseq.track import simplify_path

#: Planned paths are told to sinks simplified to within this distance (m).
PLAN_TOLERANCE = 0.01
#: Reason recorded when the navigation server stayed away longer than allowed.
SERVER_LOST_REASON = "navigation server lost"

#: How a pause ends for a state whose deadline simply goes on (the others resend the goal).
_GOES_ON = {
    ExecutorState.DWELLING: Trigger.DWELL_GOES_ON,
    ExecutorState.WAITING_RETRY: Trigger.BACKOFF_GOES_ON,
}

MissionListener = Callable[[MissionEvent], None]


@dataclass(frozen=True)
class _RunningRecovery:
    """The recovery a RunRecovery went out for (number: 1-based in the list), and when."""

    recovery_id: int
    recovery: Recovery
    number: int
    started_at: float


@dataclass(frozen=True)
class _RunningTask:
    """The task a StartTask went out for, and when (its timeout runs from then)."""

    task_id: int
    task: Task
    started_at: float


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
            check_resume_point(mission, resume)
        self._mission = mission
        self._resume = resume
        self._robot = robot or mission.robot or DEFAULT_PROFILE
        self._listeners: list[MissionListener] = []
        self._state = ExecutorState.IDLE
        # Finished visits: counted per waypoint, the latest kept in full (bounded memory).
        self._log = visit_log(mission, resume)
        self._visit: Visit | None = None
        self._monitor: AttemptMonitor | None = None  # the goal out for the current visit
        self._next_goal_id = 1
        self._next_task_id = 1
        self._task: _RunningTask | None = None  # the task out, in RUNNING_TASK
        self._recovery: _RunningRecovery | None = None  # the recovery out, in RECOVERING
        self._next_recovery_id = 1
        self._deadline = 0.0  # end of dwell or back-off, by state
        self._clear_costmaps_before_send = False
        self._server_up = True
        self._server_lost_at = 0.0
        self._odometer = Odometer()
        self._latest_pose: Pose2D | None = None  # any input's, for the arrival check
        self._start_pose: Pose2D | None = None  # the first robot pose of the run
        self._tick_pose_seen = False
        self._started_at: float | None = None
        # While PAUSED: the state to go back to, when the pause began, and the monitor
        # of the goal the pause cancelled (to send again on resume).
        self._paused_from: ExecutorState | None = None
        self._paused_at = 0.0
        self._paused_monitor: AttemptMonitor | None = None
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
        if self._state in (ExecutorState.ACTIVE, ExecutorState.WAITING_SERVER) and self._monitor:
            return self._monitor.goal
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
        return goal_tolerance(policy, self._robot)

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
        if isinstance(event, RecoveryDone):
            return self._on_recovery_done(now, event)
        if self._state is not ExecutorState.ACTIVE or self._monitor is None:
            return []
        if getattr(event, "goal_id", None) != self._monitor.goal.goal_id:
            return []  # about a goal we replaced or gave up on
        if isinstance(event, GoalFeedback):
            return self._on_feedback(now, event)
        if isinstance(event, GoalHeld):
            return self._on_held(now, event)
        if isinstance(event, GoalReleased):
            self._end_hold(now)
            return []
        if isinstance(event, GoalPlan):
            self._monitor.adopt_plan(event.path, self._latest_pose)
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
            self._drive(pose, odom_pose)
        if pose is not None:
            self._see_pose(pose)
            if self._state is ExecutorState.ACTIVE:
                commands = self._observe_pose(now, pose, None)
                monitor = self._monitor
                if monitor is not None and not monitor.feedback_seen and not commands:
                    self._emit_progress(now, pose, monitor.remaining(pose))
            if commands:
                return commands
        return self._check_clock(now)

    def on_task_done(self, done: TaskDone, now: float) -> list[Command]:
        """A task the executor started ended by itself (success or failure).

        Reports about any other task than the one running (cancelled, timed out) are
        ignored.
        """
        self._now = max(self._now, now)
        task = self._task
        if self._state is not ExecutorState.RUNNING_TASK or task is None:
            return []
        if done.task_id != task.task_id:
            return []
        if not done.succeeded:
            return self._task_failed(now, TaskOutcome.FAILED, done, cancel=False)
        visit = self._current
        self._record_task(now, TaskOutcome.SUCCEEDED, done)
        visit.next_task += 1
        visit.task_attempt = 1
        return self._tasks_or_finish(now)

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
        interrupted: ExecutorState = self._state
        if interrupted is ExecutorState.PAUSED:
            interrupted = self._end_pause(now)
        self._end_hold(now)
        stopped = [*self._stop_task(now, reason), *self._stop_recovery(now, reason)]
        if interrupted is ExecutorState.DWELLING:
            self._finish_visit(now, WaypointOutcome.REACHED, "")
        else:
            self._finish_visit(now, WaypointOutcome.SKIPPED, reason)
        commands = [*stopped, *self._advance(now)]
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
            self._end_hold(now)  # the pause holds every clock now; a new goal is held anew
            commands.append(CancelGoal())
        if self._task is not None:  # run again from its start on resume
            commands.append(CancelTask(self._task.task_id))
            self._task = None
        commands += self._stop_recovery(now, "paused")  # runs again from its start on resume
        paused_from = self._paused_from = self._state
        self._paused_at = now
        self._paused_monitor = self._monitor
        self._monitor = None  # the cancelled goal's last words are not the mission's
        self._move(Trigger.PAUSE)
        self._emit(
            MissionPaused(t=now, index=self._current.index, reason=reason, state=paused_from.value)
        )
        return commands

    def resume(self, now: float) -> list[Command]:
        """End a pause: deadlines move on by the time paused; a cancelled goal is resent.

        Does nothing when the run is not paused.
        """
        self._now = max(self._now, now)
        if self._state is not ExecutorState.PAUSED:
            return []
        monitor = self._paused_monitor
        paused_for = now - self._paused_at
        interrupted = self._end_pause(now)
        if interrupted in _GOES_ON:
            self._move(_GOES_ON[interrupted])
            return self._check_clock(now)
        if interrupted is ExecutorState.RUNNING_TASK:
            return self._start_task(now)
        if interrupted is ExecutorState.RECOVERING:
            return self._start_recovery(now)
        # ACTIVE: the same attempt, a fresh goal id (late events of the cancelled goal
        # are ignored). WAITING_SERVER: sent if the server came back while paused.
        commands = self._send_goal(now)
        if self._monitor is not None and monitor is not None:
            self._monitor = monitor.resumed(self._monitor.goal, paused_for)
        return commands

    def cancel(self, now: float, reason: str = "cancelled by operator") -> list[Command]:
        """The operator ends the mission: the goal is cancelled, the visit FAILED.

        The mission's reason is ``reason`` (sinks tell it from an interruption by
        its ``cancelled`` start).
        """
        return self._end_now(now, reason)

    def interrupt(self, now: float, reason: str) -> list[Command]:
        """End the run at once (``reason`` like ``"interrupted: SIGINT"``); cancels the goal."""
        return self._end_now(now, reason)

    # ------------------------------------------------------------------ state changes

    def _move(self, trigger: Trigger) -> None:
        """The one way the state changes: as the table says, or InvalidTransition."""
        self._state = next_state(self._state, trigger)

    def _end_now(self, now: float, reason: str) -> list[Command]:
        self._now = max(self._now, now)
        if self.finished:
            return []
        if self._state is ExecutorState.IDLE:
            self._started_at = now
            self._finish_mission(now, reason)
            return []
        self._end_hold(now)
        stopped = [*self._stop_task(now, reason), *self._stop_recovery(now, reason)]
        self._finish_visit(now, WaypointOutcome.FAILED, reason)
        self._finish_mission(now, reason)
        return [CancelGoal(), *stopped]

    def _end_pause(self, now: float) -> ExecutorState:
        """Move the interrupted state's deadlines on by the pause; the state to go back to.

        The run stays PAUSED: the caller's next trigger takes it out.
        """
        resumed = self._paused_from
        assert resumed is not None
        shift = max(0.0, now - self._paused_at)
        self._deadline += shift  # dwell or back-off
        if not self._server_up and self._server_lost_at <= self._paused_at:
            self._server_lost_at += shift
        self._monitor = None
        self._paused_from = None
        self._paused_monitor = None
        self._emit(MissionResumed(t=now, index=self._current.index, paused_for=shift))
        return resumed

    # ------------------------------------------------------------------ visits

    @property
    def _current(self) -> Visit:
        assert self._visit is not None, "no current visit"
        return self._visit

    def _begin_visit(self, now: float, loop: int, index: int, *, new_loop: bool) -> list[Command]:
        if new_loop:
            self._emit(LoopStarted(t=now, loop=loop))
        visit = self._visit = Visit.of(self._mission, loop, index)
        resume = self._resume
        if resume is not None and (loop, index) == (resume.loop, resume.index):
            # The visit a crash interrupted: its tasks that succeeded are not run again.
            visit.next_task = max(0, min(resume.tasks_done, len(visit.policy.tasks)))
            visit.result.tasks.extend(replace(task) for task in resume.tasks)
        return self._start_attempt(now)

    def _start_attempt(self, now: float) -> list[Command]:
        self._current.start_attempt(now)
        return self._send_goal(now)

    def _send_goal(self, now: float) -> list[Command]:
        """Send the current visit's goal (a fresh goal id), or wait for the server first."""
        if not self._server_up:
            self._move(Trigger.SERVER_AWAY)
            self._monitor = None
            return self._check_clock(now)
        visit = self._current
        waypoint = visit.waypoint
        goal = Goal(self._next_goal_id, waypoint.pose, z=waypoint.z, frame=self._mission.frame)
        self._next_goal_id += 1
        self._monitor = AttemptMonitor(goal, now)
        visit.goal_sent(now)
        self._move(Trigger.GOAL_SENT)
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

    def _reached(
        self, now: float, *, passed_through: bool, status: str | None = None, text: str = ""
    ) -> list[Command]:
        self._end_hold(now)
        visit = self._current
        visit.reached_at = now
        visit.close_attempt(now, reached=True, status=status, reason="", text=text)
        self._monitor = None
        if not passed_through and visit.policy.dwell_s > 0:
            self._move(Trigger.DWELL)
            self._deadline = now + visit.policy.dwell_s
            self._emit(WaypointDwelling(t=now, index=visit.index, seconds=visit.policy.dwell_s))
            return []
        if passed_through:
            self._finish_visit(now, WaypointOutcome.REACHED, "", passed_through=True)
            return self._advance(now)
        return self._tasks_or_finish(now)

    # ------------------------------------------------------------------ tasks

    def _tasks_or_finish(self, now: float) -> list[Command]:
        """At a reached waypoint: start its next task, or end the visit when none is left."""
        visit = self._current
        if visit.next_task < len(visit.policy.tasks):
            return self._start_task(now)
        self._finish_visit(now, WaypointOutcome.REACHED, "")
        return self._advance(now)

    def _start_task(self, now: float) -> list[Command]:
        visit = self._current
        task = visit.policy.tasks[visit.next_task]
        running = self._task = _RunningTask(self._next_task_id, task, now)
        self._next_task_id += 1
        self._move(Trigger.TASK)
        self._emit(
            TaskStarted(
                t=now,
                index=visit.index,
                loop=visit.loop,
                task=visit.next_task + 1,
                task_kind=task.kind,
                attempt=visit.task_attempt,
                description=task.describe(),
            )
        )
        return [StartTask(running.task_id, task, visit.index, visit.loop, visit.next_task + 1)]

    def _record_task(
        self, now: float, outcome: TaskOutcome, done: TaskDone | None, *, will_retry: bool = False
    ) -> None:
        """Put the running task's end into the visit's result and tell the sinks."""
        visit, running = self._current, self._task
        assert running is not None
        self._task = None
        detail = done.detail if done is not None else ""
        files = done.files if done is not None else ()
        output = done.output if done is not None else ()
        duration = max(0.0, now - running.started_at)
        number = visit.next_task + 1
        visit.result.tasks.append(
            TaskResult(
                number=number,
                kind=running.task.kind,
                outcome=outcome.value,
                attempt=visit.task_attempt,
                duration=duration,
                detail=detail,
                files=list(files),
                output=list(output),
            )
        )
        self._emit(
            TaskFinished(
                t=now,
                index=visit.index,
                loop=visit.loop,
                task=number,
                task_kind=running.task.kind,
                attempt=visit.task_attempt,
                outcome=outcome.value,
                duration=duration,
                detail=detail,
                files=files,
                output=output,
                will_retry=will_retry,
            )
        )

    def _stop_task(self, now: float, reason: str) -> list[Command]:
        """Cancel the running task, if any (skip, cancel, interrupt), recording why."""
        running = self._task
        if running is None:
            return []
        self._record_task(now, TaskOutcome.CANCELLED, TaskDone(running.task_id, False, reason))
        return [CancelTask(running.task_id)]

    def _task_failed(
        self, now: float, outcome: TaskOutcome, done: TaskDone, *, cancel: bool
    ) -> list[Command]:
        """A task failed or timed out: run it again, or the waypoint's on_failure decides.

        ``retries`` lets each task run again that many times (the goal is not sent
        again: the robot is there); ``on_failure: retry`` runs it again without limit.
        Each new run waits :data:`RETRY_BACKOFF` first.
        """
        visit = self._current
        running = self._task
        assert running is not None
        policy = visit.policy
        will_retry = (
            policy.on_failure is FailureAction.RETRY or visit.task_attempt <= policy.retries
        )
        commands: list[Command] = [CancelTask(running.task_id)] if cancel else []
        self._record_task(now, outcome, done, will_retry=will_retry)
        if will_retry:
            visit.task_attempt += 1
            self._deadline = now + RETRY_BACKOFF  # _check_clock starts it again
            return commands
        words = "timed out" if outcome is TaskOutcome.TIMED_OUT else "failed"
        reason = f"task {visit.next_task + 1} ({running.task.kind}) {words}"
        if done.detail:
            reason += f": {done.detail}"
        if policy.on_failure is FailureAction.SKIP:
            self._finish_visit(now, WaypointOutcome.SKIPPED, reason)
            return commands + self._advance(now)
        label = self._mission.waypoint_label(visit.index)
        self._finish_visit(now, WaypointOutcome.FAILED, reason)
        self._finish_mission(now, f"stopped: {label} failed ({reason})")
        return commands

    def _check_task(self, now: float) -> list[Command]:
        """A task's timeout, or the end of the back-off before a failed task runs again."""
        running = self._task
        if running is None:
            return self._start_task(now) if now >= self._deadline else []
        timeout = running.task.timeout_s
        if timeout is not None and now - running.started_at >= timeout:
            done = TaskDone(running.task_id, False, f"no end after {timeout:g} s")
            return self._task_failed(now, TaskOutcome.TIMED_OUT, done, cancel=True)
        return []

    def _advance(self, now: float) -> list[Command]:
        visit = self._current
        following = next_position(self._mission, visit.loop, visit.index)
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
        result = visit.finish(now, outcome, reason, passed_through=passed_through)
        if (visit.loop, visit.index) not in self._log:
            self._log.add(result)
        self._monitor = None
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
        self._move(Trigger.END)
        self._visit = None
        self._monitor = None
        self._reason = reason
        self._success = self._log.all_reached(self._active_result())
        self._emit(MissionFinished(t=now, success=self._success, reason=reason))

    # ------------------------------------------------------------------ recoveries

    def _start_recovery(self, now: float) -> list[Command]:
        """Run the visit's next due recovery (``visit.next_recovery``)."""
        visit = self._current
        assert visit.next_recovery is not None
        number = visit.next_recovery + 1
        recovery = visit.policy.recoveries[visit.next_recovery]
        running = self._recovery = _RunningRecovery(self._next_recovery_id, recovery, number, now)
        self._next_recovery_id += 1
        self._move(Trigger.RECOVER)
        self._emit(
            RecoveryStarted(
                t=now,
                index=visit.index,
                loop=visit.loop,
                recovery=number,
                recovery_kind=recovery.kind,
                attempt=visit.result.attempts + 1,
                amount=recovery.amount,
                description=recovery.describe(),
            )
        )
        return [RunRecovery(running.recovery_id, recovery)]

    def _on_recovery_done(self, now: float, done: RecoveryDone) -> list[Command]:
        running = self._recovery
        if (
            self._state is not ExecutorState.RECOVERING
            or running is None
            or done.recovery_id != running.recovery_id
        ):
            return []  # one we stopped (timeout, pause, skip): its end is no news
        outcome = "succeeded" if done.succeeded else "failed"
        self._record_recovery(now, outcome, done.detail)
        return self._after_recovery(now)

    def _check_recovery(self, now: float) -> list[Command]:
        running = self._recovery
        if running is None or now - running.started_at < running.recovery.timeout_s:
            return []
        self._record_recovery(now, "timed_out", f"no end after {running.recovery.timeout_s:g} s")
        return [CancelRecovery(running.recovery_id), *self._after_recovery(now)]

    def _after_recovery(self, now: float) -> list[Command]:
        """The next recovery of the list, or the retry once they have all run."""
        visit = self._current
        following = (visit.next_recovery or 0) + 1
        if following < len(visit.policy.recoveries):
            visit.next_recovery = following
            return self._start_recovery(now)
        visit.next_recovery = None
        return self._start_attempt(now)

    def _stop_recovery(self, now: float, reason: str) -> list[Command]:
        """Stop the running recovery, if any (pause, skip, cancel), recording why."""
        running = self._recovery
        if running is None:
            return []
        self._record_recovery(now, "cancelled", reason)
        return [CancelRecovery(running.recovery_id)]

    def _record_recovery(self, now: float, outcome: str, detail: str) -> None:
        """Put the running recovery's end into the visit's result and tell the sinks."""
        visit, running = self._current, self._recovery
        assert running is not None
        self._recovery = None
        duration = max(0.0, now - running.started_at)
        attempt = visit.result.attempts + 1
        visit.result.recoveries.append(
            RecoveryResult(
                number=running.number,
                kind=running.recovery.kind,
                amount=running.recovery.amount,
                attempt=attempt,
                outcome=outcome,
                duration=duration,
                detail=detail,
            )
        )
        self._emit(
            RecoveryFinished(
                t=now,
                index=visit.index,
                loop=visit.loop,
                recovery=running.number,
                recovery_kind=running.recovery.kind,
                attempt=attempt,
                outcome=outcome,
                duration=duration,
                detail=detail,
                amount=running.recovery.amount,
            )
        )

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
        self._end_hold(now)
        visit = self._current
        commands: list[Command] = [CancelGoal()] if cancel else []
        attempts = visit.result.attempts
        policy = visit.policy
        # A refused goal comes back at once: rejections in a row wait longer each time and,
        # under on_failure: retry, end the waypoint after a bound (navseq.executor.backoff).
        visit.rejections_in_row = visit.rejections_in_row + 1 if status == REJECTED_STATUS else 0
        if policy.on_failure is FailureAction.RETRY:
            will_retry = visit.rejections_in_row <= rejection_limit(policy)
            if not will_retry:
                reason = f"{reason} {visit.rejections_in_row} times in a row"
        else:
            will_retry = attempts <= policy.retries
        self._monitor = None
        visit.result.reason = reason
        record = visit.close_attempt(now, reached=False, status=status, reason=reason, text=text)
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
            self._move(Trigger.RETRY_LATER)
            self._deadline = now + retry_wait(visit.rejections_in_row)
            self._clear_costmaps_before_send = policy.clear_costmaps_on_retry
            visit.next_recovery = 0 if policy.recoveries else None
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
            self._end_hold(now)
            self._mark_server_lost(now, event.text or f"goal {event.status or 'LOST'}")
            self._move(Trigger.SERVER_AWAY)
            self._monitor = None
            return self._check_clock(now)
        status = event.status or "FAILED"
        return self._attempt_failed(now, status, cancel=False, status=status, text=event.text)

    def _arrival_miss(self) -> str | None:
        """Why a SUCCEEDED is not believed (the robot is not there), or None.

        Every SUCCEEDED is checked against the latest pose any input gave; without
        one the SUCCEEDED is believed.
        """
        visit = self._current
        monitor = self._monitor
        pose = self._latest_pose
        if pose is None or monitor is None:
            return None
        radius = visit.policy.pass_through_m if visit.passes_through else None
        return arrival_miss(pose, monitor.goal.pose, self.goal_tolerance(visit.policy), radius)

    def _mark_server_lost(self, now: float, reason: str) -> None:
        if self._server_up:
            self._server_up = False
            self._server_lost_at = now
            self._emit(ServerStatusChanged(t=now, available=False, reason=reason))

    def _on_server_lost(self, now: float, reason: str) -> list[Command]:
        self._mark_server_lost(now, reason)
        if self._state is ExecutorState.ACTIVE:
            self._end_hold(now)
            self._move(Trigger.SERVER_AWAY)
            self._monitor = None
        return []

    def _on_server_back(self, now: float) -> list[Command]:
        if not self._server_up:
            self._server_up = True
            self._emit(ServerStatusChanged(t=now, available=True))
        if self._state is ExecutorState.WAITING_SERVER:
            return self._send_goal(now)  # same attempt: the loss was not the waypoint's fault
        return []

    # ------------------------------------------------------------------ fleet holds

    def _on_held(self, now: float, event: GoalHeld) -> list[Command]:
        """The fleet holds the robot back: the goal's clocks stand still until released."""
        monitor = self._monitor
        assert monitor is not None
        if monitor.held_since is None:
            monitor.hold(now)
            visit = self._current
            self._emit(WaypointHeld(t=now, index=visit.index, loop=visit.loop, reason=event.reason))
        return []

    def _end_hold(self, now: float) -> None:
        """End a hold of the goal out, if any (released, or the attempt ends while held):
        its deadlines move on by the time held, which the attempt's result keeps."""
        monitor = self._monitor
        held = monitor.release(now) if monitor is not None else None
        if held is None:
            return
        visit = self._current
        visit.attempt_held += held
        self._emit(WaypointReleased(t=now, index=visit.index, loop=visit.loop, held_for=held))

    # ------------------------------------------------------------------ clock

    def _check_clock(self, now: float) -> list[Command]:
        state = self._state
        if state is ExecutorState.ACTIVE:
            monitor = self._monitor
            policy = self._current.policy
            assert monitor is not None
            overdue = monitor.overdue(now, policy.goal_timeout_s, policy.stall_timeout_s)
            if overdue is not None:
                return self._attempt_failed(now, overdue, cancel=True)
        elif state is ExecutorState.DWELLING:
            if now >= self._deadline:
                return self._tasks_or_finish(now)
        elif state is ExecutorState.RUNNING_TASK:
            return self._check_task(now)
        elif state is ExecutorState.WAITING_RETRY:
            if now >= self._deadline:
                if self._current.next_recovery is not None:
                    return self._start_recovery(now)
                return self._start_attempt(now)
        elif state is ExecutorState.RECOVERING:
            return self._check_recovery(now)
        elif state is ExecutorState.WAITING_SERVER:
            timeout = self._mission.server_timeout
            if timeout is not None and now - self._server_lost_at >= timeout:
                self._finish_visit(now, WaypointOutcome.FAILED, SERVER_LOST_REASON)
                self._finish_mission(now, SERVER_LOST_REASON)
                return [CancelGoal()]  # in case it comes back remembering the goal
        return []

    # ------------------------------------------------------------------ poses

    def _on_feedback(self, now: float, event: GoalFeedback) -> list[Command]:
        monitor = self._monitor
        assert monitor is not None
        monitor.feedback_seen = True
        if event.recoveries is not None:
            self._current.attempt_recoveries = event.recoveries
        if not self._tick_pose_seen:
            self._drive(event.pose)
        self._see_pose(event.pose)
        commands = self._observe_pose(now, event.pose, event.distance_remaining)
        if not commands and self._monitor is monitor:
            remaining = event.distance_remaining
            if remaining is None:
                remaining = monitor.remaining(event.pose)
            self._emit_progress(now, event.pose, remaining, event.recoveries, event.navigation_time)
        return commands

    def _see_pose(self, pose: Pose2D | None) -> None:
        if pose is not None:
            self._latest_pose = pose
            if self._start_pose is None:
                self._start_pose = pose

    def _drive(self, pose: Pose2D | None, odom_pose: Pose2D | None = None) -> None:
        """Add the step since the previous poses to the current visit's distance driven."""
        step = self._odometer.step(pose, odom_pose)
        if self._visit is not None:
            self._visit.result.distance_driven += step

    def _observe_pose(
        self, now: float, pose: Pose2D, navigator_distance: float | None
    ) -> list[Command]:
        """Update progress from a pose; pass through the waypoint when close enough."""
        monitor = self._monitor
        visit = self._current
        assert monitor is not None
        radius = visit.policy.pass_through_m
        if (
            radius is not None
            and visit.passes_through
            and pose.distance_to(monitor.goal.pose) <= radius
        ):
            # The next goal replaces this one at once, without a cancel: the robot
            # keeps rolling instead of braking at every intermediate point.
            return self._reached(now, passed_through=True)
        monitor.observe(now, pose, navigator_distance)
        return []

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


__all__ = [
    "PLAN_TOLERANCE",
    "RETRY_BACKOFF",
    "SERVER_LOST_REASON",
    "ExecutorState",
    "MissionExecutor",
    "MissionListener",
]
