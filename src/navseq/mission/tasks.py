"""Tasks run at a waypoint once the robot is there: one small frozen dataclass per kind.

A waypoint's ``tasks:`` (or the mission's ``defaults: tasks:``) is a tuple of these,
run in order after the arrival and the dwell. Every kind has ``timeout_s`` (None: no
limit) and ``where`` (``file.yaml:12``, for messages). The kinds that talk to ROS say
so with ``uses_ros``: the run refuses them where they cannot run
(:mod:`navseq.tasks.permissions`). Reading them from a file is
:mod:`navseq.mission.task_format`; running them is :mod:`navseq.tasks`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, ClassVar

_NOTHING: Mapping[str, Any] = MappingProxyType({})

#: The timeout a kind gets when the file gives none (s); None: no limit. ``wait`` ends by
#: itself and ``input`` waits for a person, who may take a while; a program or a ROS
#: exchange that has not finished after a minute is stuck.
DEFAULT_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class WaitTask:
    """Wait ``seconds`` (navigator clock) at the waypoint; ``dwell`` is its shorthand."""

    seconds: float
    timeout_s: float | None = None
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "wait"
    uses_ros: ClassVar[bool] = False

    def describe(self) -> str:
        return f"wait {self.seconds:g} s"


@dataclass(frozen=True)
class WaitForTask:
    """Wait until a message on ``topic`` has ``field`` equal to, above or below a value.

    ``relation`` is ``equals``, ``above`` or ``below``; ``value`` what it compares with.
    """

    topic: str
    type: str  # pkg/Type
    field_path: str  # dotted, e.g. pose.position.x
    relation: str
    value: Any
    timeout_s: float | None = DEFAULT_TIMEOUT_S
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "wait_for"
    uses_ros: ClassVar[bool] = True

    def describe(self) -> str:
        return f"wait for {self.topic} {self.field_path} {self.relation} {self.value!r}"


@dataclass(frozen=True)
class InputTask:
    """Wait until an operator confirms (a line in the terminal, the API's ``confirm``)."""

    prompt: str
    timeout_s: float | None = None
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "input"
    uses_ros: ClassVar[bool] = False

    def describe(self) -> str:
        return f"input: {self.prompt}"


@dataclass(frozen=True)
class SnapshotTask:
    """Save the next message of ``topic`` into the run folder."""

    topic: str
    type: str
    timeout_s: float | None = DEFAULT_TIMEOUT_S
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "snapshot"
    uses_ros: ClassVar[bool] = True

    def describe(self) -> str:
        return f"snapshot of {self.topic}"


@dataclass(frozen=True)
class CallTask:
    """Call a ROS service; it succeeds when ``success_field`` of the answer is true
    (None: any answer succeeds)."""

    service: str
    type: str = "std_srvs/Trigger"
    request: Mapping[str, Any] = field(default_factory=lambda: _NOTHING)
    success_field: str | None = "success"
    timeout_s: float | None = DEFAULT_TIMEOUT_S
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "call"
    uses_ros: ClassVar[bool] = True

    def describe(self) -> str:
        return f"call {self.service}"


@dataclass(frozen=True)
class PublishTask:
    """Publish one message on ``topic``."""

    topic: str
    type: str
    message: Mapping[str, Any] = field(default_factory=lambda: _NOTHING)
    timeout_s: float | None = DEFAULT_TIMEOUT_S
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "publish"
    uses_ros: ClassVar[bool] = True

    def describe(self) -> str:
        return f"publish on {self.topic}"


@dataclass(frozen=True)
class RunTask:
    """Run a local program (never through a shell); only with ``--allow-run``.

    ``cwd`` None: the folder navseq runs in; ``env`` is added to navseq's environment.
    """

    argv: tuple[str, ...]
    cwd: Path | None = None
    env: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    timeout_s: float | None = DEFAULT_TIMEOUT_S
    where: str | None = field(default=None, compare=False)
    kind: ClassVar[str] = "run"
    uses_ros: ClassVar[bool] = False

    def describe(self) -> str:
        return "run " + " ".join(self.argv)


Task = WaitTask | WaitForTask | InputTask | SnapshotTask | CallTask | PublishTask | RunTask

__all__ = [
    "DEFAULT_TIMEOUT_S",
    "CallTask",
    "InputTask",
    "PublishTask",
    "RunTask",
    "SnapshotTask",
    "Task",
    "WaitForTask",
    "WaitTask",
]
