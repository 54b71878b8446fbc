"""The navseq ROS node: a drop-in for the tutorial's ``move_base_seq`` node, done right.

``rosrun navseq navseq_node`` (or a ``<node>`` in a launch file) reads the mission from
its private parameters, exactly as the tutorial's launch file sets them:

- ``~p_seq`` (flat list x1,y1,z1,x2,...) and ``~yea_seq`` (yaw degrees), or
- ``~mission``: the path of a mission file in any format navseq reads, or
- ``~waypoints``: a structured list as in navseq's YAML format,

plus optional mission settings and policies (``~loops``, ``~goal_timeout``,
``~retries``, ``~on_failure``, ``~pass_through`` ...; see docs/mission-format.md).
The node's own parameters: ``~action`` (default ``move_base``, resolved in the node's
namespace, so ``<group ns="robot1">`` drives ``/robot1/move_base``), ``~server_wait``
(s, default 30), ``~stamp`` (``now`` or ``latest``), ``~status_timeout`` (s without
action status before the server counts as lost, default 2), ``~base_frames``,
``~plan_topic``, ``~use_tf``, ``~tick`` (s between executor looks, default 0.1),
``~keep_alive`` (default false: see below), ``~end_launch`` (default false: see
below), ``~settle`` (s of wall time between a
result and the next goal, against move_base's SUCCEEDED race; default 0.05, 0 = off),
``~odom_frame`` (default ``odom``).

It logs (rospy) the lines ``navseq run`` prints in a pipe, one per waypoint event
(going to, attempt failed, dwelling, reached / skipped / failed, paused, resumed, server
lost) and the distance to go every 10 s of mission time; trouble is a warning.

It publishes, latched, ``~waypoints`` (visualization_msgs/MarkerArray: arrows and
numbers coloured by status) and ``~status`` (std_msgs/String holding one JSON object),
and offers std_srvs/Trigger services ``~pause``, ``~resume``, ``~cancel``, ``~skip`` and
``~confirm`` (confirms the ``input`` task waiting for an operator)
(the active waypoint ends SKIPPED and the mission goes on with the next one).
Ctrl-C, SIGTERM, ``rosnode kill`` and roslaunch's shutdown all cancel the active goal
before the node exits, which logs ``interrupted (<signal or shutdown reason>)`` and
publishes the state ``interrupted``. Exit status: 0 all waypoints reached, 1 not (also
after ``rosnode kill``), 2 bad parameters or no action server, 130/143 interrupted by
SIGINT/SIGTERM.

With ``~keep_alive`` true the node does not exit when the mission ends (all waypoints
done, or cancelled through ``~cancel``): it stays up until it is shut down, so RViz
keeps showing the latched markers in their final colours and the final ``~status``.
Meanwhile the services answer that the mission is over. Being stopped is then the
expected end, not an interruption: whether by SIGINT/SIGTERM (roslaunch's shutdown),
``rosnode kill`` or the master, the exit status is the mission's own 0 or 1. Bad
parameters and a missing action server still exit at once with 2.

The run (its log lines, ending, exit status and keep-alive) and the services' answers
are shared with the ROS 2 node: :mod:`navseq.roscore.node` and
:mod:`navseq.roscore.operator`; this module only speaks rospy.

With ``~end_launch`` true (demo.launch sets it), a node started by roslaunch ends the
whole launch when the mission is over: it sends SIGINT to that roslaunch, as Ctrl-C
would, and stays up until the shutdown reaches it (exit status: the mission's 0 or 1).
Ending the launch through ``required="true"`` alone would make roslaunch print its red
"REQUIRED process has died" banner for a mission that simply finished (see
``navseq.ros1.launch_end``). Bad parameters and a missing action server still exit at
once with 2, and a ``required`` node's exit then does end the launch, banner and all.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import rospy
from std_srvs.srv import Trigger, TriggerResponse

from navseq.errors import NavseqError, error_text
from navseq.executor.control import MissionControl
from navseq.executor.events import MissionFinished
from navseq.mission.loader import mission_from_params
from navseq.mission.model import Mission
from navseq.mission.robot import RobotProfile
from navseq.ros1.launch_end import end_parent_launch
from navseq.ros1.mission_topics import MissionTopics
from navseq.ros1.navigator import Ros1Navigator, ensure_node
from navseq.ros1.navstack_params import read_navstack_profile
from navseq.ros1.params import bool_param
from navseq.roscore.navigator import CANCEL_WAIT
from navseq.roscore.node import EXIT_BAD_SETUP, run_node_mission, stay_up
from navseq.roscore.operator import CONFIRM_SERVICE, OPERATOR_SERVICES, OperatorDesk
from navseq.signals import ignore_until_exit
from navseq.sinks.progress import LogLine, LogProgress
from navseq.tasks.options import TaskOptions
from navseq.tasks.runner import TaskRunner

NODE_NAME = "navseq"
# Private parameters that configure the node itself rather than the mission.
NODE_PARAMS: dict[str, Any] = {
    "action": "move_base",
    "server_wait": 30.0,
    "stamp": "now",
    "status_timeout": 2.0,
    "base_frames": ["base_footprint", "base_link"],
    "plan_topic": "NavfnROS/plan",
    "use_tf": True,
    "tick": 0.1,
    "keep_alive": False,
    "end_launch": False,
    "settle": 0.05,
    "odom_frame": "odom",
    "snapshot_dir": "",  # where snapshot tasks write (its snapshots/); "": refused
}
# s to wait for rospy to name its shutdown reason: it does so only after the navigator's
# shutdown hook has waited (up to CANCEL_WAIT) for the server to take the cancel in.
SHUTDOWN_REASON_WAIT = CANCEL_WAIT + 1.0


def log_line(line: LogLine) -> None:
    """One of ``navseq run``'s plain progress lines, through rospy's log.

    The lines are :class:`~navseq.sinks.progress.LogProgress`'s (one per waypoint event,
    the distance to go every 10 s of mission time); a line about trouble is a warning.
    The mission's end is left to :func:`run_node`'s own line, which also says what the
    node does next.
    """
    if isinstance(line.event, MissionFinished):
        return
    (rospy.logwarn if line.attention else rospy.loginfo)("navseq: %s", line.text)


class ShutdownWatch:
    """Tells the mission's thread that ROS is shutting the node down, and why.

    On ``rosnode kill`` or a master shutdown, rospy runs its shutdown in the thread that
    got the request: first the client hooks (the navigator's, which cancels the active
    goal), then the pre-shutdown hooks, the only ones told the reason. The mission must
    stop before that cancel comes back as a PREEMPTED (failed) waypoint, so a call looks
    at rospy's "shutdown requested" flag, raised before any hook runs, and only then
    waits (bounded) for the reason. (rospy has closed its connections by then: the
    final status message no longer reaches anyone; the log line does.)
    """

    def __init__(self, reason_wait: float = SHUTDOWN_REASON_WAIT):
        self._reason = "ROS shutdown"
        self._reason_known = threading.Event()
        self._reason_wait = reason_wait
        rospy.core.add_preshutdown_hook(self._on_preshutdown)

    def _on_preshutdown(self, reason: str) -> None:
        if reason:
            self._reason = reason
        self._reason_known.set()

    def __call__(self) -> str | None:
        """None while the node runs on; the shutdown reason once ROS is stopping it."""
        if not rospy.core.is_shutdown_requested():
            return None
        self._reason_known.wait(self._reason_wait)
        return self._reason


def read_params() -> tuple[Mission, dict[str, Any]]:
    """The mission and the node settings from the node's private parameters."""
    private: dict[str, Any] = rospy.get_param("~", {}) or {}
    settings = {key: private.get(key, default) for key, default in NODE_PARAMS.items()}
    for flag in ("keep_alive", "end_launch"):
        settings[flag] = bool_param(flag, NODE_PARAMS[flag])
    mission = mission_from_params(private, "param ~", ignore=NODE_PARAMS.keys())
    return mission, settings


class RospyFace:
    """The ROS 1 node's side of :class:`~navseq.roscore.node.NodeFace`: rospy's log
    (each line starting ``navseq:``), private names, move_base's parameters."""

    kind = "ros1"

    def __init__(self, action: str) -> None:
        self.action = action

    def info(self, text: str) -> None:
        rospy.loginfo("navseq: %s", text)

    def warn(self, text: str) -> None:
        rospy.logwarn("navseq: %s", text)

    def error(self, text: str) -> None:
        rospy.logerr("navseq: %s", text)

    def service_name(self, kind: str) -> str:
        return f"~{kind}"

    def robot_from_stack(self) -> tuple[RobotProfile, str]:
        return read_navstack_profile(self.action)

    def running(self) -> bool:
        return not rospy.core.is_shutdown_requested()


def offer_operator_services(desk: OperatorDesk) -> None:
    """``~pause``, ``~resume``, ``~skip``, ``~cancel`` and ``~confirm``; rospy serves each
    call on a thread of its own, so a handler may wait (bounded) for the mission's answer."""

    def handler(kind: str) -> Callable[[Any], TriggerResponse]:
        def handle(_request: Any) -> TriggerResponse:
            ok, message = desk.answer_blocking(kind)
            return TriggerResponse(success=ok, message=message)

        return handle

    for kind in OPERATOR_SERVICES:
        rospy.Service(f"~{kind}", Trigger, handler(kind))

    def confirm(_request: Any) -> TriggerResponse:
        ok, message = desk.confirm()
        return TriggerResponse(success=ok, message=message)

    rospy.Service(f"~{CONFIRM_SERVICE}", Trigger, confirm)


def run_node() -> int:
    """Run the mission given by the node's parameters; the exit status (see module doc)."""
    try:
        mission, settings = read_params()
    except NavseqError as error:
        rospy.logerr("navseq: %s", error_text(error))
        return EXIT_BAD_SETUP
    try:
        navigator = Ros1Navigator(
            action=str(settings["action"]),
            base_frames=tuple(settings["base_frames"]),
            stamp=settings["stamp"],
            status_timeout=float(settings["status_timeout"]),
            plan_topic=settings["plan_topic"] or None,
            use_tf=bool(settings["use_tf"]),
            settle=float(settings["settle"]),
            odom_frame=str(settings["odom_frame"]),
        )
    except (NavseqError, TypeError, ValueError) as error:
        rospy.logerr("navseq: bad node parameter (param ~): %s", error_text(error))
        return EXIT_BAD_SETUP
    face = RospyFace(navigator.resolved_action)
    topics = MissionTopics(mission)
    control = MissionControl(stop_reason=ShutdownWatch())
    snapshot_dir = str(settings["snapshot_dir"] or "")
    options = TaskOptions(snapshot_folder=Path(snapshot_dir).expanduser() if snapshot_dir else None)
    tasks = TaskRunner(
        options, say=face.info, confirm_hint=f"call {rospy.resolve_name('~confirm')}"
    )
    offer_operator_services(OperatorDesk(control, topics.state, face.service_name, tasks))
    run = run_node_mission(
        face,
        mission,
        navigator,
        topics,
        control,
        server_wait=float(settings["server_wait"]),
        tick=float(settings["tick"]),
        log=lambda robot: LogProgress(mission, log_line, robot=robot),
        shutdowns=(rospy.ROSInterruptException,),
        tasks=tasks,
        task_options=options,
    )
    if not run.ran_to_end:
        return run.code
    if settings["end_launch"]:
        return end_launch(face, run.code)
    if settings["keep_alive"]:
        return stay_up(face, run.code, "mission over; staying up (~keep_alive) until shut down")
    return run.code


def end_launch(face: RospyFace, mission_code: int) -> int:
    """Ask the roslaunch that started the node to shut down, then wait for it to stop us."""

    def signal_roslaunch() -> str | None:
        why_not = end_parent_launch()
        return None if why_not is None else f"~end_launch: {why_not}"

    return stay_up(
        face,
        mission_code,
        "mission over; ending the launch (~end_launch)",
        then=signal_roslaunch,
    )


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``rosrun navseq navseq_node`` (argv: ROS remappings, ``_param:=``)."""
    if argv is not None:
        sys.argv = [sys.argv[0], *argv]
    try:
        ensure_node(NODE_NAME, anonymous=False)
    except NavseqError as error:
        print(f"navseq: {error_text(error)}", file=sys.stderr)
        sys.exit(2)
    code = run_node()
    # The status is decided: a SIGINT from roslaunch while rospy shuts down must not
    # turn it into a traceback or a death by the signal.
    ignore_until_exit()
    rospy.signal_shutdown(f"navseq finished with status {code}")
    sys.exit(code)


if __name__ == "__main__":
    main()
