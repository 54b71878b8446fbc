"""``navseq run --navigator nav2``: connect to Nav2 before the mission.

Everything that needs the running stack is done here, before the robot moves and before
any file is written, so a problem is one clear :class:`NavseqError` (exit 2): the
``navigate_to_pose`` server must answer within ``--server-timeout`` wall seconds and,
under ``use_sim_time``, its clock must run (:meth:`Nav2Navigator.wait_for_server`).
The robot profile is ``--robot``, else the mission's ``robot:``, else the one Nav2's own
node parameters describe (:mod:`navseq.ros2.nav2_params`: outline, inflation, goal
tolerance, speeds; what it does not say keeps the default's value); pre-flight runs on
``--map`` / the mission's ``map:`` when there is one, else on the map Nav2's map_server
publishes (``map`` in the namespace, else ``/map``: :mod:`navseq.navigators.stack_map`),
waited for ``--map-wait`` wall seconds.

This module imports rclpy (through the navigator): the registry imports it only when
``nav2`` is chosen, and turns an ImportError into one message saying to source ROS 2.
"""

from __future__ import annotations

from navseq.errors import NavseqError
from navseq.navigators.registry import NavigatorDraft, NavigatorSetup
from navseq.navigators.settings import Nav2NavigatorSettings, with_defaults
from navseq.navigators.stack_map import (
    MAP_TOPIC,
    map_topics,
    map_wait_setting,
    preflight_on_stack_map,
)
from navseq.ros2.nav2_params import NODES, profile_from_nav2_params
from navseq.ros2.navigator import Nav2Navigator, join_name
from navseq.sim.options import namespace_of

SERVER_WAIT = 30.0  # s of wall time for the action server by default (ROS 1 waits as long)


def sim_time_setting(text: str) -> bool | None:
    """``--use-sim-time auto|true|false`` -> None (auto: follow /clock), True, False."""
    value = str(text).strip().lower()
    if value == "auto":
        return None
    if value in ("true", "yes", "on", "1"):
        return True
    if value in ("false", "no", "off", "0"):
        return False
    raise NavseqError(f"expected auto, true or false, not {text!r}", source="--use-sim-time")


def create(settings: Nav2NavigatorSettings, draft: NavigatorDraft) -> NavigatorSetup:
    """The ``nav2`` kind: the connection, then pre-flight on a known map; NavseqError on
    any problem."""
    mission = draft.mission
    settings = with_defaults(settings)
    frame = settings.frame or mission.frame
    namespace = namespace_of(settings.ns or "")
    use_sim_time = sim_time_setting(str(settings.use_sim_time))
    server_timeout = float(settings.server_timeout)
    if not 0.0 < server_timeout < float("inf"):
        raise NavseqError(
            f"must be > 0 seconds, not {settings.server_timeout}", source="--server-timeout"
        )
    action = settings.action
    if not action or any(c.isspace() for c in action):
        raise NavseqError(f"{action!r} is not an action name", source="--action")
    map_wait = map_wait_setting(settings.map_wait)
    navigator = Nav2Navigator(action, frame, namespace=namespace, use_sim_time=use_sim_time)
    notes = []
    robot_source = None
    map_source = None
    try:
        navigator.require_server(server_timeout)
        if settings.from_ll:
            from navseq.navigators.gps_service import converted_through_from_ll

            # Before pre-flight: the stack's own conversion is what is checked and driven.
            draft.mission = converted_through_from_ll(
                navigator.ros_tasks(), settings.from_ll, mission, server_timeout
            )
            notes.append(f"GPS waypoints converted by {settings.from_ll} (fromLL)")
        if not draft.robot_given:
            # The robot Nav2 drives, as its own parameters say, unless the user named one:
            # its goal checker's tolerance is the one arrival is judged by.
            params = navigator.read_parameters(NODES)
            draft.robot, robot_source = profile_from_nav2_params(params, namespace, draft.robot)
            notes.append(robot_source)
        grid = draft.optional_map()
        if draft.map_path is None:
            # No map file: the one Nav2 publishes, checked for the robot Nav2 drives.
            topics = map_topics(join_name(namespace, MAP_TOPIC))
            used = preflight_on_stack_map(
                draft, navigator.read_map, topics, frame or "map", map_wait
            )
            grid, map_source = used.grid, used.source
            notes.append(used.note)
    except BaseException:
        navigator.close()
        raise
    info: dict[str, object] = {
        "kind": "nav2",
        "action": navigator.resolved_action,
        "frame": frame,
        "ns": namespace,
        "use_sim_time": navigator.uses_sim_time,
        "robot": draft.robot.name,
    }
    if robot_source is not None:
        info["robot_source"] = robot_source
    if map_source is not None:
        info["map_source"] = map_source
    if use_sim_time is None and navigator.uses_sim_time:
        notes.append("/clock is published: navseq runs on simulation time (use_sim_time)")
    return NavigatorSetup(
        make_navigator=lambda: navigator,
        info=info,
        grid=grid,
        notes=notes,
    )
