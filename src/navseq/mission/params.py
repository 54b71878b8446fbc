"""Missions given as ROS parameters: the node's private namespace, or the parameters a
launch file or rosparam YAML file sets for a node.

Three ways to give the waypoints, exactly one per namespace:

- ``p_seq`` + ``yea_seq``: the tutorial's flat lists (see :mod:`tutorial_format`);
- ``waypoints``: the structured list of navseq's YAML format;
- ``mission``: the path of a mission file in any format navseq reads.

Next to them, optional mission-wide keys: ``frame``, ``loops``, ``map``, ``start``,
``server_timeout`` and every policy key (``goal_timeout``, ``retries``, ...), which
override what a ``mission`` file says.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from contextvars import ContextVar
from pathlib import Path

from navseq.mission import fields
from navseq.mission.geodesy import Datum
from navseq.mission.located import Located
from navseq.mission.model import POLICY_KEYS, Mission, Policy, Waypoint
from navseq.mission.navseq_format import (
    MISSION_SETTINGS,
    read_datum_setting,
    read_path,
    read_settings,
    read_waypoints,
)
from navseq.mission.problems import Problems
from navseq.mission.tutorial_format import POSITIONS_KEY, YAWS_KEY, waypoints_from_sequences

#: Reads the mission file a ``mission`` parameter names (the loader's ``load_mission``,
#: handed down by the loader so that this module need not import it).
OpenMission = Callable[[Path], Mission]

WAYPOINT_SOURCES = (POSITIONS_KEY, YAWS_KEY, "waypoints", "mission")
MISSION_PARAM_KEYS = (*WAYPOINT_SOURCES, *MISSION_SETTINGS, *POLICY_KEYS)

# True while loading a file named by a 'mission' parameter: that file may not name
# another one, so a launch file that names itself cannot recurse.
_reading_named_file: ContextVar[bool] = ContextVar("_reading_named_file", default=False)


def mission_from_namespace(
    namespace: Located,
    problems: Problems,
    *,
    base_dir: Path | None,
    strict: bool,
    open_mission: OpenMission,
) -> Mission | None:
    """Build the mission from one parameter namespace, recording every problem.

    ``strict`` reports unknown keys (a node's own namespace); launch and rosparam
    files are read leniently, since a node's namespace there may hold other settings.
    ``base_dir`` anchors relative ``mission`` and ``map`` paths (None: the current folder);
    ``open_mission`` reads the file a ``mission`` parameter names.
    """
    before = len(problems)
    if strict:
        fields.check_keys(namespace, MISSION_PARAM_KEYS, None, problems)
    given = [key for key in ("waypoints", "mission") if namespace.get(key) is not None]
    if namespace.get(POSITIONS_KEY) is not None or namespace.get(YAWS_KEY) is not None:
        given.insert(0, f"{POSITIONS_KEY}/{YAWS_KEY}")
    if len(given) != 1:
        what = " and ".join(given) if given else "none of them"
        problems.add(
            f"give the waypoints exactly one way: {POSITIONS_KEY} + {YAWS_KEY} (the "
            f"tutorial's lists), waypoints, or mission (a file); found {what}",
            source=namespace.where,
        )
        return None
    settings = read_settings(namespace, base_dir, problems)
    datum = read_datum_setting(namespace, problems)
    if isinstance(datum, Datum):
        settings["datum"] = datum
    policy = fields.policy_values(namespace, None, problems)
    if given[0] == "mission" and _reading_named_file.get():
        problems.add(
            "a mission file named by a 'mission' parameter cannot itself name another one",
            source=namespace.value["mission"].where,
            subject="field mission",
        )
        return None
    if given[0] == "mission":
        base = _mission_from_file(namespace.value["mission"], base_dir, problems, open_mission)
        if base is None or len(problems) > before:
            return None
        return dataclasses.replace(base, defaults=base.defaults.with_overrides(policy), **settings)
    waypoints: tuple[Waypoint, ...]
    if given[0] == "waypoints":
        waypoints = read_waypoints(namespace.value["waypoints"], problems, datum)
        source = namespace.value["waypoints"].where
    else:
        positions = namespace.get(POSITIONS_KEY)
        waypoints = waypoints_from_sequences(positions, namespace.get(YAWS_KEY), problems)
        source = positions.where if positions is not None else namespace.where
    if len(problems) > before:
        return None
    return Mission(waypoints=waypoints, defaults=Policy(**policy), source=source, **settings)


def _mission_from_file(
    node: Located, base_dir: Path | None, problems: Problems, open_mission: OpenMission
) -> Mission | None:
    from navseq.errors import NavseqError

    path = fields.attempt(problems, lambda: read_path(node, "field mission", base_dir))
    if path is None:
        return None
    if "$(" in str(path):
        problems.add(
            f"uses a roslaunch substitution ({node.value[:40]}) that navseq cannot resolve here",
            source=node.where,
            subject="field mission",
        )
        return None
    token = _reading_named_file.set(True)
    try:
        return open_mission(path)
    except NavseqError as error:
        problems.record(error)
        return None
    finally:
        _reading_named_file.reset(token)
