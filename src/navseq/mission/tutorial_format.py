"""The tutorial's waypoint format: ``p_seq`` and ``yea_seq`` parameters.

The classic ``move_base_seq`` node reads two private parameters: ``p_seq``, a flat
list ``[x1, y1, z1, x2, y2, z2, ...]`` in metres, and ``yea_seq``, one yaw per point
in degrees. The tutorial itself crashes or silently reuses values when they do not
match; here every mismatch is an error that says both counts.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from navseq.errors import NavseqError
from navseq.mission import fields
from navseq.mission.located import Located, describe
from navseq.mission.model import Waypoint
from navseq.mission.problems import Problems
from navseq.mission.yaml_doc import parse_yaml_value

POSITIONS_KEY = "p_seq"
YAWS_KEY = "yea_seq"
_AXES = ("x", "y", "z")


def waypoints_from_sequences(
    p_seq: Located | None, yea_seq: Located | None, problems: Problems
) -> tuple[Waypoint, ...]:
    """Waypoints from the two flat lists; every problem is recorded, none raised."""
    before = len(problems)
    if p_seq is None:
        problems.add(
            f"'{YAWS_KEY}' is set but '{POSITIONS_KEY}' (the flat list x1,y1,z1,x2,...) is missing",
            source=yea_seq.where if yea_seq else None,
            subject=f"field {POSITIONS_KEY}",
        )
    if yea_seq is None:
        problems.add(
            f"'{POSITIONS_KEY}' is set but '{YAWS_KEY}' (one yaw in degrees per point) is missing",
            source=p_seq.where if p_seq else None,
            subject=f"field {YAWS_KEY}",
        )
    positions = _number_list(p_seq, POSITIONS_KEY, _position_subject, problems, fields.coordinate)
    yaws = _number_list(yea_seq, YAWS_KEY, _yaw_subject, problems, fields.yaw_degrees)
    if p_seq is not None and positions is not None:
        if not positions:
            problems.add(
                "is empty; a mission needs at least one waypoint",
                source=p_seq.where,
                subject=f"field {POSITIONS_KEY}",
            )
        elif len(positions) % 3:
            problems.add(
                f"has {len(positions)} numbers, which is not a multiple of 3 "
                "(x, y, z for each waypoint)",
                source=p_seq.where,
                subject=f"field {POSITIONS_KEY}",
            )
    if positions and yaws is not None and len(positions) % 3 == 0 and yea_seq is not None:
        points = len(positions) // 3
        if len(yaws) != points:
            problems.add(
                f"has {len(yaws)} yaw{'s' if len(yaws) != 1 else ''} but "
                f"{POSITIONS_KEY} has {points} point{'s' if points != 1 else ''}; "
                "give one yaw (degrees) per point",
                source=yea_seq.where,
                subject=f"field {YAWS_KEY}",
            )
    if len(problems) > before or not positions or yaws is None:
        return ()
    return tuple(
        Waypoint(x=x.value, y=y.value, z=z.value, yaw_rad=yaw.value, where=x.where)
        for (x, y, z), yaw in zip(_triples(positions), yaws, strict=True)
    )


def _triples(items: list[Located]) -> list[tuple[Located, Located, Located]]:
    return [(items[i], items[i + 1], items[i + 2]) for i in range(0, len(items), 3)]


def _position_subject(index: int) -> str:
    return f"waypoint {index // 3 + 1}, field {_AXES[index % 3]} ({POSITIONS_KEY} item {index + 1})"


def _yaw_subject(index: int) -> str:
    return f"waypoint {index + 1}, field yaw ({YAWS_KEY} item {index + 1})"


def _number_list(
    node: Located | None,
    key: str,
    subject_of: Callable[[int], str],
    problems: Problems,
    read: Callable[[Located, str], float],
) -> list[Located] | None:
    """The list's items, each checked by ``read``, or None when anything is wrong."""
    if node is None:
        return None
    try:
        node = _as_list(node, key)
    except NavseqError as error:
        problems.record(error)
        return None
    before = len(problems)
    checked = []
    for index, item in enumerate(node.value):
        value = fields.attempt(problems, functools.partial(read, item, subject_of(index)))
        checked.append(Located(value, item.where))
    return checked if len(problems) == before else None


def _as_list(node: Located, key: str) -> Located:
    """The list itself; text holding a YAML list (``<param value="[1, 2]"/>``) is read too."""
    if isinstance(node.value, str):
        if "$(" in node.value:
            raise NavseqError(
                f"holds a roslaunch substitution navseq left unresolved "
                f"({node.value.strip()[:40]}): navseq does not evaluate $(eval) "
                "or $(anon), finds only packages on ROS_PACKAGE_PATH, and (like "
                "roslaunch) substitutes in a <rosparam> body only with "
                'subst_value="true"; write the numbers themselves',
                source=node.where,
                subject=f"field {key}",
            )
        try:
            parsed = parse_yaml_value(node.value, node.where)
        except NavseqError:
            parsed = None
        if parsed is not None and parsed.is_list:
            return Located([Located(item.value, node.where) for item in parsed.value], node.where)
    if not node.is_list:
        raise NavseqError(
            f"must be a list of numbers, got {describe(node.value)}",
            source=node.where,
            subject=f"field {key}",
        )
    return node
