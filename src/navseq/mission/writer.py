"""Writing a Mission as navseq YAML: readable (yaw in degrees, one line per waypoint)
and exact (reading the file back gives the same mission, its ``robot:`` section included).

The tutorial's launch file (``p_seq`` / ``yea_seq``) is written by
:mod:`navseq.mission.tutorial_export`.
"""

from __future__ import annotations

import functools
import io
import math
import os
import re
from pathlib import Path
from typing import Any

import yaml

from navseq.errors import NavseqError
from navseq.files import write_atomically
from navseq.geometry import Pose2D
from navseq.mission.geodesy import Datum
from navseq.mission.model import POLICY_KEYS, FailureAction, Mission, Policy, Waypoint
from navseq.mission.navseq_format import FOREVER, FORMAT_VERSION
from navseq.mission.recovery_format import recovery_document
from navseq.mission.robot import BUILTIN_PROFILES, RobotProfile
from navseq.mission.task_format import task_document
from navseq.mission.yaml_doc import EXPONENT_FLOAT

HEADER = "# navseq mission (format reference: docs/mission-format.md)\n"
# A yaw someone typed keeps up to ten decimals exactly; one computed from a quaternion
# is rounded to a millionth of a degree (2e-8 rad, far below what a robot can tell).
_EXACT_YAW_DECIMALS = 10
_ROUNDED_YAW_DECIMALS = 6


class _FlowMapping(dict):
    """A mapping written on one line: a waypoint, the start pose."""


class _FlowList(list):
    """A list written on one line: a footprint point."""


class _MissionDumper(yaml.SafeDumper):
    """Block style with lists indented under their key; waypoints one per line."""

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> None:
        super().increase_indent(flow, False)


def _represent_text(dumper: yaml.SafeDumper, data: str) -> yaml.ScalarNode:
    # PyYAML writes NEL and Unicode line separators raw inside single quotes, where
    # reading folds them away; double quotes escape them.
    style = '"' if any(ch in _LINE_BREAKS for ch in data) else None
    return dumper.represent_scalar("tag:yaml.org,2002:str", data, style=style)


_LINE_BREAKS = "\n\r\x85\u2028\u2029"
_MissionDumper.add_representer(str, _represent_text)
# The reader takes plain ``1e3`` as a number (YAML 1.2); text that looks like it is quoted.
_MissionDumper.add_implicit_resolver(
    "tag:yaml.org,2002:float", EXPONENT_FLOAT, list("-+0123456789.")
)
_MissionDumper.add_representer(
    _FlowMapping,
    lambda dumper, data: dumper.represent_mapping("tag:yaml.org,2002:map", data, flow_style=True),
)
_MissionDumper.add_representer(
    _FlowList,
    lambda dumper, data: dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=True),
)
# The dumper's implicit resolvers (the YAML 1.2 float above included), for _plain_text.
_RESOLVER = _MissionDumper(io.StringIO())


def dump_mission_yaml(mission: Mission, *, base_dir: Path | None = None, gps: bool = True) -> str:
    """The mission as navseq YAML text.

    With ``base_dir`` (the folder the file will be written to) the map path is written
    relative to it, so mission and map can be moved together. Waypoints read as
    latitude/longitude are written so again, unless ``gps`` is False (map coordinates,
    for a face that draws them).

    PyYAML writes the settings; the waypoints, one flow mapping a line, are written by
    :func:`_waypoint_lines`, exactly as PyYAML would write them: PyYAML's emitter took
    12-25 s and 450 MB for 100 000 waypoints, most of a conversion's time.
    """
    doc = _settings(mission, base_dir)
    datum = mission.datum if gps else None
    waypoints = [_waypoint(w, datum) for w in mission.waypoints]
    lines = _waypoint_lines(waypoints) if waypoints else None
    if lines is None:  # none, or one the line writer does not write as PyYAML would
        doc["waypoints"] = waypoints
        return HEADER + _dump(doc)
    # "waypoints" is the last key: the settings' text is the start of the whole dump.
    return "".join([HEADER, _dump(doc), "waypoints:\n", *lines])


def dump_mission_yaml_slowly(mission: Mission, *, base_dir: Path | None = None) -> str:
    """:func:`dump_mission_yaml`, every line written by PyYAML (the reference in tests)."""
    doc = _settings(mission, base_dir)
    doc["waypoints"] = [_waypoint(w, mission.datum) for w in mission.waypoints]
    return HEADER + _dump(doc)


def _settings(mission: Mission, base_dir: Path | None) -> dict[str, Any]:
    doc: dict[str, Any] = {"navseq": FORMAT_VERSION, "frame": mission.frame}
    if mission.map is not None:
        doc["map"] = _map_text(mission.map, base_dir)
    if mission.start is not None:
        doc["start"] = _pose(mission.start)
    doc["loops"] = FOREVER if mission.loops is None else mission.loops
    doc["server_timeout"] = mission.server_timeout
    if mission.robot is not None:
        doc["robot"] = robot_section(mission.robot)
    if mission.record:
        doc["record"] = True
    if mission.datum is not None:
        doc["datum"] = _datum(mission.datum)
    if mission.filters:
        doc["filters"] = [
            _FlowMapping(
                mask=_map_text(f.mask, base_dir),
                type=int(f.type),
                base=f.base,
                multiplier=f.multiplier,
            )
            for f in mission.filters
        ]
    doc["defaults"] = _policy_values(mission.defaults, POLICY_KEYS)
    if mission.defaults.tasks:
        doc["defaults"]["tasks"] = [task_document(t) for t in mission.defaults.tasks]
    return doc


def _dump(doc: dict[str, Any]) -> str:
    return yaml.dump(
        doc,
        Dumper=_MissionDumper,
        sort_keys=False,
        default_flow_style=False,
        allow_unicode=True,
        width=_WIDTH,
    )


# PyYAML breaks a flow mapping's line past this column: the line writer leaves longer
# lines (never a waypoint of a loaded mission: names are at most 256 characters) to it.
_WIDTH = 4096
# Text PyYAML writes plain in a flow mapping, if no implicit resolver claims it (see
# _plain_text): words of letters, digits and "_", joined by single " ", "." or "-".
# Linear without possessive quantifiers (Python 3.10 has none): a separator is never a
# word character, so no two repeats can match the same text.
_PLAIN_TEXT = re.compile(r"\w+(?:[ .-]\w+)*")
_STR_TAG = "tag:yaml.org,2002:str"


def _waypoint_lines(waypoints: list[_FlowMapping]) -> list[str] | None:
    """``  - {name: dock, x: 1.0, ...}`` lines, as PyYAML writes the waypoints list;
    None if one holds a value written differently here (then PyYAML writes them)."""
    lines = []
    for entry in waypoints:
        parts = []
        for key, value in entry.items():
            kind = type(value)
            if kind is float:
                text = _float_text(value)
            elif kind is str and _plain_text(value):
                text = value
            else:
                shown = _scalar_text(value)
                if shown is None:
                    return None
                text = shown
            parts.append(f"{key}: {text}")
        line = "  - {" + ", ".join(parts) + "}\n"
        if len(line) > _WIDTH - 100:
            return None
        lines.append(line)
    return lines


def _scalar_text(value: Any) -> str | None:
    """A scalar as PyYAML's SafeRepresenter and emitter write it in a flow mapping, or
    None when that takes PyYAML's own judgement (quoted or escaped text)."""
    kind = type(value)
    if kind is float:
        return _float_text(value)
    if kind is int:
        return str(value)
    if kind is bool:
        return "true" if value else "false"
    if value is None:
        return "null"
    if kind is str and _plain_text(value):
        return value
    return None


def _float_text(value: float) -> str:
    """SafeRepresenter.represent_float's text (plain: it always reads back as a float)."""
    text = repr(value)
    if "e" in text:
        if "." not in text:
            text = text.replace("e", ".0e", 1)
    elif text[-1] not in "0123456789":  # inf, -inf, nan
        return {"inf": ".inf", "-inf": "-.inf"}.get(text, ".nan")
    return text


@functools.lru_cache(maxsize=4096)
def _plain_text(value: str) -> bool:
    """Whether PyYAML writes ``value`` plain: nothing in it needs quoting in a flow
    collection, and no implicit resolver reads it as another type (``yes``, ``1.5``)."""
    return (
        len(value) <= 256
        and _PLAIN_TEXT.fullmatch(value) is not None
        and _RESOLVER.resolve(yaml.ScalarNode, value, (True, False)) == _STR_TAG
    )


def write_mission(mission: Mission, path: str | os.PathLike[str], overwrite: bool = False) -> None:
    """Write ``mission`` to ``path`` as navseq YAML, atomically.

    Refuses to replace an existing file unless ``overwrite`` is true. The text goes
    to a temporary file in the same folder first, so a crash leaves either the old
    file or the complete new one, never half a mission.
    """
    target = Path(path)
    source = str(target)
    if target.is_dir():
        raise NavseqError("is a folder; give the path of the mission file to write", source=source)
    if not target.parent.is_dir():
        raise NavseqError(f"the folder {target.parent} does not exist", source=source)
    if target.exists() and not overwrite:
        raise NavseqError("exists already; not overwriting it", source=source)
    text = dump_mission_yaml(mission, base_dir=target.parent.resolve())
    try:
        write_atomically(target, text, replace=overwrite)
    except FileExistsError:
        raise NavseqError("exists already; not overwriting it", source=source) from None
    except OSError as error:
        raise NavseqError(f"cannot be written: {error.strerror or error}", source=source) from None


def yaw_degrees_for_file(yaw: float) -> float | int:
    """Degrees as a person would write them (``90``, not ``89.99999999999999``).

    The shortest rounding (up to ten decimals) that converts back to exactly ``yaw``
    is used, so yaws written in degrees survive a write and a read unchanged; others
    (from quaternions or radians) are rounded to a millionth of a degree.
    """
    degrees = math.degrees(yaw)
    for decimals in range(_EXACT_YAW_DECIMALS + 1):
        candidate = round(degrees, decimals)
        if math.radians(candidate) == yaw:
            return _tidy(candidate)
    return _tidy(round(degrees, _ROUNDED_YAW_DECIMALS))


def _tidy(value: float) -> float | int:
    if value.is_integer() and abs(value) < 2**53:
        return int(value)
    return value


def robot_section(robot: RobotProfile) -> str | dict[str, Any]:
    """A profile as a ``robot:`` section (docs/mission-format.md) that reads back equal.

    A built-in profile unchanged is its name; any other is written in full (name,
    outline, every number), in the file's units: degrees for angular speeds and the
    yaw tolerance, metres and seconds otherwise.
    """
    if BUILTIN_PROFILES.get(robot.name) == robot:
        return robot.name
    to_rad = math.pi / 180.0  # robot_format's factor for deg/s and deg/s²
    return {
        "name": robot.name,
        "footprint": [_FlowList([x, y]) for x, y in robot.footprint],
        "inflation_radius": robot.inflation_radius,
        "cost_scaling_factor": robot.cost_scaling_factor,
        "clearance_margin": robot.clearance_margin_m,
        "max_linear_speed": robot.max_linear_speed,
        "max_angular_speed": _exact_degrees(robot.max_angular_speed, to_rad),
        "max_linear_accel": robot.max_linear_accel,
        "max_angular_accel": _exact_degrees(robot.max_angular_accel, to_rad),
        "xy_goal_tolerance": robot.goal_tolerance.xy_m,
        "yaw_goal_tolerance": _exact_degrees(robot.goal_tolerance.yaw_rad, to_rad),
    }


def _exact_degrees(radians: float, to_rad: float) -> float | int:
    """The shortest degrees that the reader turns back into exactly ``radians``."""
    degrees = math.degrees(radians)
    for decimals in range(16):
        candidate = round(degrees, decimals)
        if candidate * to_rad == radians:
            return _tidy(candidate)
    # No short decimal does (3.2 rad/s² is 183.346... deg/s²): a neighbouring float of
    # the quotient does, written in full.
    candidate = radians / to_rad
    for _ in range(8):
        if candidate * to_rad == radians:
            return candidate
        candidate = math.nextafter(
            candidate, math.inf if candidate * to_rad < radians else -math.inf
        )
    return _tidy(degrees)


def _map_text(map_path: Path, base_dir: Path | None) -> str:
    """Relative to the mission's folder when both live in one tree (a project, a
    package), so they can move together; absolute when they only share the root."""
    if base_dir is None or not map_path.is_absolute():
        return str(map_path)
    try:
        shared = Path(os.path.commonpath([map_path, base_dir]))
    except ValueError:  # another drive (Windows)
        return str(map_path)
    if shared == Path(shared.anchor):
        return str(map_path)
    return os.path.relpath(map_path, base_dir)


def _pose(pose: Pose2D) -> _FlowMapping:
    return _FlowMapping(x=pose.x, y=pose.y, **_yaw_entry(pose.yaw))


def _yaw_entry(yaw: float) -> dict[str, Any]:
    if not math.isfinite(math.degrees(yaw)):  # only absurd radians overflow as degrees
        return {"yaw_rad": yaw}
    return {"yaw": yaw_degrees_for_file(yaw)}


def _datum(datum: Datum) -> _FlowMapping:
    entry = _FlowMapping(latitude=datum.point.latitude, longitude=datum.point.longitude)
    if datum.point.altitude is not None:
        entry["altitude"] = datum.point.altitude
    entry.update(_yaw_entry(datum.yaw_rad))
    return entry


def _written_as_gps(waypoint: Waypoint, datum: Datum | None) -> bool:
    """True when the waypoint was read as latitude/longitude and still is where that
    puts it (a waypoint moved since, in the studio, is written as x/y)."""
    if waypoint.geo is None or datum is None:
        return False
    x, y, _ = datum.to_map(waypoint.geo)
    return abs(x - waypoint.x) < 1e-3 and abs(y - waypoint.y) < 1e-3


def _waypoint(waypoint: Waypoint, datum: Datum | None = None) -> _FlowMapping:
    entry = _FlowMapping()
    if waypoint.name is not None:
        entry["name"] = waypoint.name
    if _written_as_gps(waypoint, datum):
        assert waypoint.geo is not None
        entry["latitude"] = waypoint.geo.latitude
        entry["longitude"] = waypoint.geo.longitude
        if waypoint.geo.altitude is not None:
            entry["altitude"] = waypoint.geo.altitude
    else:
        entry["x"] = waypoint.x
        entry["y"] = waypoint.y
        if waypoint.z != 0.0:
            entry["z"] = waypoint.z
    entry.update(_yaw_entry(waypoint.yaw_rad))
    if waypoint.overrides:
        entry.update(
            _policy_values(
                Policy().with_overrides(waypoint.overrides),
                [key for key, name in POLICY_KEYS.items() if name in waypoint.overrides],
            )
        )
    if "tasks" in waypoint.overrides:
        entry["tasks"] = [task_document(t) for t in waypoint.overrides["tasks"]]
    return entry


def _policy_values(policy: Policy, keys: Any) -> dict[str, Any]:
    """The file keys ``keys`` with ``policy``'s values, in the file's units."""
    values = {key: getattr(policy, POLICY_KEYS[key]) for key in keys}
    if "recovery" in values:
        if values["recovery"]:
            values["recovery"] = recovery_document(values["recovery"])
        else:
            del values["recovery"]  # none: the key stays out of the file
    if values.get("yaw_tolerance") is not None:
        values["yaw_tolerance"] = round(math.degrees(values["yaw_tolerance"]), 6)
    return {
        key: value.value if isinstance(value, FailureAction) else value
        for key, value in values.items()
    }
