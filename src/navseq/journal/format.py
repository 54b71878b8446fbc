"""The journal's line format, shared by its writer and its reader.

A journal is JSON lines: a header, then one record per line (``{"kind": "event",
"type": "WaypointStarted", "t": ..., ...}`` or ``{"kind": "resumed", ...}``). Every line
ends with ``"chain"``: the first 16 hex digits of the sha256 of the previous line's
chain and this line's record, so that a line edited, removed or moved by hand breaks
the chain where it was changed (see :mod:`navseq.journal.writer`).

This module holds what both sides must agree on: the format name and version, the
chain (:func:`sealed`, :func:`unsealed`), the event types a journal may hold, and how
a record becomes an event again (:func:`event_from_record`, checked field by field, so
that a damaged or hostile line gives a :class:`NavseqError` naming it, never a crash).
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import functools
import hashlib
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any, Union, get_args, get_origin, get_type_hints

from navseq.errors import NavseqError
from navseq.executor import events as ev

JOURNAL_FORMAT = "navseq-journal"
JOURNAL_VERSION = 2
#: From this version on every line carries a chain digest.
CHAINED_SINCE = 2
CHAIN_KEY = b', "chain": "'
CHAIN_DIGITS = 16
_CHAIN_SUFFIX_LENGTH = len(CHAIN_KEY) + CHAIN_DIGITS + 2  # digits, closing quote and brace
#: The longest header line a reader accepts (it is checked before anything else is read).
MAX_HEADER_BYTES = 64 * 1024
#: The longest record line a reader accepts. A journal's longest lines are plans, which
#: navseq journals as corners (a few hundred bytes); journals of earlier versions kept
#: whole plans, tens of kilobytes at most. A longer line is no journal record, and
#: parsing it could take hundreds of megabytes: the line limit, not the journal's size,
#: is what bounds the memory a journal can take to read.
MAX_LINE_BYTES = 4 * 1024 * 1024

EVENT_TYPES: dict[str, type] = {
    cls.__name__: cls
    for cls in (
        ev.MissionStarted,
        ev.LoopStarted,
        ev.WaypointStarted,
        ev.WaypointProgress,
        ev.WaypointPlan,
        ev.AttemptFailed,
        ev.WaypointDwelling,
        ev.TaskStarted,
        ev.TaskFinished,
        ev.RecoveryStarted,
        ev.RecoveryFinished,
        ev.WaypointFinished,
        ev.WaypointHeld,
        ev.WaypointReleased,
        ev.MissionPaused,
        ev.MissionResumed,
        ev.ServerStatusChanged,
        ev.MissionFinished,
    )
}


def sealed(record: bytes, previous_chain: str) -> bytes:
    """The journal line for a JSON object: the record plus its chain digest, and a newline."""
    digest = hashlib.sha256(previous_chain.encode() + record).hexdigest()[:CHAIN_DIGITS]
    return record[:-1] + CHAIN_KEY + digest.encode() + b'"}\n'


def chain_of(line: bytes) -> str:
    """The chain digest a line written by :func:`sealed` ends with (newline stripped)."""
    return line[-CHAIN_DIGITS - 2 : -2].decode("ascii", "replace")


def unsealed(line: bytes) -> tuple[bytes, str] | None:
    """(the record as it was hashed, its chain digest), or None if the line has no chain."""
    suffix = line[-_CHAIN_SUFFIX_LENGTH:]
    if len(line) <= _CHAIN_SUFFIX_LENGTH or not (
        suffix.startswith(CHAIN_KEY) and suffix.endswith(b'"}')
    ):
        return None
    return line[:-_CHAIN_SUFFIX_LENGTH] + b"}", suffix[len(CHAIN_KEY) : -2].decode(
        "ascii", "replace"
    )


def next_chain(previous_chain: str, line: bytes) -> str | None:
    """The chain digest ``line`` must carry after ``previous_chain``, if it carries it.

    None when the line does not chain on (edited, removed or moved lines).
    """
    parts = unsealed(line)
    if parts is None:
        return None
    expected = hashlib.sha256(previous_chain.encode() + parts[0]).hexdigest()[:CHAIN_DIGITS]
    return expected if parts[1] == expected else None


def json_default(value: Any) -> Any:
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot journal a {type(value).__name__}")


def event_from_record(record: dict[str, Any], where: str) -> ev.MissionEvent | None:
    """The event a record holds; None for an event type from a newer navseq.

    Fields added to an event type later (``AttemptFailed``'s ``status``, ``text`` ...)
    default when an older journal lacks them.
    """
    cls = EVENT_TYPES.get(str(record.get("type")))
    if cls is None:
        return None
    values: dict[str, Any] = {}
    try:
        # The common field types are checked inline: a long journal has millions of
        # lines, and reading it must stay a matter of seconds. JSON gives exact types.
        for name, kind, convert in _field_specs(cls):
            if name not in record:
                continue
            value = record[name]
            if kind is float:
                if type(value) is int:
                    value = float(value)
                elif type(value) is not float:
                    raise TypeError(f"expected a float, got {value!r}")
            elif kind is not None:
                if type(value) is not kind:
                    raise TypeError(f"expected a {kind.__name__}, got {value!r}")
            else:
                value = convert(value)
            values[name] = value
        return cls(**values)
    except (TypeError, ValueError) as error:
        raise NavseqError(
            f"journal event {cls.__name__} is malformed: {error}", source=where
        ) from None


@functools.cache
def _field_specs(cls: type) -> tuple[tuple[str, type | None, Callable[[Any], Any]], ...]:
    """Each field's name, its plain type (float, int, str, bool) or None, and a checking
    converter for the others; built once per event class, not once per line."""
    hints = get_type_hints(cls)
    return tuple(
        (
            spec.name,
            hints[spec.name] if hints[spec.name] in (float, int, str, bool) else None,
            _converter(hints[spec.name]),
        )
        for spec in dataclasses.fields(cls)
    )


def _converter(hint: Any) -> Callable[[Any], Any]:
    """A function checking a JSON value against ``hint`` (rebuilding enums and tuples)."""
    origin = get_origin(hint)
    if origin in (Union, types.UnionType):
        options = get_args(hint)
        optional = type(None) in options
        if optional and len(options) == 2 and float in options:
            return _optional_float
        inner = [_converter(option) for option in options if option is not type(None)]

        def union(value: Any) -> Any:
            if value is None and optional:
                return None
            for convert in inner:
                with contextlib.suppress(TypeError, ValueError):
                    return convert(value)
            raise TypeError(f"{value!r} is not a {hint}")

        return union
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return hint
    if origin is tuple:
        items = get_args(hint)
        if len(items) == 2 and items[1] is Ellipsis:
            each = _converter(items[0])

            def sequence(value: Any) -> Any:
                if not isinstance(value, list):
                    raise TypeError(f"expected a list, got {value!r}")
                return tuple(each(item) for item in value)

            return sequence
        if items == (float, float):
            return _point
        fixed = [_converter(item) for item in items]

        def record(value: Any) -> Any:
            if not isinstance(value, list):
                raise TypeError(f"expected a list, got {value!r}")
            if len(value) != len(fixed):
                raise TypeError(f"expected {len(fixed)} items, got {len(value)}")
            return tuple(convert(item) for convert, item in zip(fixed, value, strict=True))

        return record
    if hint is float:

        def real(value: Any) -> float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"expected a float, got {value!r}")
            return float(value)

        return real
    if hint in (int, str, bool):

        def exact(value: Any) -> Any:
            if not isinstance(value, hint) or (isinstance(value, bool) and hint is not bool):
                raise TypeError(f"expected a {hint.__name__}, got {value!r}")
            return value

        return exact

    def unknown(value: Any) -> Any:
        raise TypeError(f"expected a {getattr(hint, '__name__', hint)}, got {value!r}")

    return unknown


def _optional_float(value: Any) -> float | None:
    kind = type(value)
    if kind is float or value is None:
        return value
    if kind is int:
        return float(value)
    raise TypeError(f"expected a float or null, got {value!r}")


def _point(value: Any) -> tuple[float, float]:
    """An (x, y) pair: checked inline, since plans hold thousands of them."""
    if type(value) is list and len(value) == 2:
        x, y = value
        if type(x) is float and type(y) is float:
            return x, y
        if type(x) in (int, float) and type(y) in (int, float):
            return float(x), float(y)
    raise TypeError(f"expected an [x, y] pair of numbers, got {value!r}")
