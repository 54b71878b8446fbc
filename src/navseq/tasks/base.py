"""What a task runner tells the executor: a task's end, in neutral words.

A task runner (:mod:`navseq.tasks.runner`) does what a ``StartTask`` command asks and
reports back a :class:`TaskDone`; the executor alone decides what follows (timeouts,
retries, the waypoint's ``on_failure``), as it does for a navigator's ``GoalDone``.
No I/O here: the executor imports this module.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class TaskOutcome(str, enum.Enum):
    """How one run of a task ended."""

    SUCCEEDED = "succeeded"
    FAILED = "failed"  # the runner says so: exit status, refused, no operator ...
    TIMED_OUT = "timed_out"  # the executor gave up on it after its timeout
    CANCELLED = "cancelled"  # the operator skipped, paused or cancelled, or the run ended


@dataclass(frozen=True)
class TaskDone:
    """The task ``task_id`` (the ``StartTask``'s) ended by itself.

    ``detail`` says how in a few words (``exit status 1``); ``files`` are the paths it
    wrote; ``output`` the last lines a program printed.
    """

    task_id: int
    succeeded: bool
    detail: str = ""
    files: tuple[str, ...] = ()
    output: tuple[str, ...] = ()


__all__ = ["TaskDone", "TaskOutcome"]
