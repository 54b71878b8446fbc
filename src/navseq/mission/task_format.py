"""Reading a ``tasks:`` list (reference: docs/mission-format.md, "Tasks at waypoints").

Each item is a mapping with exactly one kind key (``wait``, ``run`` ...) and an
optional ``timeout`` (seconds, ``null`` for no limit)::

    tasks:
      - wait: 5
      - input: {prompt: "Load the tray, then press Enter"}
      - run: {argv: [./scan.sh, --fast]}
        timeout: 30

:data:`TASK_KINDS` maps each kind to its reader; a new kind is one reader and one
entry. Every problem is recorded with its file:line, so ``navseq validate`` lists
them all at once.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

from navseq.errors import NavseqError
from navseq.mission import fields
from navseq.mission.located import Located, describe, to_plain
from navseq.mission.problems import Problems
from navseq.mission.tasks import (
    DEFAULT_TIMEOUT_S,
    CallTask,
    InputTask,
    PublishTask,
    RunTask,
    SnapshotTask,
    Task,
    WaitForTask,
    WaitTask,
)

# ROS graph names both ROS accept: optional ``/`` or ``~/``, then tokens of letters,
# digits and underscores that do not start with a digit, separated by single slashes.
_ROS_NAME = re.compile(r"(?:/|~/)?[A-Za-z_][A-Za-z0-9_]*(?:/[A-Za-z_][A-Za-z0-9_]*)*")
# pkg/Type, or pkg/msg/Type (pkg/srv/Type for a service), as ROS 1 and ROS 2 write them.
_MESSAGE_TYPE = re.compile(r"([A-Za-z][A-Za-z0-9_]*)/(?:(msg|srv)/)?([A-Za-z][A-Za-z0-9_]*)")
# A field of a message: data, pose.position.x, ranges[0].
_FIELD_PATH = re.compile(
    r"[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9]+\])?(?:\.[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9]+\])?)*"
)
_ENV_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_RELATIONS = ("equals", "above", "below")
_TRIGGER = "std_srvs/Trigger"
_MAX_ARGV = 256


@dataclass(frozen=True)
class TaskKind:
    """One kind of task: its file key and the reader of its value.

    The reader gets the kind's value, the subject for messages and the problem list,
    and returns the task's own fields (without ``timeout_s`` and ``where``), or None
    when a problem was recorded.
    """

    name: str
    read: Callable[[Located, str, Problems], dict[str, Any] | None]
    make: Callable[..., Task]
    default_timeout_s: float | None
    write: Callable[[Any], Any]  # the task -> its value in a file (navseq convert)


def task_document(task: Task) -> dict[str, Any]:
    """One task as a ``tasks:`` item of a navseq YAML file (the reader's inverse)."""
    kind = TASK_KINDS[task.kind]
    document = {kind.name: kind.write(task)}
    if task.timeout_s != kind.default_timeout_s:
        document["timeout"] = task.timeout_s
    return document


def _write_wait_for(task: WaitForTask) -> dict[str, Any]:
    return {
        "topic": task.topic,
        "type": task.type,
        "field": task.field_path,
        task.relation: task.value,
    }


def _write_call(task: CallTask) -> dict[str, Any]:
    document: dict[str, Any] = {"service": task.service, "type": task.type}
    if task.request:
        document["request"] = dict(task.request)
    default_success = "success" if task.type == _TRIGGER else None
    if task.success_field != default_success:
        document["success_field"] = task.success_field
    return document


def _write_run(task: RunTask) -> dict[str, Any]:
    document: dict[str, Any] = {"argv": list(task.argv)}
    if task.cwd is not None:
        document["cwd"] = str(task.cwd)
    if task.env:
        document["env"] = dict(task.env)
    return document


def read_tasks(node: Located, owner: str | None, problems: Problems) -> tuple[Task, ...] | None:
    """The tasks of a ``tasks:`` list, or None when any of them has a problem."""
    subject = fields.field_subject(owner, "tasks")
    items = fields.attempt(problems, lambda: fields.sequence(node, subject))
    if items is None:
        return None
    before = len(problems)
    tasks = [
        _read_task(item, f"{owner + ', ' if owner else ''}task {n}", problems)
        for n, item in enumerate(items, 1)
    ]
    if len(problems) > before:
        return None
    return tuple(task for task in tasks if task is not None)


def _read_task(node: Located, label: str, problems: Problems) -> Task | None:
    if not node.is_mapping:
        problems.add(
            f"must be a mapping like {{wait: 5}} or {{run: {{argv: [...]}}}}, got "
            f"{describe(node.value)}",
            source=node.where,
            subject=label,
        )
        return None
    kinds = [key for key in node.value if key in TASK_KINDS]
    fields.check_keys(node, (*TASK_KINDS, "timeout"), label, problems)
    if len(kinds) != 1:
        if len(kinds) > 1:
            message = f"gives {' and '.join(kinds)}; one task per list item"
        else:
            message = "names no task kind; write one of " + ", ".join(TASK_KINDS)
        problems.add(message, source=node.where, subject=label)
        return None
    kind = TASK_KINDS[kinds[0]]
    label = f"{label} ({kind.name})"
    timeout: float | None = kind.default_timeout_s
    timeout_node = node.get("timeout")
    before = len(problems)
    if timeout_node is not None and timeout_node.value is not None:
        timeout = fields.attempt(
            problems, lambda: fields.positive_seconds(timeout_node, f"{label}, field timeout")
        )
    elif timeout_node is not None:
        timeout = None
    values = kind.read(node.value[kind.name], label, problems)
    if values is None or len(problems) > before:
        return None
    return kind.make(**values, timeout_s=timeout, where=node.where)


# --- the value readers ---------------------------------------------------------------


def _fields_of(
    node: Located,
    label: str,
    problems: Problems,
    required: Collection[str],
    optional: Collection[str] = (),
) -> Mapping[str, Located] | None:
    """The kind's mapping, its unknown and missing keys recorded; None if not a mapping."""
    if fields.attempt(problems, lambda: fields.mapping(node, label)) is None:
        return None
    fields.check_keys(node, (*required, *optional), label, problems)
    for key in required:
        if node.get(key) is None:
            problems.add(
                f"'{key}' is missing", source=node.where, subject=fields.field_subject(label, key)
            )
    return node.value


def ros_name(node: Located, subject: str) -> str:
    """A topic or service name as both ROS accept it (``/door``, ``arm/grip``, ``~/confirm``)."""
    name = fields.text(node, subject)
    if _ROS_NAME.fullmatch(name) is None or "__" in name:
        raise NavseqError(
            f"{name!r} is not a valid ROS name: letters, digits and underscores in parts "
            "separated by '/', each part starting with a letter or '_', no '__'",
            source=node.where,
            subject=subject,
        )
    return name


def message_type(node: Located, subject: str, *, service: bool = False) -> str:
    """``pkg/Type`` (``pkg/msg/Type`` or, for a service, ``pkg/srv/Type`` accepted)."""
    written = fields.text(node, subject)
    match = _MESSAGE_TYPE.fullmatch(written)
    middle = "srv" if service else "msg"
    if match is None or match.group(2) not in (None, middle):
        raise NavseqError(
            f"{written!r} is not a {'service' if service else 'message'} type; write "
            f"pkg/Type or pkg/{middle}/Type, e.g. "
            f"{'std_srvs/Trigger' if service else 'std_msgs/Bool'}",
            source=node.where,
            subject=subject,
        )
    return f"{match.group(1)}/{match.group(3)}"


def _field_path(node: Located, subject: str) -> str:
    path = fields.text(node, subject)
    if _FIELD_PATH.fullmatch(path) is None:
        raise NavseqError(
            f"{path!r} is not a message field; write its name, with dots into nested "
            "messages (pose.position.x) and [N] for a list item",
            source=node.where,
            subject=subject,
        )
    return path


def _plain_mapping(node: Located, subject: str) -> Mapping[str, Any]:
    fields.mapping(node, subject)
    return MappingProxyType(dict(to_plain(node)))


def _get(
    values: Mapping[str, Located],
    key: str,
    label: str,
    problems: Problems,
    read: Callable[[Located, str], Any],
) -> Any:
    node = values.get(key)
    if node is None:
        return None
    return fields.attempt(problems, lambda: read(node, fields.field_subject(label, key)))


def _read_wait(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    seconds = fields.attempt(
        problems,
        lambda: fields.bounded_number(
            node, label, minimum=0.0, inclusive=False, unit=" s", maximum=fields.MAX_SECONDS
        ),
    )
    return None if seconds is None else {"seconds": seconds}


def _read_wait_for(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    values = _fields_of(node, label, problems, ("topic", "type", "field"), _RELATIONS)
    if values is None:
        return None
    relations = [key for key in _RELATIONS if key in values]
    value: Any = None
    if len(relations) != 1:
        problems.add(
            "give exactly one of equals, above, below"
            + (f" (got {', '.join(relations)})" if relations else ""),
            source=node.where,
            subject=label,
        )
    else:
        relation_node = values[relations[0]]
        subject = fields.field_subject(label, relations[0])
        if relations[0] == "equals":
            value = to_plain(relation_node)
            if isinstance(value, dict | list) or value is None:
                problems.add(
                    f"must be a number, true/false or text, got {describe(value)}",
                    source=relation_node.where,
                    subject=subject,
                )
        else:
            value = fields.attempt(problems, lambda: fields.number(relation_node, subject))
    return {
        "topic": _get(values, "topic", label, problems, ros_name),
        "type": _get(values, "type", label, problems, message_type),
        "field_path": _get(values, "field", label, problems, _field_path),
        "relation": relations[0] if relations else "",
        "value": value,
    }


def _read_input(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    if node.value is None:
        return {"prompt": "confirm to go on"}
    values = _fields_of(node, label, problems, (), ("prompt",))
    if values is None:
        return None
    prompt = _get(values, "prompt", label, problems, fields.text)
    return {"prompt": prompt or "confirm to go on"}


def _read_snapshot(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    values = _fields_of(node, label, problems, ("topic", "type"))
    if values is None:
        return None
    return {
        "topic": _get(values, "topic", label, problems, ros_name),
        "type": _get(values, "type", label, problems, message_type),
    }


def _read_call(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    values = _fields_of(node, label, problems, ("service",), ("type", "request", "success_field"))
    if values is None:
        return None
    kind = _get(values, "type", label, problems, lambda n, s: message_type(n, s, service=True))
    kind = kind or _TRIGGER
    success_node = values.get("success_field")
    if success_node is None:
        success: str | None = "success" if kind == _TRIGGER else None
    elif success_node.value is None:
        success = None
    else:
        success = _get(values, "success_field", label, problems, _field_path)
    request = _get(values, "request", label, problems, _plain_mapping)
    return {
        "service": _get(values, "service", label, problems, ros_name),
        "type": kind,
        "request": request if request is not None else MappingProxyType({}),
        "success_field": success,
    }


def _read_publish(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    values = _fields_of(node, label, problems, ("topic", "type"), ("message",))
    if values is None:
        return None
    message = _get(values, "message", label, problems, _plain_mapping)
    return {
        "topic": _get(values, "topic", label, problems, ros_name),
        "type": _get(values, "type", label, problems, message_type),
        "message": message if message is not None else MappingProxyType({}),
    }


def _argv(node: Located, subject: str) -> tuple[str, ...]:
    items = fields.sequence(node, subject)
    if not items or len(items) > _MAX_ARGV:
        raise NavseqError(
            f"must list the program and its arguments (1 to {_MAX_ARGV} items), got {len(items)}",
            source=node.where,
            subject=subject,
        )
    problems = Problems()
    argv = [
        fields.attempt(
            problems,
            functools.partial(fields.text, item, subject, allow_numbers=True, single_line=False),
        )
        for item in items
    ]
    for item, text in zip(items, argv, strict=True):
        if text is not None and "\0" in text:
            problems.add(
                "an argument cannot contain a NUL character", source=item.where, subject=subject
            )
    problems.raise_if_any()
    return tuple(a for a in argv if a is not None)


def _environment(node: Located, subject: str) -> Mapping[str, str]:
    fields.mapping(node, subject)
    problems = Problems()
    env: dict[str, str] = {}
    for key, value in node.value.items():
        if _ENV_NAME.fullmatch(key) is None:
            problems.add(
                f"{key!r} is not an environment variable name",
                source=node.where_key(key),
                subject=subject,
            )
            continue
        text = fields.attempt(
            problems,
            functools.partial(
                fields.text, value, f"{subject} {key}", allow_numbers=True, single_line=False
            ),
        )
        if text is not None:
            env[key] = text
    problems.raise_if_any()
    return MappingProxyType(env)


def _cwd(node: Located, subject: str) -> Path:
    written = fields.text(node, subject, single_line=False)
    if "\0" in written:
        raise NavseqError(
            "a folder cannot contain a NUL character", source=node.where, subject=subject
        )
    return Path(written)


def _read_run(node: Located, label: str, problems: Problems) -> dict[str, Any] | None:
    values = _fields_of(node, label, problems, ("argv",), ("cwd", "env"))
    if values is None:
        return None
    env = _get(values, "env", label, problems, _environment)
    return {
        "argv": _get(values, "argv", label, problems, _argv),
        "cwd": _get(values, "cwd", label, problems, _cwd),
        "env": env if env is not None else MappingProxyType({}),
    }


#: Every task kind a mission may name, by its file key.
TASK_KINDS: Mapping[str, TaskKind] = MappingProxyType(
    {
        kind.name: kind
        for kind in (
            TaskKind("wait", _read_wait, WaitTask, None, lambda t: t.seconds),
            TaskKind("wait_for", _read_wait_for, WaitForTask, DEFAULT_TIMEOUT_S, _write_wait_for),
            TaskKind("input", _read_input, InputTask, None, lambda t: {"prompt": t.prompt}),
            TaskKind(
                "snapshot",
                _read_snapshot,
                SnapshotTask,
                DEFAULT_TIMEOUT_S,
                lambda t: {"topic": t.topic, "type": t.type},
            ),
            TaskKind("call", _read_call, CallTask, DEFAULT_TIMEOUT_S, _write_call),
            TaskKind(
                "publish",
                _read_publish,
                PublishTask,
                DEFAULT_TIMEOUT_S,
                lambda t: {"topic": t.topic, "type": t.type, "message": dict(t.message)},
            ),
            TaskKind("run", _read_run, RunTask, DEFAULT_TIMEOUT_S, _write_run),
        )
    }
)

__all__ = ["TASK_KINDS", "TaskKind", "message_type", "read_tasks", "ros_name", "task_document"]
