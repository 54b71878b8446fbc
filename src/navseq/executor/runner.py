"""Run a mission to the end against a navigator: the loop around the state machine.

:func:`run_mission` is what the CLI and the ROS node call. It owns the one promise
the state machine cannot keep on its own: whatever ends the run early (Ctrl-C,
SIGTERM, an exception in a sink or a navigator), the active goal is cancelled on the
navigator before the error leaves this function, so the robot never keeps driving
to a goal nobody watches.

For that it installs its own SIGINT and SIGTERM handlers while the mission runs (in
the main thread), restoring the previous ones afterwards. SIGINT too: a process
started in the background of a shell script inherits SIGINT as ignored, and Python
then installs no KeyboardInterrupt handler, so ``kill -INT`` would leave the robot
driving.
"""

from __future__ import annotations

import contextlib
import logging
from collections import deque
from collections.abc import Generator, Iterable, Iterator
from typing import TYPE_CHECKING

from navseq.errors import NavseqError
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
from navseq.executor.control import MissionControl, OperatorRequest, StopRequested
from navseq.executor.events import MissionEvent
from navseq.executor.machine import MissionExecutor, MissionListener
from navseq.executor.result import MissionResult
from navseq.executor.resume import ResumePoint
from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.mission.robot import RobotProfile
from navseq.navigators.base import NavEvent, Navigator, RecoveryDone, RecoveryRunner
from navseq.signals import SignalGuard, Terminated

if TYPE_CHECKING:
    from navseq.tasks.runner import TaskRunner

_log = logging.getLogger(__name__)

#: Exit status of a process ended by each signal, as shells report it (128 + number).
SIGNAL_EXIT_CODES = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}


class MissionInterrupted(Exception):
    """The run was ended by a signal; the goal was cancelled and ``result`` is final.

    ``exit_code`` is the conventional status for the signal (130 for SIGINT, 143 for
    SIGTERM), for a CLI to ``sys.exit`` with.
    """

    def __init__(self, signal_name: str, result: MissionResult):
        self.signal_name = signal_name
        self.result = result
        self.exit_code = SIGNAL_EXIT_CODES.get(signal_name, 1)
        super().__init__(f"mission interrupted by {signal_name}")


class MissionAborted(NavseqError):
    """Bad input or a failing output stopped the run mid-way; the goal was cancelled.

    The error's own message, plus ``result``: what the run did until then, so the
    caller can still report it.
    """

    def __init__(self, error: NavseqError, result: MissionResult):
        super().__init__(error.message, source=error.source, subject=error.subject)
        self.result = result


def run_mission(
    mission: Mission,
    navigator: Navigator,
    listeners: Iterable[MissionListener] = (),
    *,
    resume: ResumePoint | None = None,
    tick: float = 0.1,
    server_wait: float = 10.0,
    control: MissionControl | None = None,
    signals: SignalGuard | None = None,
    robot: RobotProfile | None = None,
    tasks: TaskRunner | None = None,
) -> MissionResult:
    """Drive ``mission`` through ``navigator`` until it ends, and return the result.

    ``listeners`` receive every mission event (progress display, journal, report).
    ``resume`` continues an earlier run (see :mod:`navseq.journal.writer`). ``tick`` is
    how much navigator time passes between two looks at the mission (seconds);
    ``server_wait`` how long to wait (wall time) for the navigation server at start.
    ``control`` lets other threads file operator requests (skip, pause, resume,
    cancel) and tells the run when its process is being shut down (``stop_reason``).
    ``signals`` is the run's :class:`~navseq.signals.SignalGuard`: armed for the run
    (SIGINT, SIGTERM and SIGHUP end it, also where SIGINT was ignored), deferring from
    the moment the run is stopped or ends, so that the caller can finish its outputs
    before it restores the handlers. Without one, a guard of the run's own is restored
    on return. ``robot`` gives the goal tolerance of the arrival check (see
    :class:`~navseq.executor.machine.MissionExecutor`; default: the mission's
    ``robot:``, else the TurtleBot3 burger). ``tasks`` runs the waypoints' tasks
    (default: a :class:`~navseq.tasks.runner.TaskRunner` that refuses ``run`` tasks and
    ROS ones); whatever ends the run stops the task still running.

    Raises :class:`~navseq.errors.NavseqError` when the server is not there,
    :class:`MissionInterrupted` on SIGINT/SIGTERM/SIGHUP,
    :class:`~navseq.executor.control.StopRequested` when ``control``'s ``stop_reason``
    gives a reason (the result then says ``interrupted (<reason>)``), :class:`MissionAborted` when
    a NavseqError (a sink that cannot write) stops the run, and re-raises any other
    exception;
    in the last two cases only after cancelling the active goal and telling the
    listeners that the mission finished (``MissionFinished``, reason
    ``"interrupted: SIGINT"`` and so on).
    """
    executor = MissionExecutor(mission, resume=resume, robot=robot)
    for listener in listeners:
        executor.add_listener(listener)
    tasks = tasks if tasks is not None else _default_tasks()
    guard = signals if signals is not None else SignalGuard()
    guard.arm()
    try:
        server_up = navigator.wait_for_server(server_wait)
        if server_up:
            _drive(executor, _Outside(navigator, tasks, guard), tick, control)
    except KeyboardInterrupt:
        guard.defer()  # also for a KeyboardInterrupt not raised by the guard
        result = _abort(executor, navigator, "interrupted: SIGINT", tasks)
        raise MissionInterrupted("SIGINT", result) from None
    except Terminated as signalled:
        name = signalled.signal_name
        result = _abort(executor, navigator, f"interrupted: {name}", tasks)
        raise MissionInterrupted(name, result) from None
    except StopRequested as stop:
        guard.defer()
        _abort(executor, navigator, f"interrupted ({stop})", tasks)
        raise
    except NavseqError as error:
        # A sink could not do its job (the journal on a full disk): stop, then say why.
        guard.defer()
        result = _abort(executor, navigator, f"stopped: {error}", tasks)
        raise MissionAborted(error, result) from None
    except BaseException as error:
        guard.defer()
        _abort(executor, navigator, f"interrupted: {type(error).__name__}: {error}", tasks)
        raise
    finally:
        tasks.close()
        if control is not None:
            control.close("the mission has ended")
        if signals is None:
            guard.restore()
        else:
            guard.defer()  # the caller's outputs come next
    if not server_up:
        raise _no_server(server_wait)
    return executor.result


def iter_mission(
    mission: Mission,
    navigator: Navigator,
    *,
    tick: float = 0.1,
    server_wait: float = 10.0,
    control: MissionControl | None = None,
    robot: RobotProfile | None = None,
    tasks: TaskRunner | None = None,
) -> Generator[MissionEvent, None, MissionResult]:
    """:func:`run_mission` as a generator of mission events, for a caller's own loop.

    Yields every event as it happens and returns the result (``StopIteration.value``).
    It installs no signal handlers (a library's loop may not run in the main thread);
    whatever ends it early -- an exception, Ctrl-C, or the caller leaving the loop
    (``close()``) -- cancels the active goal first, as :func:`run_mission` does.
    Raises :class:`~navseq.errors.NavseqError` when the server is not there. ``tasks``
    as for :func:`run_mission`.
    """
    executor = MissionExecutor(mission, robot=robot)
    tasks = tasks if tasks is not None else _default_tasks()
    pending: deque[MissionEvent] = deque()
    executor.add_listener(pending.append)
    if not navigator.wait_for_server(server_wait):
        raise _no_server(server_wait)
    try:
        for _ in _steps(executor, _Outside(navigator, tasks), tick, control):
            while pending:
                yield pending.popleft()
    except GeneratorExit:
        _abort(executor, navigator, "interrupted: the caller stopped the run", tasks)
        raise
    except KeyboardInterrupt:
        _abort(executor, navigator, "interrupted: SIGINT", tasks)
        raise
    except BaseException as error:
        _abort(executor, navigator, f"interrupted: {type(error).__name__}: {error}", tasks)
        raise
    finally:
        tasks.close()
    while pending:
        yield pending.popleft()
    return executor.result


def _no_server(server_wait: float) -> NavseqError:
    return NavseqError(
        f"no navigation server answered within {server_wait:g} s; is the navigation "
        "stack (move_base or the simulator) running, and is the action name right?",
        source="navigator",
    )


def _default_tasks() -> TaskRunner:
    from navseq.tasks.runner import TaskRunner

    return TaskRunner()


class _Outside:
    """What the executor's commands act on: the navigator and the task runner.

    Sending and cancelling a goal run with the run's shutdown signals held (``guard``):
    a Ctrl-C halfway through a send would leave a goal on its way that the navigator
    has no handle of yet, which the cancel that follows could not reach.
    """

    def __init__(
        self, navigator: Navigator, tasks: TaskRunner, guard: SignalGuard | None = None
    ) -> None:
        self.navigator = navigator
        self.tasks = tasks
        self.guard = guard
        self.local_events: list[NavEvent] = []  # events the runner itself reports

    def apply(self, commands: list[Command]) -> None:
        navigator = self.navigator
        held = self.guard.held if self.guard is not None else contextlib.nullcontext
        for command in commands:
            if isinstance(command, SendGoal):
                with held():
                    navigator.send_goal(command.goal)
            elif isinstance(command, CancelGoal):
                with held():
                    navigator.cancel_goal()
            elif isinstance(command, ClearCostmaps):
                navigator.clear_costmaps()
            elif isinstance(command, StartTask):
                self.tasks.start(command, navigator.now())
            elif isinstance(command, CancelTask):
                self.tasks.cancel(command.task_id)
            elif isinstance(command, RunRecovery):
                with held():
                    self._run_recovery(command)
            elif isinstance(command, CancelRecovery):
                with held():
                    _cancel_recovery(navigator)

    def _run_recovery(self, command: RunRecovery) -> None:
        """Hand the recovery to the navigator; one that runs none (a navigator of the
        Python API: pre-flight refuses recoveries for the registered kinds that cannot
        run them) has it fail, and the retry goes ahead."""
        if isinstance(self.navigator, RecoveryRunner):
            self.navigator.run_recovery(command.recovery_id, command.recovery)
        else:
            why = f"this navigator runs no recoveries ({command.recovery.describe()})"
            self.local_events.append(RecoveryDone(command.recovery_id, False, why))


def _cancel_recovery(navigator: Navigator) -> None:
    if isinstance(navigator, RecoveryRunner):
        navigator.cancel_recovery()


def _drive(
    executor: MissionExecutor, outside: _Outside, tick: float, control: MissionControl | None
) -> None:
    """The loop: navigator events, operator requests and the clock in; commands out."""
    for _ in _steps(executor, outside, tick, control):
        pass


def _steps(
    executor: MissionExecutor, outside: _Outside, tick: float, control: MissionControl | None
) -> Iterator[None]:
    """The loop, one step (one look at the mission, then ``tick`` of navigator time) per
    item, so that :func:`iter_mission` can hand over the events between steps."""
    navigator, _apply = outside.navigator, outside.apply
    _apply(executor.start(navigator.now(), navigator.robot_pose()))
    while not executor.finished:
        events = navigator.poll()
        if outside.local_events:
            events, outside.local_events = [*outside.local_events, *events], []
        if control is not None and control.stop_reason is not None:
            # Asked after taking the events: a shutdown is announced before the goal is
            # cancelled under us, so that cancel's result is never a failed waypoint.
            stop = control.stop_reason()
            if stop is not None:
                raise StopRequested(stop)
        for event in events:
            _apply(executor.on_event(event, navigator.now(), navigator.robot_pose()))
        for done in outside.tasks.poll(navigator.now()):
            _apply(executor.on_task_done(done, navigator.now()))
        if control is not None:
            for request in control.take_requests():
                _apply(_operate(executor, request, navigator.now()))
        pose, odom_pose = navigator.robot_pose(), _odometry_pose(navigator)
        _apply(executor.on_tick(navigator.now(), pose, odom_pose))
        yield
        if not executor.finished:
            navigator.spin(tick)
            outside.tasks.pace(navigator.now())


def _operate(executor: MissionExecutor, request: OperatorRequest, now: float) -> list[Command]:
    """Carry out one operator request as an executor input, and answer it."""
    if executor.finished:
        request.answer(False, f"nothing to {request.kind}: the mission has ended")
        return []
    if request.kind == "skip":
        commands = executor.skip(now, request.reason or "skipped by operator")
        request.answer(True, "skipped; going on with the next waypoint")
    elif request.kind == "pause":
        if executor.paused:
            request.answer(False, "already paused")
            return []
        commands = executor.pause(now, request.reason or "paused by operator")
        request.answer(True, "paused; the active goal was cancelled")
    elif request.kind == "resume":
        if not executor.paused:
            request.answer(False, "not paused")
            return []
        commands = executor.resume(now)
        request.answer(True, "resumed")
    else:  # cancel
        commands = executor.cancel(now, request.reason or "cancelled by operator")
        request.answer(True, "mission cancelled; the active goal was cancelled")
    return commands


def _odometry_pose(navigator: Navigator) -> Pose2D | None:
    """The navigator's odometry pose; None from navigators written before it existed."""
    odometry_pose = getattr(navigator, "odometry_pose", None)
    return odometry_pose() if odometry_pose is not None else None


def _abort(
    executor: MissionExecutor, navigator: Navigator, reason: str, tasks: TaskRunner
) -> MissionResult:
    """Stop the robot and the running task first, then close the books; never raise.

    Called with the run's signal guard deferring: a second Ctrl-C cannot cut it short.
    """
    try:
        navigator.cancel_goal()
        _cancel_recovery(navigator)  # a spin or backup under way stops too
    except Exception:
        _log.exception("cancelling the active goal failed")
    try:
        tasks.close()
    except Exception:
        _log.exception("stopping the running task failed")
    try:
        now = navigator.now()
    except Exception:
        now = executor.now
    try:
        executor.interrupt(now, reason)  # its CancelGoal was done above
    except Exception:
        _log.exception("a mission listener failed while the mission was interrupted")
    return executor.result
