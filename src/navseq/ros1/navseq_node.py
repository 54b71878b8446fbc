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
and offers std_srvs/Trigger services ``~pause``, ``~resume``, ``~cancel`` and ``~skip``
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
from typing import Any

import rospy
from std_srvs.srv import Trigger, TriggerResponse

from navseq.errors import NavseqError, error_text
from navseq.executor.control import (
    MissionControl,
    StopRequested,
    cancelled_by_operator,
    operator_reason,
)
from navseq.executor.events import MissionFinished
from navseq.executor.runner import SIGNAL_EXIT_CODES, MissionInterrupted, run_mission
from navseq.mission.loader import mission_from_params
from navseq.mission.model import Mission
from navseq.ros1.launch_end import end_parent_launch
from navseq.ros1.mission_topics import MissionTopics
from navseq.ros1.navigator import CANCEL_FLUSH, Ros1Navigator, ensure_node
from navseq.ros1.navstack_params import read_navstack_profile
from navseq.ros1.params import bool_param
from navseq.signals import StopSignals, ignore_until_exit
from navseq.sinks.progress import LogLine, LogProgress
from navseq.text import printable

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
}
# s to wait for rospy to name its shutdown reason: it does so only after the navigator's
# shutdown hook has waited (up to CANCEL_FLUSH) for the goal's cancel to go out.
SHUTDOWN_REASON_WAIT = CANCEL_FLUSH + 1.0
KEEP_ALIVE_POLL = 0.1  # s of wall time between two looks for a shutdown while kept alive


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


def _trigger_service(name: str, control: MissionControl, topics: MissionTopics) -> None:
    """``~pause``, ``~resume``, ``~cancel``: executor inputs, answered by the run's thread."""

    def handle(_request: Any) -> TriggerResponse:
        if topics.over is not None:
            # Nobody takes requests any more: a request would only be refused.
            return TriggerResponse(success=False, message=f"nothing to {name}: {topics.over}")
        ok, message = control.request(name, operator_reason(name, f"~{name}"))
        return TriggerResponse(success=ok, message=message)

    rospy.Service(f"~{name}", Trigger, handle)


def _skip_service(topics: MissionTopics, control: MissionControl) -> None:
    def handle(_request: Any) -> TriggerResponse:
        index = topics.active_waypoint
        if topics.over is not None:
            return TriggerResponse(success=False, message=f"nothing to skip: {topics.over}")
        if index is None:
            # Filed now, the request would skip whichever waypoint comes next.
            return TriggerResponse(success=False, message="no waypoint is underway")
        control.request_skip(operator_reason("skip", "~skip"))
        return TriggerResponse(
            success=True, message=f"waypoint {index + 1} skipped; going on with the next one"
        )

    rospy.Service("~skip", Trigger, handle)


def run_node() -> int:
    """Run the mission given by the node's parameters; the exit status (see module doc)."""
    try:
        mission, settings = read_params()
    except NavseqError as error:
        rospy.logerr("navseq: %s", error_text(error))
        return 2
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
        return 2
    topics = MissionTopics(mission)
    control = MissionControl(stop_reason=ShutdownWatch())
    for name in ("pause", "resume", "cancel"):
        _trigger_service(name, control, topics)
    _skip_service(topics, control)
    try:
        rospy.loginfo(
            "navseq: %d waypoints from %s; waiting for %s",
            len(mission),
            printable(mission.source),
            navigator.resolved_action,
        )
        navigator.require_server(float(settings["server_wait"]))
        robot = mission.robot
        if robot is None:
            # Arrival is judged with the tolerance move_base's local planner uses.
            robot, note = read_navstack_profile(navigator.resolved_action)
            rospy.loginfo("navseq: %s", note)
        result = run_mission(
            mission,
            navigator,
            # The robot also gives the log's time still to go.
            [topics, LogProgress(mission, log_line, robot=robot)],
            tick=float(settings["tick"]),
            control=control,
            robot=robot,
        )
    except NavseqError as error:
        rospy.logerr("navseq: %s", error_text(error))
        topics.publish_status({"state": "error", "reason": str(error)})
        return 2
    except MissionInterrupted as interrupted:
        _log_interrupted(interrupted.signal_name)
        return interrupted.exit_code
    except KeyboardInterrupt:
        # Ctrl-C while still waiting for the action server: no goal is out yet.
        rospy.logwarn("navseq: interrupted (SIGINT) while waiting for the action server")
        return SIGNAL_EXIT_CODES["SIGINT"]
    except StopRequested as shutdown:
        # rosnode kill / master shutdown: the navigator's shutdown hook cancelled the goal.
        _log_interrupted(str(shutdown))
        return 1
    except rospy.ROSInterruptException:
        # A shutdown seen first by rospy.sleep (simulated time), not by the poll.
        _log_interrupted("ROS shutdown")
        return 1
    else:
        if cancelled_by_operator(result.reason):
            rospy.logwarn("navseq: mission cancelled by the operator (~cancel)")
            topics.over = "the mission was cancelled"
        elif result.success:
            rospy.loginfo("navseq: mission succeeded (%s)", result.reason)
            topics.over = "the mission has ended (succeeded)"
        else:
            rospy.logwarn(
                "navseq: mission ended without reaching every waypoint (%s)", result.reason
            )
            topics.over = "the mission has ended (failed)"
        code = result.exit_code
    finally:
        navigator.close()
    if settings["end_launch"]:
        return end_launch(code)
    if settings["keep_alive"]:
        return stay_up(code)
    return code


def end_launch(mission_code: int) -> int:
    """Ask the roslaunch that started the node to shut down, then wait for it to stop us."""

    def signal_roslaunch() -> str | None:
        why_not = end_parent_launch()
        return None if why_not is None else f"~end_launch: {why_not}"

    return stay_up(
        mission_code, "mission over; ending the launch (~end_launch)", then=signal_roslaunch
    )


def stay_up(
    mission_code: int,
    why: str = "mission over; staying up (~keep_alive) until shut down",
    then: Callable[[], str | None] | None = None,
) -> int:
    """Keep the node (its latched topics and services) up until it is shut down.

    Returns ``mission_code`` however the node is stopped: the mission is over, so a
    signal interrupts nothing, and roslaunch (which stops nodes with SIGINT) should
    not see a finished mission as a failure. ``then`` runs once the node's signal
    handlers are in place (ending the launch sends a SIGINT that comes straight back);
    a reason it returns means there is nothing to wait for: the node just exits.
    """
    # rospy's own signal handlers are off (see ensure_node); the node's are set here.
    with StopSignals() as stop:
        rospy.loginfo("navseq: %s", why)
        if then is not None and (why_not := then()) is not None:
            rospy.logwarn("navseq: %s; the node just exits", why_not)
            return mission_code
        while not rospy.core.is_shutdown_requested() and not stop.wait(KEEP_ALIVE_POLL):
            pass
    if stop.received:
        rospy.loginfo("navseq: %s; shutting down", stop.received[0])
    return mission_code


def _log_interrupted(cause: str) -> None:
    rospy.logwarn("navseq: interrupted (%s); the active goal was cancelled", cause)


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
