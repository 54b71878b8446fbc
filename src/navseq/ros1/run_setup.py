"""``navseq run --navigator ros1``: connect to the navigation stack before the mission.

Everything that needs the running stack is done here, before the robot moves and before
any file is written, so a problem is one clear :class:`NavseqError` (exit 2): the
action server must answer, the stack's clock must run (see
:meth:`Ros1Navigator.wait_for_server`), and, unless the user named a robot, the robot
profile is read from move_base's parameters (:func:`navstack_robot`). The mission's
markers and status topics are set up as the navseq node's are (:class:`MissionTopics`).
Without a map file, pre-flight runs on the map the stack latches on ``map`` (in the
robot's namespace, else ``/map``: :mod:`navseq.navigators.stack_map`), read by
:func:`read_stack_map`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import rosgraph.names
import rospy
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg

from navseq.mission.model import Mission
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.navigators.registry import NavigatorDraft, NavigatorSetup
from navseq.navigators.settings import Ros1NavigatorSettings, with_defaults
from navseq.navigators.stack_map import (
    GRAPH_LOOK,
    MAP_TOPIC,
    MAP_WAIT,
    MapCatch,
    StackMap,
    map_topics,
    map_wait_setting,
    preflight_on_stack_map,
    stack_map_from_message,
)
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


def own_map_topic(namespace: str) -> str:
    """``map`` resolved in the robot's namespace (``--ns``, else this node's, which
    ``ROS_NAMESPACE`` sets), as move_base's static layer resolves it."""
    name = rosgraph.names.ns_join(namespace, MAP_TOPIC) if namespace else MAP_TOPIC
    return str(rospy.resolve_name(name))


def read_stack_map(topics: Sequence[str], timeout: float = MAP_WAIT) -> StackMap | None:
    """The map (``nav_msgs/OccupancyGrid``) from the best of ``topics`` (resolved names,
    best first) heard within ``timeout`` wall seconds, or None. map_server latches it, so
    it comes as soon as the subscription connects; which topic wins is
    :class:`~navseq.navigators.stack_map.MapCatch`'s rule, asking the master who
    publishes. NavseqError when the message's fields do not make a map."""
    catch = MapCatch(topics)
    subscribers = [
        # rospy calls back with (message, callback_args).
        rospy.Subscriber(
            topic,
            OccupancyGridMsg,
            lambda message, topic: catch.offer(topic, message),
            callback_args=topic,
            queue_size=1,
        )
        for topic in catch.topics
    ]
    try:
        heard = catch.wait(timeout, _publisher_check())
    finally:
        for subscriber in subscribers:
            subscriber.unregister()
    return None if heard is None else stack_map_from_message(heard[1], heard[0])


def _publisher_check() -> Callable[[str], bool]:
    """``has_publisher(topic)`` from the master's list of published topics (asked again
    at most every :data:`~navseq.navigators.stack_map.GRAPH_LOOK` seconds)."""
    published: set[str] = set()
    asked = -math.inf

    def has_publisher(topic: str) -> bool:
        nonlocal published, asked
        if time.monotonic() - asked >= GRAPH_LOOK:
            asked = time.monotonic()
            try:
                published = {name for name, _type in rospy.get_published_topics()}
            except (OSError, rospy.ROSException):
                published = set()
        return topic in published

    return has_publisher


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


def create(settings: Ros1NavigatorSettings, draft: NavigatorDraft) -> NavigatorSetup:
    """The ``ros1`` kind: the connection, then pre-flight on a known map.

    Before anything is written the server must answer and its clock run; the robot
    comes from move_base's parameters unless the user named one (``--robot`` or the
    mission's ``robot:``), and pre-flight then checks against the stack's own robot.
    """
    mission = draft.mission
    settings = with_defaults(settings)
    assert settings.action is not None and settings.ns is not None
    assert settings.settle is not None
    frame = settings.frame or mission.frame
    map_wait = map_wait_setting(settings.map_wait)
    connection = connect_for_run(
        mission,
        action=settings.action,
        frame=frame,
        namespace=settings.ns,
        settle=settings.settle,
        read_robot=not draft.robot_given,
    )
    info: dict[str, object] = {"kind": "ros1", "action": settings.action, "frame": frame}
    info["ns"] = settings.ns
    notes = []
    if connection.robot is not None and connection.robot_note is not None:
        draft.robot = connection.robot
        info["robot_source"] = connection.robot_note
        notes.append(connection.robot_note)
    info["robot"] = draft.robot.name
    try:
        grid = draft.optional_map()
        if draft.map_path is None:
            # No map file: the one the stack latches, checked for the robot it drives.
            topics = map_topics(own_map_topic(settings.ns))
            used = preflight_on_stack_map(draft, read_stack_map, topics, frame or "map", map_wait)
            grid = used.grid
            info["map_source"] = used.source
            notes.append(used.note)
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
