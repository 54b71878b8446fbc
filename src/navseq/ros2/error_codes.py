"""Nav2's error codes by name, read from the nav2_msgs this process imports.

A failed Nav2 goal carries a bare number (``error_code`` 104): bt_navigator passes on
the code of the behaviour-tree node that failed, so the number belongs to another
server's action — ``FollowPath`` (the controller, 1xx), ``ComputePathToPose`` (the
planner, 2xx), ``SmoothPath`` (5xx), ... Each action's ``Result`` declares the codes of
its range as constants. The table is read from the installed ``nav2_msgs.action`` and
not copied here, because releases add actions and codes (docking, routes, the
navigators' own codes): whatever the robot's release can send, its nav2_msgs names. A
code the installed release does not declare stays a bare number.

The table builder and the renderers take plain objects, so they run (and are tested)
without ROS; only :func:`installed_table` imports nav2_msgs, on first use.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import Any, NamedTuple

# rosidl names constants in upper case; it also puts each field's default value on the
# class as ``FIELD__DEFAULT`` (DockRobot's ``NUM_RETRIES__DEFAULT``), which is no code.
_CONSTANT = re.compile(r"[A-Z][A-Z0-9_]*")
_FIELD_DEFAULT = "__DEFAULT"


class CodeName(NamedTuple):
    """Where a code is declared: ``CodeName("FollowPath", "PATIENCE_EXCEEDED")``."""

    action: str
    constant: str


#: code -> every (action, constant) declaring it, sorted. Several actions may share a
#: code (Jazzy: FollowWaypoints and FollowGPSWaypoints both declare 601).
CodeTable = Mapping[int, tuple[CodeName, ...]]


def actions_of(module: Any) -> Iterator[tuple[str, type]]:
    """The actions of a generated ``<package>.action`` module: each public attribute
    that has a ``Result`` class, with that class."""
    for name in sorted(dir(module)):
        if name.startswith("_"):
            continue
        result = getattr(getattr(module, name), "Result", None)
        if isinstance(result, type):
            yield name, result


def result_codes(result: type) -> Iterator[tuple[str, int]]:
    """The error codes a ``Result`` class declares: its upper-case int constants but
    ``NONE`` (0, success) and the fields' defaults."""
    for name in dir(result):
        if not _CONSTANT.fullmatch(name) or name.endswith(_FIELD_DEFAULT):
            continue
        value = getattr(result, name, None)
        if isinstance(value, int) and not isinstance(value, bool) and value != 0:
            yield name, value


def build_table(actions: Iterable[tuple[str, type]]) -> dict[int, tuple[CodeName, ...]]:
    """The code table of ``(action name, Result class)`` pairs."""
    table: dict[int, list[CodeName]] = {}
    for action, result in actions:
        for constant, code in result_codes(result):
            table.setdefault(code, []).append(CodeName(action, constant))
    return {code: tuple(sorted(names)) for code, names in table.items()}


@functools.cache
def installed_table() -> CodeTable:
    """The code table of the installed ``nav2_msgs`` (read once); empty without it."""
    try:
        import nav2_msgs.action
    except ImportError:
        return {}
    return build_table(actions_of(nav2_msgs.action))


def name_of(names: Sequence[CodeName]) -> str:
    """``FollowPath PATIENCE_EXCEEDED``. A shared code names every declaration, actions
    with the same constant together: ``FollowGPSWaypoints/FollowWaypoints
    TASK_EXECUTOR_FAILED``, ``DockRobot/UndockRobot DOCK_NOT_VALID or FollowObject
    FAILED_TO_DETECT_OBJECT`` — which server sent it is not in the result."""
    by_constant: dict[str, list[str]] = {}
    for action, constant in sorted(names):
        by_constant.setdefault(constant, []).append(action)
    groups = (f"{'/'.join(actions)} {constant}" for constant, actions in by_constant.items())
    return " or ".join(groups)


def describe(code: int, table: CodeTable | None = None) -> str | None:
    """The name of a Nav2 error code (``"FollowPath PATIENCE_EXCEEDED"`` for 104), from
    ``table`` or the installed nav2_msgs; None for a code it does not declare."""
    names = (installed_table() if table is None else table).get(int(code))
    return name_of(names) if names else None


def describe_result(error_code: int, error_msg: str, table: CodeTable | None = None) -> str:
    """Nav2's own words about a result, for the report: ``error_msg`` as Nav2 wrote it,
    then the code by name and number — ``Failed to make progress (FollowPath
    PATIENCE_EXCEEDED, error_code 104)``; without ``error_msg``, ``FollowPath
    PATIENCE_EXCEEDED (error_code 104)``. The number stays for codes no name covers and
    for anyone searching Nav2's sources. Empty for ``NONE`` without a message.
    """
    message = error_msg.strip()
    if not error_code:
        return message
    name = describe(error_code, table)
    if not message:
        return f"{name} (error_code {error_code})" if name else f"error_code {error_code}"
    code = f"{name}, error_code {error_code}" if name else f"error_code {error_code}"
    return f"{message} ({code})"
