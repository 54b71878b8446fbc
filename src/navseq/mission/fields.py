"""Readers that turn one :class:`Located` value into a checked Python value.

Each reader raises :class:`NavseqError` naming the place, the subject (``waypoint 3
'dock', field yaw``) and what is wrong. Callers that want every problem at once
catch the error into a :class:`Problems` list and go on with the next field.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Collection
from typing import Any, TypeVar

from navseq.errors import NavseqError
from navseq.mission.located import Located, describe
from navseq.mission.model import POLICY_KEYS, FailureAction
from navseq.mission.problems import Problems, closest_hint
from navseq.text import text_problem

T = TypeVar("T")

# What a robot can mean. Beyond these, map and controller arithmetic overflows or
# loses all precision (a yaw of 1e20 rad is no direction: the goal was never reached).
MAX_COORDINATE = 1e6  # m: 1000 km from the frame's origin
MAX_YAW_DEGREES = 3600.0  # ten turns; normalised to (-180, 180] afterwards
MAX_YAW_RADIANS = math.radians(MAX_YAW_DEGREES)
MAX_SECONDS = 1e6  # about 11.5 days for one goal, dwell or wait
MAX_METRES = MAX_COORDINATE
# Names and frames are labels: every message and progress line about a waypoint
# repeats its name, so a megabyte name would flood the terminal.
MAX_LABEL_CHARACTERS = 256


def field_subject(owner: str | None, name: str) -> str:
    """``waypoint 2, field x`` — or ``field x`` for mission-wide keys."""
    return f"{owner}, field {name}" if owner else f"field {name}"


def number(node: Located, subject: str) -> float:
    """A finite real number. Booleans and text are refused, not coerced."""
    value = node.value
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise NavseqError(
            f"must be a number, got {describe(value)}", source=node.where, subject=subject
        )
    try:
        result = float(value)
    except OverflowError:
        raise NavseqError(
            "is too large to be a coordinate or a time", source=node.where, subject=subject
        ) from None
    if not math.isfinite(result):
        raise NavseqError(
            f"must be a finite number, got {value!r}", source=node.where, subject=subject
        )
    return result


def bounded_number(
    node: Located,
    subject: str,
    *,
    minimum: float,
    inclusive: bool,
    unit: str = "",
    maximum: float | None = None,
) -> float:
    """A finite number ``>= minimum`` (or ``> minimum`` when not inclusive), ``<= maximum``."""
    result = number(node, subject)
    if result < minimum or (not inclusive and result == minimum):
        relation = ">=" if inclusive else ">"
        raise NavseqError(
            f"must be {relation} {minimum:g}{unit}, got {result:g}",
            source=node.where,
            subject=subject,
        )
    if maximum is not None and result > maximum:
        raise NavseqError(
            f"must be <= {maximum:g}{unit}, got {result:g}", source=node.where, subject=subject
        )
    return result


def within(node: Located, subject: str, *, limit: float, unit: str, what: str = "") -> float:
    """A finite number with ``|value| <= limit``."""
    result = number(node, subject)
    if abs(result) > limit:
        raise NavseqError(
            f"must be within ±{limit:g}{unit}{what}, got {result:g}",
            source=node.where,
            subject=subject,
        )
    return result


def coordinate(node: Located, subject: str) -> float:
    """A position in metres, within ±MAX_COORDINATE of the frame's origin."""
    return within(node, subject, limit=MAX_COORDINATE, unit=" m", what=" of the origin")


def yaw_degrees(node: Located, subject: str) -> float:
    """A yaw written in degrees (within ten turns), as radians in (-pi, pi]."""
    degrees = within(node, subject, limit=MAX_YAW_DEGREES, unit=" degrees")
    return normalized_yaw(math.radians(degrees))


def yaw_radians(node: Located, subject: str) -> float:
    """A yaw written in radians (within ten turns), normalised to (-pi, pi]."""
    return normalized_yaw(within(node, subject, limit=MAX_YAW_RADIANS, unit=" rad"))


def normalized_yaw(radians: float) -> float:
    """The same direction in (-pi, pi]; exact for any finite angle (math.remainder)."""
    wrapped = math.remainder(radians, math.tau)
    return math.pi if wrapped <= -math.pi else wrapped


def integer(node: Located, subject: str, *, minimum: int) -> int:
    """A whole number ``>= minimum`` (``2.0`` is accepted as 2, ``2.5`` is not)."""
    value = node.value
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise NavseqError(
            f"must be a whole number, got {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
    if value < minimum:
        raise NavseqError(f"must be >= {minimum}, got {value}", source=node.where, subject=subject)
    return value


def boolean(node: Located, subject: str) -> bool:
    if not isinstance(node.value, bool):
        raise NavseqError(
            f"must be true or false, got {describe(node.value)}", source=node.where, subject=subject
        )
    return node.value


def text(
    node: Located, subject: str, *, allow_numbers: bool = False, single_line: bool = True
) -> str:
    """Non-empty text; with ``allow_numbers`` a number is taken as its text (``name: 7``).

    Lone surrogates are refused (they cannot be printed or written as UTF-8), and with
    ``single_line`` (names, frames) control characters too: printed, they could
    retitle or clear the operator's terminal.
    """
    value = node.value
    if allow_numbers and isinstance(value, int | float) and not isinstance(value, bool):
        value = str(value)
    if not isinstance(value, str) or not value.strip():
        raise NavseqError(
            f"must be non-empty text, got {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
    problem = text_problem(value, single_line=single_line)
    if problem is not None:
        raise NavseqError(problem, source=node.where, subject=subject)
    if single_line and len(value) > MAX_LABEL_CHARACTERS:
        raise NavseqError(
            f"is {len(value):,} characters long; at most {MAX_LABEL_CHARACTERS} are allowed",
            source=node.where,
            subject=subject,
        )
    return value


def choice(node: Located, subject: str, options: Collection[str]) -> str:
    value = node.value
    if not isinstance(value, str) or value not in options:
        hint = closest_hint(value, options) if isinstance(value, str) else ""
        listed = " | ".join(options)
        raise NavseqError(
            f"must be one of {listed}, got {describe(value)}{hint}",
            source=node.where,
            subject=subject,
        )
    return value


def mapping(node: Located, subject: str) -> Located:
    if not node.is_mapping:
        raise NavseqError(
            f"must be a mapping of keys to values, got {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
    return node


def sequence(node: Located, subject: str) -> list[Located]:
    if not node.is_list:
        raise NavseqError(
            f"must be a list, got {describe(node.value)}", source=node.where, subject=subject
        )
    return node.value


def check_keys(
    node: Located, known: Collection[str], owner: str | None, problems: Problems
) -> None:
    """Report every key of a mapping that navseq does not know, with the closest known one."""
    for key in node.value:
        if key not in known:
            problems.add(
                f"unknown key{closest_hint(key, known)}",
                source=node.where_key(key),
                subject=field_subject(owner, shortened(key)),
            )


def shortened(written: str, limit: int = 60) -> str:
    """Text the user wrote, cut to a length a message can quote."""
    return written if len(written) <= limit else written[: limit - 3] + "..."


def attempt(problems: Problems, read: Callable[[], T]) -> T | None:
    """Run one reader; on a NavseqError record it and return None so parsing goes on."""
    try:
        return read()
    except NavseqError as error:
        problems.record(error)
        return None


# --- policies ------------------------------------------------------------------------


def _optional(reader: Callable[[Located, str], Any]) -> Callable[[Located, str], Any]:
    """``null`` switches the limit off; anything else goes through ``reader``."""

    def read(node: Located, subject: str) -> Any:
        return None if node.value is None else reader(node, subject)

    return read


def positive_seconds(node: Located, subject: str) -> float:
    return bounded_number(
        node, subject, minimum=0.0, inclusive=False, unit=" s", maximum=MAX_SECONDS
    )


def _positive_metres(node: Located, subject: str) -> float:
    return bounded_number(
        node, subject, minimum=0.0, inclusive=False, unit=" m", maximum=MAX_METRES
    )


def _angle_degrees_as_radians(node: Located, subject: str) -> float:
    """An angular tolerance written in degrees (like yaw), kept in radians."""
    degrees = bounded_number(node, subject, minimum=0.0, inclusive=False, unit=" degrees")
    if degrees > 180.0:
        raise NavseqError(
            f"must be <= 180 degrees, got {degrees:g}", source=node.where, subject=subject
        )
    return math.radians(degrees)


def _failure_action(node: Located, subject: str) -> FailureAction:
    return FailureAction(choice(node, subject, [a.value for a in FailureAction]))


#: Each policy key's reader. ``recovery`` is registered by
#: :mod:`navseq.mission.recovery_format`, which reads through this module's readers.
POLICY_READERS: dict[str, Callable[[Located, str], Any]] = {
    "goal_timeout": _optional(positive_seconds),
    "stall_timeout": _optional(positive_seconds),
    "retries": lambda node, subject: integer(node, subject, minimum=0),
    "clear_costmaps_on_retry": boolean,
    "on_failure": _failure_action,
    "pass_through": _optional(
        lambda node, subject: bounded_number(
            node, subject, minimum=0.0, inclusive=True, unit=" m", maximum=MAX_METRES
        )
    ),
    "dwell": lambda node, subject: bounded_number(
        node, subject, minimum=0.0, inclusive=True, unit=" s", maximum=MAX_SECONDS
    ),
    "xy_tolerance": _optional(_positive_metres),
    "yaw_tolerance": _optional(_angle_degrees_as_radians),
}


def policy_values(node: Located, owner: str | None, problems: Problems) -> dict[str, Any]:
    """The policy keys present in a mapping, checked, by :class:`Policy` field name.

    The file says ``goal_timeout: 30`` and ``yaw_tolerance: 10`` (degrees); the result
    is ``{"goal_timeout_s": 30.0, "yaw_tolerance_rad": 0.1745...}`` (``POLICY_KEYS``).
    Other keys are left to the caller.
    """
    values: dict[str, Any] = {}
    for key, reader in POLICY_READERS.items():
        entry = node.get(key)
        if entry is None:
            continue
        before = len(problems)
        value = attempt(problems, functools.partial(reader, entry, field_subject(owner, key)))
        if len(problems) == before:
            values[POLICY_KEYS[key]] = value
    return values
