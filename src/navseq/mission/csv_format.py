"""Waypoints recorded as CSV, the way follow_waypoints-style recorders write them.

One pose per line: ``x,y,z,qx,qy,qz,qw`` (metres; orientation as a quaternion,
turned into a yaw). No header is needed, but one header line is tolerated, as are
blank lines and ``#`` comments. Every other line must hold exactly seven numbers.
"""

from __future__ import annotations

import csv
import functools
import math
from collections.abc import Iterator

from navseq.errors import NavseqError
from navseq.mission import fields
from navseq.mission.located import Located
from navseq.mission.model import Mission, Waypoint
from navseq.mission.navseq_format import quaternion_yaw_checked
from navseq.mission.problems import Problems

COLUMNS = ("x", "y", "z", "qx", "qy", "qz", "qw")
# An hour recorded at 25 Hz; beyond it, checking and running take minutes and gigabytes.
MAX_WAYPOINTS = 100_000


def mission_from_csv(text: str, source: str, problems: Problems) -> Mission | None:
    before = len(problems)
    waypoints: list[Waypoint] = []
    seen_data = False
    try:
        for line_number, row in _rows(text):
            cells = [cell.strip() for cell in row]
            if not any(cells) or cells[0].startswith("#"):
                continue
            if not seen_data and _looks_like_header(cells):
                seen_data = True
                continue
            seen_data = True
            if len(waypoints) >= MAX_WAYPOINTS:
                problems.add(
                    f"holds more than {MAX_WAYPOINTS:,} waypoints; navseq refuses "
                    "missions this long (thin the recorded path out)",
                    source=f"{source}:{line_number}",
                )
                return None
            waypoint = _waypoint(cells, len(waypoints), f"{source}:{line_number}", problems)
            if waypoint is not None:
                waypoints.append(waypoint)
    except csv.Error as error:
        raise NavseqError(f"is not readable as CSV: {error}", source=source) from None
    if len(problems) > before:
        return None
    if not waypoints:
        problems.add("holds no waypoints (expected lines of x,y,z,qx,qy,qz,qw)", source=source)
        return None
    return Mission(waypoints=tuple(waypoints), source=source)


def _rows(text: str) -> Iterator[tuple[int, list[str]]]:
    """(line number, cells) for every CSV record; a quoted cell may span lines."""
    reader = csv.reader(text.splitlines())
    for row in reader:
        yield reader.line_num, row


def _looks_like_header(cells: list[str]) -> bool:
    """A first line of names such as ``x,y,z,qx,qy,qz,qw`` rather than numbers."""
    return any(cell and cell[0].isalpha() and not _is_number(cell) for cell in cells)


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _waypoint(cells: list[str], index: int, where: str, problems: Problems) -> Waypoint | None:
    label = f"waypoint {index + 1}"
    if len(cells) != len(COLUMNS):
        problems.add(
            f"has {len(cells)} values, expected {len(COLUMNS)}: " + ",".join(COLUMNS),
            source=where,
            subject=label,
        )
        return None
    if not any(_is_number(cell) for cell in cells):
        shown = ",".join(cells)
        problems.add(
            f"holds no numbers ({shown[:60]!r}); only the first line may be a header",
            source=where,
            subject=label,
        )
        return None
    before = len(problems)
    values = [
        fields.attempt(problems, functools.partial(_number, cell, where, label, name))
        for cell, name in zip(cells, COLUMNS, strict=True)
    ]
    if len(problems) > before:
        return None
    x, y, z, *quaternion = (v for v in values if v is not None)
    subject = fields.field_subject(label, "orientation")
    yaw = fields.attempt(problems, lambda: quaternion_yaw_checked(quaternion, where, subject))
    if yaw is None or math.isnan(yaw):
        return None
    return Waypoint(x=x, y=y, z=z, yaw_rad=yaw, where=where)


def _number(cell: str, where: str, label: str, column: str) -> float:
    subject = fields.field_subject(label, column)
    try:
        value = float(cell)
    except ValueError:
        raise NavseqError(
            f"must be a number, got {cell[:40]!r}", source=where, subject=subject
        ) from None
    if column in ("x", "y", "z"):
        return fields.coordinate(Located(value, where), subject)
    return fields.number(Located(value, where), subject)
