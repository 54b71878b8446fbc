"""``navseq run --navigator ros1``: connect to the navigation stack before the mission.

Everything that needs the running stack is done here, before the robot moves and before
any file is written, so a problem is one clear :class:`NavseqError` (exit 2): the
action server must answer, the stack's clock must run (see
:meth:`Ros1Navigator.wait_for_server`), and, unless the user named a robot, the robot
profile is read from move_base's parameters (:func:`navstack_robot`). The mission's
markers and status topics are set up as the navseq node's are (:class:`MissionTopics`).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

from navseq.mission.model import Mission
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.navigators.registry import NavigatorDraft, NavigatorSetup
from navseq.ros1.mission_topics import MissionTopics, run_topics_namespace
from navseq.ros1.navigator import DEFAULT_SETTLE, Ros1Navigator
from navseq.ros1.navstack_params import read_navstack_profile

SERVER_WAIT = 30.0  # s of wall time for the action server, as the navseq node waits


@dataclass
class Ros1Connection:
    """A navigator whose server answered, the robot it drives, and the mission's topics."""

    navigator: Ros1Navigator
    topics: MissionTopics
    robot: RobotProfile | None  # None: the user named the robot; nothing was read
    robot_note: str | None  # what was read from the stack, one line, for stderr


def navstack_robot(
    navigator: Ros1Navigator, base: RobotProfile = DEFAULT_PROFILE
) -> tuple[RobotProfile, str]:
    """The robot profile the running move_base is configured for, and a note saying so."""
    return read_navstack_profile(navigator.resolved_action, base)


def connect_for_run(
    mission: Mission,
    *,
    action: str,
    frame: str | None,
    namespace: str,
    settle: float = DEFAULT_SETTLE,
    read_robot: bool = True,
    server_wait: float = SERVER_WAIT,
) -> Ros1Connection:
    """Find the server (and its clock), read the robot, set up markers; or NavseqError."""
    navigator = Ros1Navigator(action, frame, namespace=namespace, settle=settle)
    try:
        navigator.require_server(server_wait)
        robot, note = navstack_robot(navigator) if read_robot else (None, None)
        topics = MissionTopics(mission, run_topics_namespace(namespace))
    except BaseException:
        navigator.close()
        raise
    return Ros1Connection(navigator, topics, robot, note)


def create(args: argparse.Namespace, draft: NavigatorDraft) -> NavigatorSetup:
    """``navseq run --navigator ros1``: the connection, then pre-flight on a known map.

    Before anything is written the server must answer and its clock run; the robot
    comes from move_base's parameters unless the user named one (``--robot`` or the
    mission's ``robot:``), and pre-flight then checks against the stack's own robot.
    """
    mission = draft.mission
    frame = args.frame or mission.frame
    connection = connect_for_run(
        mission,
        action=args.action,
        frame=frame,
        namespace=args.ns,
        settle=args.settle,
        read_robot=getattr(args, "robot", None) is None and mission.robot is None,
    )
    info: dict[str, object] = {"kind": "ros1", "action": args.action, "frame": frame}
    info["ns"] = args.ns
    notes = []
    if connection.robot is not None and connection.robot_note is not None:
        draft.robot = connection.robot
        info["robot_source"] = connection.robot_note
        notes.append(connection.robot_note)
    info["robot"] = draft.robot.name
    try:
        grid = draft.optional_map()
    except BaseException:
        connection.navigator.close()
        raise
    return NavigatorSetup(
        make_navigator=lambda: connection.navigator,
        info=info,
        grid=grid,
        notes=notes,
        listeners=[connection.topics],
    )
