"""The navseq node's run, the same on ROS 1 and ROS 2: start, run, ending, exit status.

Both nodes read their parameters their own way, then hand the mission, a navigator
and a :class:`NodeFace` (logging, the robot profile from the stack, the names of
their parameters and services) to :func:`run_node_mission`, which:

1. logs ``N waypoints from SOURCE; waiting for ACTION`` and waits for the server
   (a missing one is a :class:`NavseqError`: exit status 2);
2. takes the robot profile from the mission's ``robot:``, else from the running
   stack's parameters (arrival is judged with the stack's own goal tolerance), and
   logs where it came from;
3. runs the mission through the run service (:mod:`navseq.run`: the node's own
   navigator, its topics and log as the sinks, no files, SIGINT / SIGTERM cancel the
   goal; the waypoints' tasks on the node's :class:`~navseq.tasks.runner.TaskRunner`,
   whose ``input`` tasks the ``~/confirm`` service answers);
4. ends it: cancelled by the operator (a warning naming the service), succeeded
   (info) or failed (a warning); the status topic and the services then say the
   mission is over;
5. always closes the navigator: the active goal is cancelled and the server's answer
   waited for, bounded (:mod:`navseq.roscore.navigator`).

Exit status: 0 every waypoint reached, 1 not (also when ROS shut the node down), 2
bad parameters, no action server or no valid clock, 130 / 143 interrupted by SIGINT /
SIGTERM (the active goal cancelled first). After a mission that ran to its end the
node may stay up (:func:`stay_up`: keep-alive, so RViz keeps the final markers and
status); being stopped then is the expected end, and the status stays the mission's.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from navseq.errors import NavseqError, error_text
from navseq.executor.control import MissionControl, StopRequested, cancelled_by_operator
from navseq.executor.machine import MissionListener
from navseq.executor.runner import SIGNAL_EXIT_CODES
from navseq.mission.model import Mission
from navseq.mission.robot import RobotProfile
from navseq.navigators.base import Navigator
from navseq.run import RunRequest, UseNavigator, prepare
from navseq.signals import SignalGuard, StopSignals
from navseq.sinks.mission_status import StatusPublisher
from navseq.tasks.options import TaskOptions
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.tasks.runner import TaskRunner

EXIT_BAD_SETUP = 2  # bad parameters, no action server, no valid clock
EXIT_SHUT_DOWN = 1  # ROS shut the node down (rosnode kill, the master, rclpy's context)
KEEP_ALIVE_POLL = 0.1  # s of wall time between two looks for a shutdown while kept alive


class NodeNavigator(Navigator, Protocol):
    """A ROS navigator as the node needs it: it names its server and insists on it."""

    resolved_action: str

    def require_server(self, timeout: float) -> None: ...


class NodeFace(Protocol):
    """What one ROS version's node does its own way."""

    #: The navigator kind the report and status name (``ros1``, ``nav2``).
    kind: str

    def info(self, text: str) -> None: ...

    def warn(self, text: str) -> None: ...

    def error(self, text: str) -> None: ...

    def service_name(self, kind: str) -> str:
        """An operator service's name as offered (``~cancel``, ``~/cancel``)."""
        ...

    def robot_from_stack(self) -> tuple[RobotProfile, str]:
        """The robot as the running navigation stack knows it, and a note saying so."""
        ...

    def running(self) -> bool:
        """False once the client library is shutting the node down."""
        ...


@dataclass(frozen=True)
class NodeRun:
    """How a node's mission ended: the exit status, and whether it ran to its end (only
    then may the node stay up: keep-alive, ending its launch)."""

    code: int
    ran_to_end: bool


def run_node_mission(
    face: NodeFace,
    mission: Mission,
    navigator: NodeNavigator,
    topics: StatusPublisher,
    control: MissionControl,
    *,
    server_wait: float,
    tick: float,
    log: Callable[[RobotProfile], MissionListener],
    shutdowns: Sequence[type[BaseException]] = (),
    tasks: TaskRunner | None = None,
    task_options: TaskOptions | None = None,
) -> NodeRun:
    """Run the node's mission (module doc). ``log(robot)`` makes the listener that logs
    the run (the robot known by then gives it the time still to go); ``shutdowns``
    are the client library's own "shutting down" exceptions, which end the run with
    :data:`EXIT_SHUT_DOWN`. ``tasks`` runs the waypoints' tasks (the one the node's
    ``~/confirm`` service answers); None: one made for the run. ``task_options``: what
    the tasks may do (where snapshots go)."""
    state = topics.state
    try:
        face.info(
            f"{len(mission)} waypoints from {printable(mission.source)}; "
            f"waiting for {navigator.resolved_action}"
        )
        navigator.require_server(server_wait)
        robot = mission.robot
        if robot is None:
            # Arrival is judged with the tolerance the stack's own goal checker uses.
            robot, note = face.robot_from_stack()
            face.info(note)
        session = prepare(
            RunRequest(
                mission,
                navigator=UseNavigator(
                    navigator, {"kind": face.kind, "action": navigator.resolved_action}
                ),
                robot=robot,
                preflight=False,  # the node has no map file; the stack checks its goals
                outputs=None,  # a node's record is its topics and its log
                server_wait=server_wait,
                tick=tick,
                tasks=task_options or TaskOptions(),
            )
        )
        session.task_runner = tasks
        guard = SignalGuard()  # the node's main thread: a shutdown signal cancels the goal
        try:
            outcome = session.run([topics, log(robot)], control=control, signals=guard)
        finally:
            guard.restore()
        if outcome.error is not None:  # a sink that could not do its job stopped the run
            raise outcome.error
        if outcome.interrupted is not None:
            _log_interrupted(face, outcome.interrupted)
            return NodeRun(outcome.exit_status, ran_to_end=False)
        result = outcome.result
    except NavseqError as error:
        face.error(error_text(error))
        topics.publish_status({"state": "error", "reason": str(error)})
        state.over = "the mission could not run"
        return NodeRun(EXIT_BAD_SETUP, ran_to_end=False)
    except KeyboardInterrupt:
        # Ctrl-C while still waiting for the action server: no goal is out yet.
        face.warn("interrupted (SIGINT) while waiting for the action server")
        return NodeRun(SIGNAL_EXIT_CODES["SIGINT"], ran_to_end=False)
    except StopRequested as shutdown:
        # rosnode kill, a master or rclpy shutdown: the navigator cancelled the goal.
        _log_interrupted(face, str(shutdown))
        return NodeRun(EXIT_SHUT_DOWN, ran_to_end=False)
    except BaseException as error:
        if not isinstance(error, tuple(shutdowns)):
            raise
        # A shutdown the client library saw first (rospy.sleep on simulated time).
        _log_interrupted(face, "ROS shutdown")
        return NodeRun(EXIT_SHUT_DOWN, ran_to_end=False)
    finally:
        navigator.close()
    if cancelled_by_operator(result.reason):
        face.warn(f"mission cancelled by the operator ({face.service_name('cancel')})")
        state.over = "the mission was cancelled"
    elif result.success:
        face.info(f"mission succeeded ({result.reason})")
        state.over = "the mission has ended (succeeded)"
    else:
        face.warn(f"mission ended without reaching every waypoint ({result.reason})")
        state.over = "the mission has ended (failed)"
    return NodeRun(outcome.exit_status, ran_to_end=True)


def stay_up(
    face: NodeFace,
    mission_code: int,
    why: str,
    then: Callable[[], str | None] | None = None,
) -> int:
    """Keep the node (its latched topics and services) up until it is shut down.

    Returns ``mission_code`` however the node is stopped: the mission is over, so a
    signal interrupts nothing, and a launch (which stops nodes with SIGINT) should not
    see a finished mission as a failure. ``then`` runs once the signal handlers are in
    place (ending a launch sends a SIGINT that comes straight back); a reason it
    returns means there is nothing to wait for: the node just exits.
    """
    with StopSignals() as stop:
        face.info(why)
        if then is not None and (why_not := then()) is not None:
            face.warn(f"{why_not}; the node just exits")
            return mission_code
        while face.running() and not stop.wait(KEEP_ALIVE_POLL):
            pass
    if stop.received:
        face.info(f"{stop.received[0]}; shutting down")
    return mission_code


def _log_interrupted(face: NodeFace, cause: str) -> None:
    face.warn(f"interrupted ({cause}); the active goal was cancelled")
