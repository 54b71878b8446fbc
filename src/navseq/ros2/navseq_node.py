"""The navseq ROS 2 node: the tutorial's waypoint sequencer for Nav2, done right.

``ros2 run navseq navseq_node --ros-args -p p_seq:="[...]" -p yea_seq:="[...]"`` (or
``python -m navseq.ros2.navseq_node``, or a ``Node`` in a launch file) reads the
mission from its parameters, as the ROS 1 node (:mod:`navseq.ros1.navseq_node`) does:

- ``p_seq`` (double array, x y z triples) and ``yea_seq`` (double array, yaw degrees),
  exactly like the tutorial's, or
- ``mission``: the path of a mission file in any format navseq reads, or
- ``waypoints``: a string holding navseq's YAML waypoint list;

plus the same optional mission keys (``loops``, ``goal_timeout``, ``retries``,
``on_failure``, ``pass_through`` ...; see :mod:`navseq.ros2.node_params`), and the
node's own: ``action`` (default ``navigate_to_pose``, relative to the node's
namespace), ``server_wait`` (s, default 30), ``tick``, ``keep_alive``, ``base_frames``,
``odom_topic``, ``plan_topic``; ``use_sim_time`` as every ROS 2 node (not given: on as
soon as ``/clock`` is published).

It drives Nav2 through :class:`~navseq.ros2.navigator.Nav2Navigator` on this node,
publishes ``~/waypoints`` (``visualization_msgs/msg/MarkerArray``) and ``~/status``
(``std_msgs/msg/String``, one JSON object per event), both transient local, offers
``~/pause``, ``~/resume``, ``~/skip``, ``~/cancel`` and ``~/confirm`` (``std_srvs/srv/Trigger``),
and logs one line per waypoint event. SIGINT / SIGTERM (Ctrl-C, ``ros2 launch``'s
shutdown) cancel the active goal and wait (bounded) for Nav2's answer before the node
exits. Exit status: 0 all waypoints reached, 1 not, 2 bad parameters or no action
server, 130 / 143 interrupted by SIGINT / SIGTERM. With ``keep_alive`` the node stays
up after the mission (markers and status keep their final state) until it is stopped,
and then exits with the mission's 0 or 1.

The run (its log lines, ending, exit status and keep-alive) and the services' answers
are shared with the ROS 1 node: :mod:`navseq.roscore.node` and
:mod:`navseq.roscore.operator`; this module only speaks rclpy.

Threads: the node's executor spins on a thread of its own
(:class:`~navseq.ros2.session.Ros2Session`); the mission runs on the main thread,
where the signals arrive. Service handlers are coroutines: they file the request with
:class:`~navseq.executor.control.MissionControl` and await its answer, so the single
executor thread keeps delivering ``/clock``, feedback and results meanwhile.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Sequence
from typing import Any

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.task import Future
from std_srvs.srv import Trigger

from navseq.errors import NavseqError, error_text
from navseq.executor.control import MissionControl, OperatorRequest
from navseq.executor.events import (
    AttemptFailed,
    MissionEvent,
    MissionPaused,
    WaypointFinished,
    WaypointOutcome,
    WaypointProgress,
)
from navseq.mission.robot import RobotProfile
from navseq.ros2.mission_topics import MissionTopics
from navseq.ros2.nav2_params import NODES, profile_from_nav2_params
from navseq.ros2.navigator import Nav2Navigator
from navseq.ros2.node_params import NodeSettings, read_node_params
from navseq.ros2.session import Ros2Session
from navseq.roscore.node import EXIT_BAD_SETUP, run_node_mission, stay_up
from navseq.roscore.operator import (
    CONFIRM_SERVICE,
    OPERATOR_SERVICES,
    SERVICE_ANSWER_WAIT,
    OperatorDesk,
)
from navseq.signals import ignore_until_exit
from navseq.sinks.progress import RunView, describe
from navseq.tasks.options import TaskOptions
from navseq.tasks.runner import TaskRunner

NODE_NAME = "navseq"


class WaypointLog:
    """A mission listener logging one line per waypoint event, as ``navseq run`` words it.

    Failed attempts, waypoints not reached and pauses are warnings. The waypoint an
    interruption ends is left to the interruption's own log line.
    """

    def __init__(self, mission: Any, logger: Any) -> None:
        self.view = RunView(mission)
        self.logger = logger

    def __call__(self, event: MissionEvent) -> None:
        self.view.update(event)
        if isinstance(event, WaypointProgress):
            return
        if isinstance(event, WaypointFinished) and event.reason.startswith("interrupted"):
            return
        text = describe(event, self.view)
        if text is None:
            return
        warn = isinstance(event, MissionPaused | AttemptFailed) or (
            isinstance(event, WaypointFinished) and event.outcome is not WaypointOutcome.REACHED
        )
        if warn:
            self.logger.warning(f"{text}")
        else:
            self.logger.info(f"{text}")


class RclpyFace:
    """The ROS 2 node's side of :class:`~navseq.roscore.node.NodeFace`: the node's
    logger, ``~/`` names, Nav2's node parameters."""

    kind = "nav2"

    def __init__(self, session: Ros2Session, navigator: Nav2Navigator) -> None:
        self.session = session
        self.navigator = navigator
        self.logger = session.node.get_logger()

    def info(self, text: str) -> None:
        self.logger.info(text)

    def warn(self, text: str) -> None:
        self.logger.warning(text)

    def error(self, text: str) -> None:
        self.logger.error(text)

    def service_name(self, kind: str) -> str:
        return f"~/{kind}"

    def robot_from_stack(self) -> tuple[RobotProfile, str]:
        params = self.navigator.read_parameters(NODES)
        return profile_from_nav2_params(params, self.navigator.namespace)

    def running(self) -> bool:
        return self.session.ok()


class OperatorServices:
    """``~/pause``, ``~/resume``, ``~/skip``, ``~/cancel`` and ``~/confirm``, answered by
    :class:`~navseq.roscore.operator.OperatorDesk` without holding the executor."""

    def __init__(self, session: Ros2Session, desk: OperatorDesk) -> None:
        self.session = session
        self.desk = desk
        # A group of their own: while a handler awaits the mission's answer its group is
        # busy, and in the node's default group that would hold back /clock, Nav2's
        # feedback and results - which the mission needs to answer.
        group = MutuallyExclusiveCallbackGroup()
        for name in OPERATOR_SERVICES:
            session.node.create_service(
                Trigger, f"~/{name}", self._handler(name), callback_group=group
            )
        # Answered at once: the default group will do.
        session.node.create_service(Trigger, f"~/{CONFIRM_SERVICE}", self._confirm)

    def _confirm(self, _request: Any, response: Any) -> Any:
        response.success, response.message = self.desk.confirm()
        return response

    def _handler(self, name: str) -> Any:
        async def handle(_request: Any, response: Any) -> Any:
            ok, message = await self._answer(name)
            response.success, response.message = ok, message
            return response

        return handle

    async def _answer(self, name: str) -> tuple[bool, str]:
        at_once = self.desk.answer_at_once(name)
        if at_once is not None:
            return at_once
        answered: Future = Future(executor=self.session.executor)

        def wake(request: OperatorRequest) -> None:
            if not answered.done():
                answered.set_result(request)
                # The awaiting handler runs again when the executor looks next: now.
                self.session.executor.wake()

        request = self.desk.submit(name, wake)
        # The run answers within one tick; the timer only guards against a stuck run.
        timer = threading.Timer(SERVICE_ANSWER_WAIT, lambda: wake(request))
        timer.daemon = True
        timer.start()
        await answered
        timer.cancel()
        return self.desk.answer_of(request)


def make_navigator(session: Ros2Session, settings: NodeSettings) -> Nav2Navigator:
    return Nav2Navigator(
        settings.action,
        namespace=session.node.get_namespace(),
        use_sim_time=settings.use_sim_time,
        base_frames=settings.base_frames,
        odom_topic=settings.odom_topic,
        plan_topic=settings.plan_topic,
        session=session,
    )


def run_node(session: Ros2Session) -> int:
    """Run the mission the node's parameters give; the exit status (see module doc)."""
    node = session.node
    logger = node.get_logger()
    given = {name: parameter.value for name, parameter in session.given_parameters().items()}
    try:
        mission, settings = read_node_params(given, node.get_fully_qualified_name())
        navigator = make_navigator(session, settings)
    except NavseqError as error:
        logger.error(error_text(error))
        return EXIT_BAD_SETUP
    face = RclpyFace(session, navigator)
    topics = MissionTopics(node, mission)
    control = MissionControl(stop_reason=lambda: None if session.ok() else "ROS 2 shut down")
    confirm = node.resolve_service_name(f"~/{CONFIRM_SERVICE}", only_expand=True)
    options = TaskOptions(snapshot_folder=settings.snapshot_dir)
    tasks = TaskRunner(options, say=face.info, confirm_hint=f"call {confirm}")
    OperatorServices(session, OperatorDesk(control, topics.state, face.service_name, tasks))
    run = run_node_mission(
        face,
        mission,
        navigator,
        topics,
        control,
        server_wait=settings.server_wait,
        tick=settings.tick,
        log=lambda _robot: WaypointLog(mission, logger),
        tasks=tasks,
        task_options=options,
    )
    if run.ran_to_end and settings.keep_alive:
        return stay_up(face, run.code, "mission over; staying up (keep_alive) until shut down")
    return run.code


def main(argv: Sequence[str] | None = None) -> int:
    """``ros2 run navseq navseq_node [--ros-args ...]``; returns the exit status."""
    args = list(sys.argv if argv is None else ["navseq_node", *argv])
    try:
        session = Ros2Session(NODE_NAME, args=args, any_parameter=True)
    except Exception as error:  # rclpy's own: bad --ros-args, a params file it cannot read
        print(f"navseq: cannot start the ROS 2 node: {error_text(error)}", file=sys.stderr)
        return 2
    try:
        return run_node(session)
    finally:
        if argv is None:  # the process's own node: a signal now must not change its status
            ignore_until_exit()
        # Let the last status reach transient-local subscribers already matched.
        time.sleep(0.05)
        session.close()


if __name__ == "__main__":
    sys.exit(main())
