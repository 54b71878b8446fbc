"""Values that remember where the user wrote them.

Every source format (YAML file, launch file, ROS parameters) is first turned into a
tree of :class:`Located` values: plain Python data plus, for every node, a place to
name in messages (``mission.yaml:12`` or ``param ~waypoints``). The format-specific
code only builds these trees; one set of field readers turns them into a Mission.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from navseq.errors import NavseqError

# ROS parameter trees and launch files are shallow; anything deeper is a mistake or an attack.
MAX_DEPTH = 64


_NO_KEYS: Mapping[str, str] = MappingProxyType({})


class Located:
    """One value of a parsed document and where it came from.

    ``value`` is a scalar (None, bool, int, float, str), a ``list[Located]`` or a
    ``dict[str, Located]``. For mappings ``key_where`` gives the place of each key,
    which is where an unknown key is reported.

    A plain class with slots, not a dataclass: a 100 000-waypoint mission makes half
    a million of these, and a frozen dataclass's ``__init__`` cost a second of it.
    Treat instances as immutable.
    """

    __slots__ = ("key_where", "value", "where")

    def __init__(self, value: Any, where: str, key_where: Mapping[str, str] = _NO_KEYS):
        self.value = value
        self.where = where
        self.key_where = key_where

    def __repr__(self) -> str:
        return f"Located({self.value!r}, {self.where!r})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Located):
            return NotImplemented
        return (self.value, self.where, dict(self.key_where)) == (
            other.value,
            other.where,
            dict(other.key_where),
        )

    __hash__ = None  # type: ignore[assignment]  # mutable contents (lists, dicts)

    @property
    def is_mapping(self) -> bool:
        return isinstance(self.value, dict)

    @property
    def is_list(self) -> bool:
        return isinstance(self.value, list)

    def get(self, key: str) -> Located | None:
        """The entry ``key`` of a mapping (None when absent or when this is no mapping)."""
        value = self.value
        return value.get(key) if type(value) is dict else None

    def where_key(self, key: str) -> str:
        return self.key_where.get(key, self.where)


def from_plain(data: Any, where: str, _depth: int = 0) -> Located:
    """Wrap plain data (e.g. a ROS parameter dict) whose parts all share one place."""
    if _depth > MAX_DEPTH:
        raise NavseqError(f"nested more than {MAX_DEPTH} levels deep", source=where)
    if isinstance(data, Mapping):
        return Located({str(k): from_plain(v, where, _depth + 1) for k, v in data.items()}, where)
    if isinstance(data, list | tuple):
        return Located([from_plain(v, where, _depth + 1) for v in data], where)
    return Located(data, where)


def to_plain(node: Located | None) -> Any:
    """The plain data a Located tree holds (dicts, lists, scalars), places dropped."""
    if node is None:
        return None
    value = node.value
    if isinstance(value, dict):
        return {key: to_plain(item) for key, item in value.items()}
    if isinstance(value, list):
        return [to_plain(item) for item in value]
    return value


def describe(value: Any) -> str:
    """How a wrong value is shown in a message: ``text 'abc'``, ``a list``, ``null``."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        shown = value if len(value) <= 40 else value[:37] + "..."
        return f"text {shown!r}"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, Located):
        return describe(value.value)
    return repr(value)
