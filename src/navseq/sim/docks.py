"""Docks for the simulator's docking server, read from a file in Nav2's formats.

opennav_docking (Nav2 Jazzy) takes its dock instances in either of two forms, and so
does ``navseq sim --ros2 --docks FILE``:

- the ``docking_server`` parameters' form: ``docks: [home_dock, ...]`` and, for each
  name, a mapping ``home_dock: {type: simple_charging_dock, frame: map, pose: [x, y, yaw]}``
  (also inside ``docking_server: {ros__parameters: ...}``, as in a Nav2 params file);
- the dock database file's form (``dock_database_filepath``): ``docks: {home_dock: {type:
  ..., frame: ..., pose: [x, y, yaw]}}``.

``frame`` defaults to ``map`` (Nav2's default) and must be ``map``: the simulator knows
no other fixed frame. ``type`` may be left out while one dock type exists, as in Nav2;
the only type is nav2_bringup's ``simple_charging_dock``. ``pose`` is metres, metres,
radians. Every problem names the file and line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.located import Located, describe
from navseq.mission.problems import Problems
from navseq.mission.reading import read_mission_text
from navseq.mission.yaml_doc import parse_yaml

#: nav2_bringup's dock plugins (``dock_plugins``): the types a dock may have.
DOCK_TYPES = ("simple_charging_dock",)
DOCK_FRAME = "map"


@dataclass(frozen=True)
class Dock:
    """One dock instance: where the robot stands when docked, facing the dock."""

    name: str
    type: str
    frame: str
    pose: Pose2D


def read_docks_file(path: Path) -> tuple[Dock, ...]:
    """The docks of ``path``; a NavseqError naming file:line for anything wrong."""
    source = str(path)
    problems = Problems()
    doc = parse_yaml(read_mission_text(path, what="docks file"), source, problems)
    problems.raise_if_any()
    if doc is not None and doc.is_mapping and doc.get("docking_server") is not None:
        doc = doc.value["docking_server"]
        if doc.is_mapping and doc.get("ros__parameters") is not None:
            doc = doc.value["ros__parameters"]
    docks_node = doc.get("docks") if doc is not None else None
    if doc is None or docks_node is None:
        raise NavseqError(
            "has no docks: (Nav2's form: docks: [home_dock] and home_dock: {type: "
            "simple_charging_dock, frame: map, pose: [x, y, yaw]})",
            source=doc.where if doc is not None else source,
        )
    if docks_node.is_list:
        entries = [(name, _named(doc, name, problems)) for name in docks_node.value]
    elif docks_node.is_mapping:
        entries = [
            (Located(key, docks_node.where_key(key)), value)
            for key, value in docks_node.value.items()
        ]
    else:
        raise NavseqError(
            f"docks: must be a list of dock names or a mapping of docks, not "
            f"{describe(docks_node.value)}",
            source=docks_node.where,
        )
    docks: list[Dock] = []
    for name, node in entries:
        if node is not None:
            dock = _dock(name, node, problems)
            if dock is not None:
                docks.append(dock)
    seen: set[str] = set()
    for name, _node in entries:
        if isinstance(name.value, str) and name.value in seen:
            problems.add(f"dock {name.value!r} is given twice", source=name.where)
        seen.add(str(name.value))
    if not entries:
        problems.add("docks: is empty", source=docks_node.where)
    problems.raise_if_any()
    return tuple(docks)


def _named(doc: Located, name: Located, problems: Problems) -> Located | None:
    """The section of the dock ``name`` lists, or None (recorded as a problem)."""
    if not isinstance(name.value, str) or not name.value:
        problems.add(f"a dock name must be text, not {describe(name.value)}", source=name.where)
        return None
    node = doc.get(name.value)
    if node is None:
        problems.add(
            f"dock {name.value!r} is listed in docks: but has no section "
            f"{name.value}: {{type, frame, pose}}",
            source=name.where,
        )
    return node


def _dock(name: Located, node: Located, problems: Problems) -> Dock | None:
    subject = f"dock {name.value!r}"
    if not node.is_mapping:
        problems.add(
            f"must be a mapping {{type, frame, pose}}, not {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
        return None
    for key in node.value:
        if key not in ("type", "frame", "pose", "id"):
            problems.add(
                f"unknown field {key!r} (type, frame, pose, id)",
                source=node.where_key(key),
                subject=subject,
            )
    kind = _text(node, "type", DOCK_TYPES[0], subject, problems)
    if kind is not None and kind not in DOCK_TYPES:
        problems.add(
            f"type {kind!r} is not a dock plugin of nav2_bringup's docking_server "
            f"({', '.join(DOCK_TYPES)})",
            source=node.where_key("type"),
            subject=subject,
        )
    frame = _text(node, "frame", DOCK_FRAME, subject, problems)
    if frame is not None and frame.lstrip("/") != DOCK_FRAME:
        problems.add(
            f"frame {frame!r}: the simulator's docks are in the {DOCK_FRAME!r} frame",
            source=node.where_key("frame"),
            subject=subject,
        )
    pose = _pose(node, subject, problems)
    if kind is None or frame is None or pose is None:
        return None
    return Dock(str(name.value), kind, DOCK_FRAME, pose)


def _text(node: Located, key: str, default: str, subject: str, problems: Problems) -> str | None:
    value = node.get(key)
    if value is None:
        return default
    if not isinstance(value.value, str) or not value.value:
        problems.add(
            f"{key} must be text, not {describe(value.value)}", source=value.where, subject=subject
        )
        return None
    return value.value


def _pose(node: Located, subject: str, problems: Problems) -> Pose2D | None:
    value = node.get("pose")
    if value is None:
        problems.add("has no pose: [x, y, yaw]", source=node.where, subject=subject)
        return None
    numbers = [item.value for item in value.value] if value.is_list else None
    if (
        numbers is None
        or len(numbers) != 3
        or not all(
            isinstance(n, int | float) and not isinstance(n, bool) and math.isfinite(n)
            for n in numbers
        )
    ):
        problems.add(
            f"pose must be three numbers [x, y, yaw] (metres, metres, radians), not "
            f"{describe(value.value)}",
            source=value.where,
            subject=subject,
        )
        return None
    return Pose2D(float(numbers[0]), float(numbers[1]), float(numbers[2]))


__all__ = ["DOCK_TYPES", "Dock", "read_docks_file"]
