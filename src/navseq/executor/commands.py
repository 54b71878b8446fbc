"""What the executor asks the navigator to do.

The executor never calls a navigator itself: every input method of
:class:`~navseq.executor.machine.MissionExecutor` returns a list of these commands,
and the runner (or a test) applies them in order. That keeps the state machine free
of I/O, so it can be driven by hand in tests and by any navigator in production.
"""

from __future__ import annotations

from dataclasses import dataclass

from navseq.mission.recovery import Recovery
from navseq.mission.tasks import Task
from navseq.navigators.base import Goal


@dataclass(frozen=True)
class SendGoal:
    """Start pursuing ``goal``; it replaces any goal still active (no cancel needed)."""

    goal: Goal


@dataclass(frozen=True)
class CancelGoal:
    """Cancel the active goal so the robot stops."""


@dataclass(frozen=True)
class ClearCostmaps:
    """Forget transient obstacles before a retry."""


@dataclass(frozen=True)
class StartTask:
    """Start ``task`` (number ``number``, 1-based, of waypoint ``index``'s list); its end
    comes back as :class:`~navseq.tasks.base.TaskDone` with ``task_id``."""

    task_id: int
    task: Task
    index: int
    loop: int
    number: int


@dataclass(frozen=True)
class CancelTask:
    """Stop the task ``task_id`` (timeout, skip, pause, cancel); no TaskDone is expected."""

    task_id: int


@dataclass(frozen=True)
class RunRecovery:
    """Run ``recovery`` on the robot (no goal is out); its end comes back as
    :class:`~navseq.navigators.base.RecoveryDone` with ``recovery_id``."""

    recovery_id: int
    recovery: Recovery


@dataclass(frozen=True)
class CancelRecovery:
    """Stop the recovery ``recovery_id`` and the robot (timeout, pause, skip, cancel)."""

    recovery_id: int


Command = (
    SendGoal | CancelGoal | ClearCostmaps | StartTask | CancelTask | RunRecovery | CancelRecovery
)
