"""Waypoints as Nav2 users already have them: the RViz panel's file and echoed poses.

Two sources, both YAML, recognised by their shape (:func:`nav2_reader_for`):

- **The waypoint file of Nav2's RViz panel** (nav2_rviz_plugins' ``Nav2Panel``, Jazzy:
  ``handleGoalSaver`` writes it, ``handleGoalLoader`` reads it back)::

      waypoints:
        waypoint0:
          pose: [x, y, z]
          orientation: [w, x, y, z]     # w first, as the panel writes it

  The panel loads the entries in the file's order and always in frame ``map``; so
  does navseq. It saves its file with ``.yaml`` appended to the name chosen.
- **A ``geometry_msgs/PoseArray`` or ``nav_msgs/Path`` as ``ros2 topic echo`` prints it**
  (``header:`` and ``poses:``; a Path's poses are PoseStampeds, ``pose:`` inside). An
  echo of several messages (separated by ``---``) gives the **last** one, the latest
  the topic carried; the frame is the message's ``header.frame_id``.

:func:`dump_nav2_panel` writes a mission back in the panel's format (what the panel can
hold: positions and headings; names and policies have no place there).
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Sequence
from pathlib import Path

from navseq.errors import NavseqError
from navseq.geometry import yaw_to_quaternion
from navseq.mission import fields
from navseq.mission.located import Located
from navseq.mission.model import Mission, Waypoint
from navseq.mission.navseq_format import quaternion_yaw_checked
from navseq.mission.problems import Problems
from navseq.mission.yaml_doc import parse_yaml

Nav2Reader = Callable[[Located, str, Problems], "Mission | None"]

#: The frame the panel gives every pose it loads (``convert_to_msg``).
PANEL_FRAME = "map"
# A line holding only the document separator ``ros2 topic echo`` prints after a message.
_SEPARATOR = re.compile(r"^---[ \t]*$", re.MULTILINE)


def nav2_reader_for(doc: Located | None) -> Nav2Reader | None:
    """The reader of a parsed YAML document in one of Nav2's shapes, or None."""
    if doc is None or not doc.is_mapping:
        return None
    waypoints = doc.value.get("waypoints")
    if _is_panel_list(waypoints) and set(doc.value) == {"waypoints"}:
        return mission_from_panel  # navseq's own ``waypoints:`` is a list
    poses = doc.value.get("poses")
    if poses is not None and poses.is_list and set(doc.value) <= {"header", "poses"}:
        return mission_from_echoed_poses
    return None


def _is_panel_list(waypoints: Located | None) -> bool:
    """``waypoints:`` as the panel writes it: a mapping of entries, one with a ``pose``."""
    if waypoints is None or not waypoints.is_mapping or not waypoints.value:
        return False
    entries = list(waypoints.value.values())
    return all(e.is_mapping for e in entries) and any("pose" in e.value for e in entries)


def echoed_message(text: str, source: str, problems: Problems) -> Located | None:
    """The last message of ``ros2 topic echo``'s output of several (``---`` between
    them) when it is a PoseArray or Path; None for any other text (read as usual)."""
    if not _SEPARATOR.search(text):
        return None
    own = Problems()
    try:
        doc = parse_echo(text, source, own)
    except NavseqError:
        return None
    if doc is None or nav2_reader_for(doc) is None:
        return None
    for error in own.errors:
        problems.record(error)
    return doc


def last_echoed_message(text: str) -> tuple[str, int]:
    """The last non-empty YAML document of ``ros2 topic echo``'s output and the file line
    it starts on. A text without ``---`` is one document."""
    start = 0
    chunks: list[tuple[int, int]] = []
    for match in _SEPARATOR.finditer(text):
        chunks.append((start, match.start()))
        start = match.end()
    chunks.append((start, len(text)))
    for begin, end in reversed(chunks):
        chunk = text[begin:end]
        if chunk.strip() and not all(
            line.lstrip().startswith("#") for line in chunk.splitlines() if line.strip()
        ):
            return chunk, text.count("\n", 0, begin) + 1
    return text, 1


def parse_echo(text: str, source: str, problems: Problems) -> Located | None:
    """The last message of an echo (or the one document of any YAML text), parsed."""
    chunk, first_line = last_echoed_message(text)
    if first_line > 1 and chunk.startswith("\n"):
        chunk, first_line = chunk[1:], first_line + 1
    return parse_yaml(chunk, source, problems, first_line=first_line)


# --- the RViz panel's file ---------------------------------------------------------------


def mission_from_panel(doc: Located, source: str, problems: Problems) -> Mission | None:
    """The mission of a Nav2 RViz panel waypoint file (frame ``map``, file order)."""
    entries = doc.value["waypoints"]
    before = len(problems)
    waypoints: list[Waypoint] = []
    for index, key in enumerate(entries.value):
        where = entries.where_key(key)
        label = f"waypoint {index + 1} ({fields.shortened(str(key))})"
        entry = entries.value[key]
        if not entry.is_mapping:
            problems.add(
                "must be a mapping with pose: [x, y, z] and orientation: [w, x, y, z]",
                source=where,
                subject=label,
            )
            continue
        fields.check_keys(entry, ("pose", "orientation"), label, problems)
        position = _numbers(entry, "pose", 3, "[x, y, z]", label, where, problems)
        orientation = _numbers(entry, "orientation", 4, "[w, x, y, z]", label, where, problems)
        if position is None or orientation is None:
            continue
        qw, qx, qy, qz = orientation
        yaw = _yaw(
            (qx, qy, qz, qw), entry.where_key("orientation"), f"{label}, orientation", problems
        )
        if yaw is not None:
            x, y, z = position
            waypoints.append(Waypoint(x, y, yaw_rad=yaw, z=z, where=where))
    return _mission(waypoints, PANEL_FRAME, source, problems, before)


# --- PoseArray / Path as ros2 topic echo prints them ---------------------------------------


def mission_from_echoed_poses(doc: Located, source: str, problems: Problems) -> Mission | None:
    """The mission of an echoed ``PoseArray`` or ``nav_msgs/Path`` (its header's frame)."""
    before = len(problems)
    frame = _frame_of(doc.value.get("header"), problems) or PANEL_FRAME
    waypoints: list[Waypoint] = []
    for index, item in enumerate(doc.value["poses"].value):
        label = f"waypoint {index + 1}"
        pose = item.get("pose") if item.is_mapping and "pose" in item.value else item
        if not pose.is_mapping or not {"position", "orientation"} <= set(pose.value):
            problems.add(
                "must be a pose with position: {x, y, z} and orientation: {x, y, z, w}",
                source=item.where,
                subject=label,
            )
            continue
        position = _fields(pose.value["position"], ("x", "y", "z"), label, problems)
        quaternion = _fields(pose.value["orientation"], ("x", "y", "z", "w"), label, problems)
        if position is None or quaternion is None:
            continue
        yaw = _yaw(quaternion, pose.value["orientation"].where, f"{label}, orientation", problems)
        if yaw is not None:
            x, y, z = position
            waypoints.append(Waypoint(x, y, yaw_rad=yaw, z=z, where=item.where))
    return _mission(waypoints, frame, source, problems, before)


def _frame_of(header: Located | None, problems: Problems) -> str | None:
    if header is None or not header.is_mapping:
        return None
    frame = header.value.get("frame_id")
    if frame is None or frame.value in (None, ""):
        return None
    return fields.attempt(problems, lambda: fields.text(frame, "field header.frame_id"))


# --- shared --------------------------------------------------------------------------------


def _numbers(
    entry: Located,
    key: str,
    count: int,
    shape: str,
    label: str,
    where: str,
    problems: Problems,
) -> list[float] | None:
    node = entry.get(key)
    subject = fields.field_subject(label, key)
    if node is None:
        problems.add(f"is missing; the panel writes {key}: {shape}", source=where, subject=subject)
        return None
    if not node.is_list or len(node.value) != count:
        problems.add(
            f"must be a list of {count} numbers {shape}", source=node.where, subject=subject
        )
        return None
    read = fields.coordinate if key == "pose" else fields.number
    values = [
        fields.attempt(problems, functools.partial(read, item, subject)) for item in node.value
    ]
    return None if any(v is None for v in values) else [float(v) for v in values if v is not None]


def _fields(
    node: Located, names: Sequence[str], label: str, problems: Problems
) -> list[float] | None:
    if not node.is_mapping:
        problems.add(f"must be a mapping of {', '.join(names)}", source=node.where, subject=label)
        return None
    values: list[float | None] = []
    for name in names:
        item = node.get(name)
        subject = fields.field_subject(label, name)
        if item is None:
            problems.add("is missing", source=node.where, subject=subject)
            values.append(None)
            continue
        read = fields.coordinate if name in ("x", "y", "z") and "w" not in names else fields.number
        values.append(fields.attempt(problems, functools.partial(read, item, subject)))
    return None if any(v is None for v in values) else [float(v) for v in values if v is not None]


def _yaw(quaternion: Sequence[float], where: str, subject: str, problems: Problems) -> float | None:
    yaw = fields.attempt(problems, lambda: quaternion_yaw_checked(quaternion, where, subject))
    return None if yaw is None or math.isnan(yaw) else yaw


def _mission(
    waypoints: list[Waypoint], frame: str, source: str, problems: Problems, before: int
) -> Mission | None:
    if len(problems) > before:
        return None
    if not waypoints:
        problems.add("holds no waypoints", source=source)
        return None
    return Mission(waypoints=tuple(waypoints), frame=frame, source=source)


# --- writing the panel's format ------------------------------------------------------------


def dump_nav2_panel(mission: Mission) -> str:
    """The mission as the RViz panel's waypoint file (``waypoint0``... in order).

    Each waypoint's position and heading; what the panel has no place for (names,
    policies, the frame, loops) is left out: :func:`panel_left_out` says what.
    """
    lines = ["waypoints:"]
    for index, waypoint in enumerate(mission.waypoints):
        qx, qy, qz, qw = yaw_to_quaternion(waypoint.yaw_rad)
        lines += [
            f"  waypoint{index}:",
            f"    pose: [{_num(waypoint.x)}, {_num(waypoint.y)}, {_num(waypoint.z)}]",
            f"    orientation: [{_num(qw)}, {_num(qx)}, {_num(qy)}, {_num(qz)}]",
        ]
    return "\n".join(lines) + "\n"


def panel_left_out(mission: Mission) -> list[str]:
    """What of ``mission`` the panel's file cannot hold, in words (empty: nothing)."""
    left: list[str] = []
    if any(w.name for w in mission.waypoints):
        left.append("waypoint names")
    if any(w.overrides for w in mission.waypoints) or mission.defaults != type(mission.defaults)():
        left.append("policies")
    if mission.frame != PANEL_FRAME:
        left.append(f"the frame {mission.frame!r} (the panel loads every pose in 'map')")
    if mission.loops != 1:
        left.append("loops")
    if mission.map is not None or mission.start is not None or mission.robot is not None:
        left.append("map, start and robot")
    return left


def write_nav2_panel(mission: Mission, path: Path, *, overwrite: bool) -> list[str]:
    """Write the panel's file atomically (never over a file unless ``overwrite``); what
    was left out."""
    from navseq.files import write_atomically

    source = str(path)
    if path.exists() and not overwrite:
        raise NavseqError("exists already; not overwriting it", source=source)
    try:
        write_atomically(path, dump_nav2_panel(mission), replace=overwrite)
    except FileExistsError:
        raise NavseqError("exists already; not overwriting it", source=source) from None
    except OSError as error:
        raise NavseqError(f"cannot be written: {error.strerror or error}", source=source) from None
    return panel_left_out(mission)


def _num(value: float) -> str:
    rounded = round(value, 9)
    return repr(0.0 if rounded == 0 else rounded)


__all__ = [
    "PANEL_FRAME",
    "dump_nav2_panel",
    "echoed_message",
    "last_echoed_message",
    "mission_from_echoed_poses",
    "mission_from_panel",
    "nav2_reader_for",
    "panel_left_out",
    "parse_echo",
    "write_nav2_panel",
]
