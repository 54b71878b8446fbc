"""A message's field by its path, and ``wait_for``'s condition: alike on both ROS.

ROS 1 and ROS 2 messages are Python objects whose fields are attributes; arrays are
sequences (``bytes``, ``list``, ``array.array``, numpy arrays). A path is the mission's
``pose.position.x`` or ``ranges[0]`` (checked by :mod:`navseq.mission.task_format`).
"""

from __future__ import annotations

import math
import re
from typing import Any

_STEP = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)(?:\[([0-9]+)\])?")


class FieldMissing(LookupError):
    """The path does not lead to a field of the message (the message says which)."""


def field_value(message: Any, path: str) -> Any:
    """The value at ``path`` in ``message``; FieldMissing names the step that failed."""
    value = message
    walked = ""
    for step in path.split("."):
        match = _STEP.fullmatch(step)
        if match is None:
            raise FieldMissing(f"{path!r} is not a field path")
        name, index = match.group(1), match.group(2)
        slots = _field_names(value)
        if name not in slots:
            where = f"{walked} " if walked else ""
            known = ", ".join(slots) if slots else "none"
            raise FieldMissing(f"the message {where}has no field {name!r} (fields: {known})")
        value = getattr(value, name)
        walked = f"{walked}.{name}" if walked else name
        if index is not None:
            try:
                value = value[int(index)]
            except (IndexError, TypeError):
                raise FieldMissing(f"{walked} has no item [{index}]") from None
            walked += f"[{index}]"
    return value


def _field_names(value: Any) -> list[str]:
    """The message's field names: ``__slots__`` on both ROS (ROS 2 prefixes them ``_``)."""
    names = getattr(value, "get_fields_and_field_types", None)
    if names is not None:  # ROS 2
        return list(names())
    slots = getattr(value, "__slots__", None)
    if slots is None:
        return []
    return [slot for slot in slots if not slot.startswith("_")]


def condition_met(value: Any, relation: str, expected: Any) -> bool:
    """Whether ``value`` (a message field) is ``relation`` (equals, above, below) to
    ``expected`` (a number, true/false or text from the mission)."""
    if relation == "equals":
        return _equal(value, expected)
    number = _number(value)
    if number is None:
        return False
    if relation == "above":
        return number > float(expected)
    if relation == "below":
        return number < float(expected)
    raise ValueError(f"unknown relation {relation!r}")


def _equal(value: Any, expected: Any) -> bool:
    if isinstance(expected, bool):
        return isinstance(_plain(value), bool | int) and bool(_plain(value)) is expected
    if isinstance(expected, int | float):
        number = _number(value)
        return number is not None and math.isclose(number, float(expected), abs_tol=1e-9)
    return _text(value) == str(expected)


def _plain(value: Any) -> Any:
    """A numpy scalar as the Python value it holds."""
    item = getattr(value, "item", None)
    return item() if callable(item) and not isinstance(value, bytes | str) else value


def _number(value: Any) -> float | None:
    value = _plain(value)
    if isinstance(value, bool | int | float):
        return float(value)
    return None


def _text(value: Any) -> str:
    value = _plain(value)
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return str(value)


def shown(value: Any) -> str:
    """A field's value for a report line, cut short."""
    text = repr(_plain(value))
    return text if len(text) <= 60 else text[:57] + "..."


__all__ = ["FieldMissing", "condition_met", "field_value", "shown"]
