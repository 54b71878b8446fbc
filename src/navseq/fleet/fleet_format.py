"""The fleet YAML file (reference: docs/fleet.md).

::

    navseq_fleet: 1
    map: ../maps/warehouse.yaml        # optional: else the mission's map:
    mission: orders.yaml               # a navseq mission file, or a mission inline
    robots:
      - name: alpha
        namespace: alpha               # optional: else the name
        start: {x: 0.5, y: 1.0, yaw: 0}
        robot: turtlebot3_waffle       # optional: else the mission's robot:, else burger
        max_time: 900                  # optional: seconds its share may take
    waypoints:                         # optional: who may take a waypoint
      cold_store: {robots: [alpha]}    # by name, or by number ("7")

Every problem is reported at once, each with its file:line, as for missions; the
mission's own problems keep the mission file's lines.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import TypeVar

from navseq.errors import NavseqError
from navseq.fleet.model import Fleet, FleetRobot
from navseq.mission import fields
from navseq.mission.located import Located, describe
from navseq.mission.model import Mission
from navseq.mission.navseq_format import (
    mission_from_document,
    read_map_path,
    read_path,
    read_start,
)
from navseq.mission.problems import Problems
from navseq.mission.reading import read_mission_text
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.mission.robot_format import read_robot
from navseq.mission.yaml_doc import parse_yaml

T = TypeVar("T")

FORMAT_VERSION = 1
TOP_LEVEL_KEYS = ("navseq_fleet", "map", "mission", "robots", "waypoints")
ROBOT_KEYS = ("name", "namespace", "start", "robot", "max_time")
WAYPOINT_RULE_KEYS = ("robots",)
#: Robots at most: routing and one simulator in one process are made for small fleets.
MAX_ROBOTS = 50
# A robot's name is also a folder of the run and its default ROS namespace.
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}")
_NAMESPACE = re.compile(r"/?[A-Za-z_][A-Za-z0-9_]{0,63}(?:/[A-Za-z_][A-Za-z0-9_]{0,63}){0,7}/?")


def load_fleet(path: Path, mission_path: Path | None = None) -> Fleet:
    """The fleet a fleet file describes; ``mission_path`` replaces its ``mission:``.

    Raises NavseqError for one problem, MissionErrors for several (all at once).
    """
    fleet, problems = inspect_fleet(path, mission_path)
    problems.raise_if_any()
    assert fleet is not None
    return fleet


def inspect_fleet(path: Path, mission_path: Path | None = None) -> tuple[Fleet | None, Problems]:
    """The fleet as far as it reads, and every problem of the file (top to bottom).

    With problems, the fleet (when there is one) holds the robots that read well, so
    that their start poses can be checked against the map in the same report.
    """
    source = str(path)
    problems = Problems()
    doc = fields.attempt(
        problems,
        lambda: parse_yaml(read_mission_text(path, what="fleet file"), source, problems),
    )
    if problems.errors:
        return None, problems
    if doc is None or not doc.is_mapping:
        problems.add(
            "must be a mapping with a robots: list and a mission: "
            f"(docs/fleet.md), got {describe(None if doc is None else doc.value)}",
            source=source,
        )
        return None, problems
    fleet = fleet_from_document(doc, source, path.resolve().parent, problems, mission_path)
    problems.errors.sort(key=line_order)
    return fleet, problems


def line_order(error: NavseqError) -> tuple[str, int]:
    """Where an error is, to sort them as the file reads (other files' problems last)."""
    source = error.source or ""
    name, _, line = source.rpartition(":")
    return (name, int(line)) if line.isdigit() else (source, 0)


def fleet_from_document(
    doc: Located,
    source: str,
    base_dir: Path,
    problems: Problems,
    mission_path: Path | None = None,
) -> Fleet | None:
    """The Fleet of a parsed fleet document (problems recorded; with problems, what read
    well), or None when there is no mission to share."""
    fields.check_keys(doc, TOP_LEVEL_KEYS, None, problems)
    version = doc.get("navseq_fleet")
    if version is not None and (isinstance(version.value, bool) or version.value != FORMAT_VERSION):
        problems.add(
            f"format version {describe(version.value)} is not supported; this navseq reads "
            f"version {FORMAT_VERSION}",
            source=version.where,
            subject="field navseq_fleet",
        )
    map_node = doc.get("map")
    fleet_map = None
    if map_node is not None and map_node.value is not None:
        fleet_map = fields.attempt(problems, lambda: read_map_path(map_node, "field map", base_dir))
    mission, read_from = _mission(doc, source, base_dir, problems, mission_path)
    default_profile = mission.robot if mission is not None and mission.robot else DEFAULT_PROFILE
    robots = _robots(doc, source, default_profile, problems)
    allowed = _allowed(doc.get("waypoints"), mission, _listed_names(doc), problems)
    if mission is None:
        return None
    return Fleet(
        robots=tuple(robots),
        mission=mission,
        map=fleet_map if fleet_map is not None else mission.map,
        allowed=MappingProxyType(allowed),
        source=source,
        mission_path=read_from,
    )


def _mission(
    doc: Located,
    source: str,
    base_dir: Path,
    problems: Problems,
    given: Path | None,
) -> tuple[Mission | None, Path | None]:
    """The mission the fleet shares (a file, or inline), and its file (None: inline)."""
    from navseq.mission import load_mission

    if given is not None:
        path: Path | None = given
    else:
        node = doc.get("mission")
        if node is None:
            problems.add(
                "has no mission: give mission: (a mission file, or a mission inline) or "
                "the mission on the command line",
                source=doc.where,
            )
            return None, None
        if node.is_mapping:
            mission = mission_from_document(node, f"{source} (mission:)", base_dir, problems)
            return mission, None
        path = fields.attempt(problems, lambda: read_path(node, "field mission", base_dir))
    if path is None:
        return None, None
    try:
        return load_mission(path), path
    except NavseqError as error:
        problems.record(error)
        return None, path


def _robots(
    doc: Located, source: str, default_profile: RobotProfile, problems: Problems
) -> list[FleetRobot]:
    node = doc.get("robots")
    if node is None:
        problems.add("has no robots: list (docs/fleet.md)", source=source)
        return []
    items = fields.attempt(problems, lambda: fields.sequence(node, "field robots"))
    if items is None:
        return []
    if not items:
        problems.add("the robot list is empty", source=node.where, subject="field robots")
        return []
    if len(items) > MAX_ROBOTS:
        problems.add(
            f"lists {len(items)} robots; a fleet has at most {MAX_ROBOTS}",
            source=node.where,
            subject="field robots",
        )
        return []
    robots = [_robot(item, index, default_profile, problems) for index, item in enumerate(items)]
    kept = [robot for robot in robots if robot is not None]
    _check_unique(kept, lambda robot: robot.name, "name", problems)
    # A robot named twice is reported once, not again for the namespace its name gave it.
    named_once = [r for r in kept if [o.name for o in kept].count(r.name) == 1]
    _check_unique(named_once, lambda robot: robot.namespace.strip("/"), "namespace", problems)
    return [r for r in kept if r in named_once]


def _robot(
    node: Located, index: int, default_profile: RobotProfile, problems: Problems
) -> FleetRobot | None:
    owner = f"robot {index + 1}"
    if fields.attempt(problems, lambda: fields.mapping(node, owner)) is None:
        return None
    before = len(problems)
    fields.check_keys(node, ROBOT_KEYS, owner, problems)
    name = _required(node, "name", owner, problems, _read_name)
    if name is not None:
        owner = f"robot {index + 1} '{name}'"
    namespace_node = node.get("namespace")
    namespace = name
    if namespace_node is not None:
        namespace = fields.attempt(
            problems, lambda: _read_namespace(namespace_node, f"{owner}, field namespace")
        )
    start = _required(node, "start", owner, problems, read_start)
    profile = default_profile
    robot_node = node.get("robot")
    if robot_node is not None:
        profile = (
            fields.attempt(problems, lambda: read_robot(robot_node, f"{owner}, field robot"))
            or default_profile
        )
    max_time = None
    time_node = node.get("max_time")
    if time_node is not None and time_node.value is not None:
        max_time = fields.attempt(
            problems,
            functools.partial(fields.positive_seconds, time_node, f"{owner}, field max_time"),
        )
    if len(problems) > before or name is None or namespace is None or start is None:
        return None
    return FleetRobot(name, namespace, start, profile, max_time, node.where)


def _required(
    node: Located,
    key: str,
    owner: str,
    problems: Problems,
    reader: Callable[[Located, str], T],
) -> T | None:
    entry = node.get(key)
    if entry is None:
        problems.add(f"has no {key}:", source=node.where, subject=owner)
        return None
    return fields.attempt(problems, lambda: reader(entry, fields.field_subject(owner, key)))


def _read_name(node: Located, subject: str) -> str:
    name = fields.text(node, subject)
    if not _NAME.fullmatch(name):
        raise NavseqError(
            f"{name!r} is no robot name: a letter, then letters, digits or _ (it names "
            "the robot's folder of a run and its default namespace)",
            source=node.where,
            subject=subject,
        )
    return name


def _read_namespace(node: Located, subject: str) -> str:
    namespace = fields.text(node, subject)
    if not _NAMESPACE.fullmatch(namespace):
        raise NavseqError(
            f"{namespace!r} is no ROS namespace (like robot1 or /fleet/robot1)",
            source=node.where,
            subject=subject,
        )
    return namespace


def _check_unique(
    robots: Sequence[FleetRobot],
    key: Callable[[FleetRobot], str],
    what: str,
    problems: Problems,
) -> None:
    seen: dict[str, FleetRobot] = {}
    for robot in robots:
        value = key(robot)
        first = seen.setdefault(value, robot)
        if first is not robot:
            problems.add(
                f"has the {what} {value!r} of robot {first.name!r} ({first.where}); each "
                f"robot needs its own {what}",
                source=robot.where,
                subject=f"robot '{robot.name}'",
            )


def _listed_names(doc: Located) -> set[str]:
    """The names the robot list gives, also of robots with problems of their own."""
    node = doc.get("robots")
    if node is None or not node.is_list:
        return set()
    names = (item.get("name") for item in node.value)
    return {name.value for name in names if name is not None and isinstance(name.value, str)}


def _allowed(
    node: Located | None,
    mission: Mission | None,
    names: set[str],
    problems: Problems,
) -> dict[int, tuple[str, ...]]:
    """``waypoints:``: for a waypoint (by name or number), the robots that may take it."""
    if node is None or node.value is None:
        return {}
    if fields.attempt(problems, lambda: fields.mapping(node, "field waypoints")) is None:
        return {}
    allowed: dict[int, tuple[str, ...]] = {}
    for key, rule in node.value.items():
        subject = f"waypoints, {fields.shortened(key)}"
        index = _waypoint_index(key, mission)
        if index is None and mission is not None:
            problems.add(
                "names no waypoint of the mission (a waypoint's name, or its number from 1 "
                f"to {len(mission.waypoints)})",
                source=node.where_key(key),
                subject=subject,
            )
        if fields.attempt(problems, functools.partial(fields.mapping, rule, subject)) is None:
            continue
        fields.check_keys(rule, WAYPOINT_RULE_KEYS, subject, problems)
        listed = rule.get("robots")
        if listed is None:
            problems.add("has no robots: list", source=rule.where, subject=subject)
            continue
        entries = fields.attempt(
            problems, functools.partial(fields.sequence, listed, f"{subject}, field robots")
        )
        if entries is None:
            continue
        chosen = []
        for entry in entries:
            robot = fields.attempt(
                problems, functools.partial(fields.text, entry, f"{subject}, field robots")
            )
            if robot is None:
                continue
            if robot not in names and names:
                problems.add(
                    f"{robot!r} is none of the fleet's robots ({', '.join(sorted(names))})",
                    source=entry.where,
                    subject=subject,
                )
                continue
            chosen.append(robot)
        if not entries:
            problems.add(
                "lists no robot: no robot may take this waypoint (remove it from the "
                "mission, or name a robot)",
                source=listed.where,
                subject=subject,
            )
        if index is not None:
            allowed[index] = tuple(chosen)
    return allowed


def _waypoint_index(key: str, mission: Mission | None) -> int | None:
    if mission is None:
        return None
    for index, waypoint in enumerate(mission.waypoints):
        if waypoint.name == key:
            return index
    if key.isdigit() and 1 <= int(key) <= len(mission.waypoints):
        return int(key) - 1
    return None


__all__ = [
    "FORMAT_VERSION",
    "MAX_ROBOTS",
    "fleet_from_document",
    "inspect_fleet",
    "line_order",
    "load_fleet",
]
