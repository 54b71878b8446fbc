"""navseq's own YAML mission format (reference: docs/mission-format.md).

A mission document is a mapping::

    navseq: 1
    frame: map
    map: ../maps/turtlebot3_world.yaml
    start: {x: -2.0, y: -0.5, yaw: 0}
    loops: 1
    defaults: {goal_timeout: 120, retries: 1, on_failure: skip}
    waypoints:
      - {name: dock, x: 1.0, y: 2.0, yaw: 90}
      - [2.0, 0.5, 0]

This module turns such a :class:`Located` tree into a :class:`Mission`, recording
every problem it finds. The same readers serve ROS parameters (``~waypoints``).
"""

from __future__ import annotations

import difflib
import functools
import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any

from navseq.errors import NavseqError
from navseq.geometry import Pose2D, quaternion_to_yaw
from navseq.mission import (
    fields,
    recovery_format,  # noqa: F401  (registers the recovery: key)
)
from navseq.mission.costmap_filters import read_filters
from navseq.mission.geodesy import Datum, GeoPoint, check_latitude, check_longitude
from navseq.mission.located import Located, describe
from navseq.mission.model import POLICY_KEYS, Mission, Policy, Waypoint
from navseq.mission.problems import Problems, Salvage
from navseq.mission.robot_format import read_robot
from navseq.mission.task_format import read_tasks

FORMAT_VERSION = 1
FOREVER = "forever"
DEFAULT_SERVER_TIMEOUT = Mission.__dataclass_fields__["server_timeout"].default

MISSION_SETTINGS = (
    "frame",
    "map",
    "start",
    "loops",
    "server_timeout",
    "robot",
    "record",
    "datum",
    "filters",
)
OPTIONAL_SETTINGS = ("map", "start", "robot", "datum")  # null: none, like leaving the key out
TOP_LEVEL_KEYS = ("navseq", *MISSION_SETTINGS, "defaults", "waypoints")
ORIENTATION_KEYS = ("yaw", "yaw_rad", "orientation")
POSE_KEYS = ("x", "y", "z", *ORIENTATION_KEYS)
GEO_KEYS = ("latitude", "longitude", "altitude")  # a GPS waypoint, through the datum
TASKS_KEY = "tasks"  # a waypoint's (or the defaults') list, read by navseq.mission.task_format
WAYPOINT_KEYS = ("name", *POSE_KEYS, *GEO_KEYS, *POLICY_KEYS, TASKS_KEY)
DATUM_KEYS = ("latitude", "longitude", "altitude", "yaw", "yaw_rad")


class _NoDatum:
    """The datum a waypoint converts through when the mission's is faulty: its problem is
    reported once, at the datum, not again at every GPS waypoint."""


FAULTY_DATUM = _NoDatum()
DatumSetting = Datum | _NoDatum | None


def mission_from_document(
    doc: Located | None, source: str, base_dir: Path | None, problems: Problems
) -> Mission | None:
    """The Mission a navseq YAML document describes, or None when it has problems."""
    if doc is None:
        problems.add("is empty; a mission needs at least one waypoint", source=source)
        return None
    if not doc.is_mapping:
        problems.add(
            f"must be a mapping with a 'waypoints' list, got {describe(doc.value)}",
            source=doc.where,
        )
        return None
    before = len(problems)
    fields.check_keys(doc, TOP_LEVEL_KEYS, None, problems)
    version = doc.get("navseq")
    if version is not None and (isinstance(version.value, bool) or version.value != FORMAT_VERSION):
        problems.add(
            f"format version {describe(version.value)} is not supported; this navseq "
            f"reads version {FORMAT_VERSION}",
            source=version.where,
            subject="field navseq",
        )
    defaults = read_defaults(doc.get("defaults"), problems)
    datum = read_datum_setting(doc, problems)
    waypoints_node = doc.get("waypoints")
    waypoints: tuple[Waypoint, ...] = ()
    numbers: tuple[int, ...] = ()
    if waypoints_node is None:
        # A misspelt 'waypoints' key is already reported with its correction.
        if not any(difflib.get_close_matches(key, ["waypoints"], cutoff=0.6) for key in doc.value):
            problems.add(
                "has no 'waypoints' list; a mission needs at least one waypoint "
                "(or p_seq/yea_seq, the tutorial's lists)",
                source=doc.where,
            )
    else:
        waypoints, numbers = read_numbered_waypoints(waypoints_node, problems, datum)
    settings = read_settings(doc, base_dir, problems)
    if isinstance(datum, Datum):
        settings["datum"] = datum
    check_tasks_stop(waypoints, numbers, defaults, problems)
    if len(problems) > before:
        if waypoints:
            problems.salvage = Salvage(
                Mission(waypoints=waypoints, defaults=defaults, source=source, **settings), numbers
            )
        return None
    return Mission(waypoints=waypoints, defaults=defaults, source=source, **settings)


def read_defaults(node: Located | None, problems: Problems) -> Policy:
    if node is None:
        return Policy()
    if fields.attempt(problems, lambda: fields.mapping(node, "field defaults")) is None:
        return Policy()
    fields.check_keys(node, (*POLICY_KEYS, TASKS_KEY), "defaults", problems)
    values = fields.policy_values(node, "defaults", problems)
    tasks = _tasks(node, "defaults", problems)
    if tasks is not None:
        values["tasks"] = tasks
    return Policy(**values)


def _tasks(node: Located, owner: str, problems: Problems) -> tuple[Any, ...] | None:
    """The mapping's ``tasks:`` list, checked; None when absent or faulty."""
    entry = node.get(TASKS_KEY)
    return None if entry is None else read_tasks(entry, owner, problems)


def check_tasks_stop(
    waypoints: Sequence[Waypoint], numbers: Sequence[int], defaults: Policy, problems: Problems
) -> None:
    """A waypoint the robot only passes through cannot run tasks: it does not stop there.

    ``numbers``: each waypoint's index in the file, for the message.
    """
    for index, waypoint in zip(numbers, waypoints, strict=True):
        policy = defaults.with_overrides(waypoint.overrides)
        if policy.tasks and policy.pass_through_m is not None and policy.dwell_s == 0:
            problems.add(
                "has tasks but passes through (pass_through) without stopping; tasks run "
                "only where the robot stops: remove pass_through (or the tasks)",
                source=waypoint.where,
                subject=waypoint.label(index),
            )


def read_settings(node: Located, base_dir: Path | None, problems: Problems) -> dict[str, Any]:
    """The mission-wide keys other than policies: frame, map, start, loops, server_timeout,
    robot, record."""
    readers = {
        "frame": read_frame,
        "map": lambda entry, subject: read_map_path(entry, subject, base_dir),
        "start": read_start,
        "loops": read_loops,
        "server_timeout": read_server_timeout,
        "robot": read_robot,
        "record": fields.boolean,
        "filters": lambda entry, subject: read_filters(
            entry,
            subject,
            lambda node, what: read_map_path(node, what, base_dir),
            fields.number,
        ),
    }
    settings: dict[str, Any] = {}
    for key, reader in readers.items():
        entry = node.get(key)
        if entry is None:
            continue
        if entry.value is None and key in OPTIONAL_SETTINGS:
            settings[key] = None
            continue
        before = len(problems)
        value = fields.attempt(problems, functools.partial(reader, entry, f"field {key}"))
        if len(problems) == before:
            settings[key] = value
    return settings


def read_datum_setting(node: Located, problems: Problems) -> DatumSetting:
    """The mission's ``datum:`` (None when absent or null; FAULTY_DATUM, with its problem
    recorded, when it cannot be read)."""
    entry = node.get("datum")
    if entry is None or entry.value is None:
        return None
    datum = fields.attempt(problems, lambda: read_datum(entry, "field datum"))
    return FAULTY_DATUM if datum is None else datum


def read_datum(node: Located, subject: str) -> Datum:
    """navsat_transform's datum: ``{latitude, longitude, altitude, yaw}`` (degrees, metres,
    degrees counter-clockwise from east; or ``yaw_rad``), or its parameter's list
    ``[latitude, longitude, yaw_radians]``."""
    if node.is_list:
        items = node.value
        if len(items) not in (2, 3):
            raise NavseqError(
                "the list form is navsat_transform's datum parameter [latitude, longitude, "
                f"yaw_radians], got {len(items)} values",
                source=node.where,
                subject=subject,
            )
        values = [fields.number(item, subject) for item in items]
        point = _geo_point(node, subject, values[0], values[1], None)
        return Datum(point, fields.normalized_yaw(values[2]) if len(values) == 3 else 0.0)
    fields.mapping(node, subject)
    problems = Problems()
    fields.check_keys(node, DATUM_KEYS, "datum", problems)
    latitude = _required_number(node, "latitude", "datum", problems)
    longitude = _required_number(node, "longitude", "datum", problems)
    altitude = _optional_number(node, "altitude", "datum", problems, fields.coordinate)
    yaw = read_yaw(node, "datum", problems, keys=("yaw", "yaw_rad"))
    problems.raise_if_any()
    assert latitude is not None and longitude is not None and yaw is not None
    return Datum(_geo_point(node, subject, latitude, longitude, altitude), yaw)


def _geo_point(
    node: Located, subject: str, latitude: float, longitude: float, altitude: float | None
) -> GeoPoint:
    problem = check_latitude(latitude) or check_longitude(longitude)
    if problem:
        raise NavseqError(problem, source=node.where, subject=subject)
    return GeoPoint(latitude, longitude, altitude)


def read_frame(node: Located, subject: str) -> str:
    frame = fields.text(node, subject)
    if any(ch.isspace() for ch in frame):
        raise NavseqError(
            f"a frame id has no spaces, got {frame!r}", source=node.where, subject=subject
        )
    return frame


def read_map_path(node: Located, subject: str, base_dir: Path | None) -> Path:
    """A map_server YAML path; relative paths are relative to the mission file's folder."""
    return read_path(node, subject, base_dir).resolve()


def read_path(node: Located, subject: str, base_dir: Path | None) -> Path:
    """A file path as written, ``~`` expanded, anchored at ``base_dir`` when relative."""
    written = fields.text(node, subject, single_line=False)
    if "\0" in written:
        raise NavseqError(
            "a file path cannot contain a NUL character", source=node.where, subject=subject
        )
    path = Path(os.path.expanduser(written))  # unlike Path.expanduser, never raises
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    return path


def read_loops(node: Located, subject: str) -> int | None:
    """How many times the waypoint list is run; ``forever`` (None) patrols until stopped."""
    if node.value == FOREVER:
        return None
    if isinstance(node.value, str):
        raise NavseqError(
            f"must be a whole number >= 1 or '{FOREVER}', got {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
    return fields.integer(node, subject, minimum=1)


def read_server_timeout(node: Located, subject: str) -> float | None:
    if node.value is None:
        return None
    return fields.positive_seconds(node, subject)


def read_start(node: Located, subject: str) -> Pose2D:
    """The simulator's start pose: ``{x, y, yaw}`` (yaw in degrees, or yaw_rad/orientation)."""
    fields.mapping(node, subject)
    problems = Problems()
    fields.check_keys(node, ("x", "y", *ORIENTATION_KEYS), "start", problems)
    x = _required_number(node, "x", "start", problems, fields.coordinate)
    y = _required_number(node, "y", "start", problems, fields.coordinate)
    yaw = read_yaw(node, "start", problems)
    problems.raise_if_any()
    assert x is not None and y is not None and yaw is not None
    return Pose2D(x, y, yaw)


def read_waypoints(
    node: Located, problems: Problems, datum: DatumSetting = None
) -> tuple[Waypoint, ...]:
    return read_numbered_waypoints(node, problems, datum)[0]


def read_numbered_waypoints(
    node: Located,
    problems: Problems,
    datum: DatumSetting = None,
) -> tuple[tuple[Waypoint, ...], tuple[int, ...]]:
    """The waypoints that read without a problem, and their indices in the list."""
    items = fields.attempt(problems, lambda: fields.sequence(node, "field waypoints"))
    if items is None:
        return (), ()
    if not items:
        problems.add(
            "the waypoint list is empty; a mission needs at least one waypoint",
            source=node.where,
            subject="field waypoints",
        )
        return (), ()
    read = [
        (index, read_waypoint(item, index, problems, datum)) for index, item in enumerate(items)
    ]
    check_unique_names(items, problems)
    kept = [(index, waypoint) for index, waypoint in read if waypoint is not None]
    return tuple(w for _, w in kept), tuple(i for i, _ in kept)


# The keys of most waypoints: read without the problem bookkeeping (see _plain_waypoint).
_PLAIN_WAYPOINT_KEYS = frozenset(("name", "x", "y", "z", "yaw"))
_NO_OVERRIDES: Mapping[str, Any] = MappingProxyType({})


def _plain_waypoint(node: Located) -> Waypoint | None:
    """A waypoint of only name, x, y, z, yaw that reads without a problem, else None.

    The same readers as :func:`read_waypoint`, without building labels and recording
    problems for each value: a 100 000-waypoint mission spent most of its reading time
    there. Any problem (or any other key) returns None, and the general reader then
    reports it exactly as before.
    """
    values = node.value
    if type(values) is not dict or not values.keys() <= _PLAIN_WAYPOINT_KEYS:
        return None
    x, y = values.get("x"), values.get("y")
    if x is None or y is None:
        return None
    try:
        name_node = values.get("name")
        name = fields.text(name_node, "", allow_numbers=True) if name_node is not None else None
        z_node, yaw_node = values.get("z"), values.get("yaw")
        return Waypoint(
            x=fields.coordinate(x, ""),
            y=fields.coordinate(y, ""),
            z=(fields.coordinate(z_node, "") or 0.0) if z_node is not None else 0.0,
            yaw_rad=fields.yaw_degrees(yaw_node, "") if yaw_node is not None else 0.0,
            name=name,
            overrides=_NO_OVERRIDES,
            where=node.where,
        )
    except NavseqError:
        return None


def read_waypoint(
    node: Located, index: int, problems: Problems, datum: DatumSetting = None
) -> Waypoint | None:
    """One waypoint: a mapping, or the short form ``[x, y]`` / ``[x, y, yaw_degrees]``.

    A mapping may give its position as ``latitude``/``longitude`` (and ``altitude``)
    instead of ``x``/``y`` (and ``z``): converted to the map frame through ``datum``.
    """
    plain = _plain_waypoint(node)
    if plain is not None:
        return plain
    if node.is_list:
        return _waypoint_from_list(node, index, problems)
    label = f"waypoint {index + 1}"
    if not node.is_mapping:
        problems.add(
            f"must be a mapping like {{x: 1.0, y: 2.0, yaw: 90}}, got {describe(node.value)}",
            source=node.where,
            subject=label,
        )
        return None
    before = len(problems)
    name = None
    if node.get("name") is not None:
        name_node = node.value["name"]
        name = fields.attempt(
            problems, lambda: fields.text(name_node, f"{label}, field name", allow_numbers=True)
        )
        if name is not None:
            label = f"{label} '{name}'"
    fields.check_keys(node, WAYPOINT_KEYS, label, problems)
    geo: GeoPoint | None = None
    if any(node.get(key) is not None for key in GEO_KEYS):
        x, y, z, geo = _gps_position(node, label, problems, datum)
    else:
        x = _required_number(node, "x", label, problems, fields.coordinate)
        y = _required_number(node, "y", label, problems, fields.coordinate)
        z = _optional_number(node, "z", label, problems, fields.coordinate)
    yaw = read_yaw(node, label, problems)
    overrides = fields.policy_values(node, label, problems)
    tasks = _tasks(node, label, problems)
    if tasks is not None:
        overrides["tasks"] = tasks
    if len(problems) > before or x is None or y is None or yaw is None:
        return None
    return Waypoint(
        x=x,
        y=y,
        z=z or 0.0,
        yaw_rad=yaw,
        name=name,
        overrides=MappingProxyType(overrides),
        where=node.where,
        geo=geo,
    )


def _gps_position(
    node: Located, label: str, problems: Problems, datum: DatumSetting
) -> tuple[float | None, float | None, float | None, GeoPoint | None]:
    """(x, y, z, the GPS position) of a waypoint written as latitude/longitude; Nones
    with the problems recorded when it cannot be converted."""
    failed = (None, None, None, None)
    mixed = [key for key in ("x", "y", "z") if node.get(key) is not None]
    if mixed:
        problems.add(
            f"gives both {', '.join(mixed)} and latitude/longitude: write the position "
            "once, in the map frame (x, y, z) or as GPS (latitude, longitude, altitude)",
            source=node.where,
            subject=label,
        )
        return failed
    before = len(problems)
    latitude = _required_number(node, "latitude", label, problems)
    longitude = _required_number(node, "longitude", label, problems)
    altitude = _optional_number(node, "altitude", label, problems, fields.coordinate)
    for key, value, check in (
        ("latitude", latitude, check_latitude),
        ("longitude", longitude, check_longitude),
    ):
        problem = check(value) if value is not None else None
        if problem:
            problems.add(
                problem, source=node.value[key].where, subject=fields.field_subject(label, key)
            )
    if len(problems) > before or latitude is None or longitude is None:
        return failed
    if datum is None:
        problems.add(
            "is given as latitude/longitude but the mission has no datum: add "
            "datum: {latitude, longitude, yaw} (the map frame's origin, as "
            "navsat_transform's datum parameter)",
            source=node.where,
            subject=label,
        )
        return failed
    if not isinstance(datum, Datum):
        return failed  # the datum's own problem is reported
    geo = GeoPoint(latitude, longitude, altitude)
    x, y, z = datum.to_map(geo)
    if max(abs(x), abs(y)) > fields.MAX_COORDINATE:
        problems.add(
            f"is {max(abs(x), abs(y)) / 1000:.0f} km from the datum; map coordinates "
            f"are within ±{fields.MAX_COORDINATE:g} m",
            source=node.where,
            subject=label,
        )
        return failed
    return x, y, z, geo


def _waypoint_from_list(node: Located, index: int, problems: Problems) -> Waypoint | None:
    label = f"waypoint {index + 1}"
    items: Sequence[Located] = node.value
    if len(items) not in (2, 3):
        problems.add(
            f"the short form is [x, y] or [x, y, yaw_degrees], got {len(items)} values",
            source=node.where,
            subject=label,
        )
        return None
    names = ("x", "y", "yaw")
    before = len(problems)
    readers = (fields.coordinate, fields.coordinate, fields.yaw_degrees)
    values = [
        fields.attempt(problems, functools.partial(read, item, fields.field_subject(label, name)))
        for item, name, read in zip(items, names, readers, strict=False)
    ]
    if len(problems) > before:
        return None
    x, y, *rest = (v for v in values if v is not None)
    yaw = rest[0] if rest else 0.0
    return Waypoint(x=x, y=y, yaw_rad=yaw, where=node.where)


def read_yaw(
    node: Located, owner: str, problems: Problems, keys: Sequence[str] = ORIENTATION_KEYS
) -> float | None:
    """Yaw in radians from exactly one of ``yaw`` (degrees), ``yaw_rad``, ``orientation``
    (those of them in ``keys``).

    None (with a recorded problem) when the orientation is invalid; 0 when absent.
    """
    given = [key for key in keys if node.get(key) is not None]
    if len(given) > 1:
        problems.add(
            f"give only one of {', '.join(given)}",
            source=node.where,
            subject=fields.field_subject(owner, given[1]),
        )
        return None
    if not given:
        return 0.0
    key = given[0]
    entry = node.value[key]
    subject = fields.field_subject(owner, key)
    if key == "yaw":
        return fields.attempt(problems, lambda: fields.yaw_degrees(entry, subject))
    if key == "yaw_rad":
        return fields.attempt(problems, lambda: fields.yaw_radians(entry, subject))
    return fields.attempt(problems, lambda: read_quaternion_yaw(entry, subject))


def read_quaternion_yaw(node: Located, subject: str) -> float:
    """Yaw of an ``{x, y, z, w}`` quaternion; it is normalised, but must not be zero."""
    fields.mapping(node, subject)
    problems = Problems()
    fields.check_keys(node, ("x", "y", "z", "w"), subject, problems)
    parts = [_required_number(node, key, subject, problems) for key in ("x", "y", "z", "w")]
    problems.raise_if_any()
    return quaternion_yaw_checked([p for p in parts if p is not None], node.where, subject)


def quaternion_yaw_checked(parts: Sequence[float], where: str, subject: str) -> float:
    qx, qy, qz, qw = parts
    # hypot scales before squaring: components near 1e200 do not overflow to inf.
    norm = math.hypot(qx, qy, qz, qw)
    if not math.isfinite(norm):
        raise NavseqError(
            "the quaternion (x, y, z, w) is too long to normalise; write a unit quaternion",
            source=where,
            subject=subject,
        )
    if norm < 1e-9:
        raise NavseqError(
            "the quaternion (x, y, z, w) has length 0; it is no rotation",
            source=where,
            subject=subject,
        )
    return fields.normalized_yaw(quaternion_to_yaw(qx / norm, qy / norm, qz / norm, qw / norm))


def check_unique_names(items: Sequence[Located], problems: Problems) -> None:
    """Names identify waypoints in reports and on resume, so each may be used once."""
    first_use: dict[str, int] = {}
    for index, item in enumerate(items):
        name_node = item.get("name")
        if name_node is None or isinstance(name_node.value, bool | list | dict):
            continue
        name = str(name_node.value)
        if name in first_use:
            problems.add(
                f"the name '{fields.shortened(name)}' is already used by waypoint "
                f"{first_use[name] + 1}; names must be unique",
                source=name_node.where,
                subject=f"waypoint {index + 1}, field name",
            )
        else:
            first_use[name] = index


NumberReader = Callable[[Located, str], float]


def _required_number(
    node: Located, key: str, owner: str, problems: Problems, read: NumberReader = fields.number
) -> float | None:
    entry = node.get(key)
    if entry is None:
        problems.add(
            f"'{key}' is missing", source=node.where, subject=fields.field_subject(owner, key)
        )
        return None
    return fields.attempt(problems, lambda: read(entry, fields.field_subject(owner, key)))


def _optional_number(
    node: Located, key: str, owner: str, problems: Problems, read: NumberReader = fields.number
) -> float | None:
    entry = node.get(key)
    if entry is None:
        return None
    return fields.attempt(problems, lambda: read(entry, fields.field_subject(owner, key)))
