"""What the executor tells the outside world (sinks: terminal, journal, report, ROS).

Every event carries ``t``, the navigator clock time in seconds, and is a frozen
dataclass whose fields are JSON-friendly so the journal can write it as is.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class WaypointOutcome(str, enum.Enum):
    REACHED = "reached"
    SKIPPED = "skipped"  # failed, and the policy said go on
    FAILED = "failed"  # failed, and the mission stopped here
    NOT_RUN = "not_run"  # the mission ended before this waypoint was tried


@dataclass(frozen=True)
class MissionStarted:
    t: float
    waypoint_count: int
    loops: int | None
    resumed_from: int | None = None  # waypoint index when resuming a journal


@dataclass(frozen=True)
class LoopStarted:
    t: float
    loop: int  # 0-based


@dataclass(frozen=True)
class WaypointStarted:
    t: float
    index: int
    loop: int
    attempt: int  # 1-based
    goal_id: int
    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class WaypointProgress:
    t: float
    index: int
    x: float
    y: float
    yaw: float
    distance_remaining: float | None
    distance_driven: float
    # From stacks that count them (Nav2's feedback), else None: recovery behaviours run
    # for the current goal, and seconds the stack has been on it (its own clock).
    recoveries: int | None = None
    navigation_time: float | None = None


@dataclass(frozen=True)
class WaypointPlan:
    """The navigation stack's global plan for the current attempt (for pictures/markers)."""

    t: float
    index: int
    path: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class AttemptFailed:
    """One attempt at a waypoint failed; ``will_retry`` says whether another follows.

    ``reason`` is navseq's verdict: the stack's failure status (``"ABORTED"``,
    Nav2's ``"CANCELED"`` ...), ``"timeout"``, ``"stalled"``, or ``"succeeded far from
    goal (2.38 m)"`` / ``"succeeded 35° off the goal yaw"`` when the stack said
    SUCCEEDED but the robot is not there. ``status`` is the terminal status the
    navigation stack gave (None when navseq gave up on the goal itself), ``text``
    the stack's own words (move_base's result text, may be empty).
    ``duration`` (s) and ``distance_driven`` (m) are the attempt's own. Fields after
    ``will_retry`` default so that journals written before them still read.
    """

    t: float
    index: int
    attempt: int
    reason: str
    will_retry: bool
    status: str | None = None
    text: str = ""
    duration: float = 0.0
    distance_driven: float = 0.0
    loop: int = 0
    recoveries: int | None = None  # the stack's recovery count for the goal, if it gives one


@dataclass(frozen=True)
class WaypointDwelling:
    t: float
    index: int
    seconds: float


@dataclass(frozen=True)
class TaskStarted:
    """A task of the waypoint began (``task``: its 1-based number in the list)."""

    t: float
    index: int
    loop: int
    task: int
    # wait, run, input ... (not ``kind``: the journal's records have their own ``kind``)
    task_kind: str
    attempt: int  # 1-based: a failed task runs again under retries / on_failure: retry
    description: str = ""


@dataclass(frozen=True)
class TaskFinished:
    """A task ended; ``outcome`` a :class:`~navseq.tasks.base.TaskOutcome` value.

    ``will_retry``: the same task runs again. ``files``: what it wrote; ``output``: the
    last lines a ``run`` program printed.
    """

    t: float
    index: int
    loop: int
    task: int
    task_kind: str
    attempt: int
    outcome: str
    duration: float
    detail: str = ""
    files: tuple[str, ...] = ()
    output: tuple[str, ...] = ()
    will_retry: bool = False


@dataclass(frozen=True)
class RecoveryStarted:
    """A recovery of the waypoint's ``recovery:`` list began, before attempt ``attempt``
    (``recovery``: its 1-based number in the list)."""

    t: float
    index: int
    loop: int
    recovery: int
    recovery_kind: str  # spin, backup, wait, clear_costmaps
    attempt: int  # the attempt it prepares (2 for the first retry)
    amount: float | None = None  # degrees (spin), metres (backup), seconds (wait)
    description: str = ""


@dataclass(frozen=True)
class RecoveryFinished:
    """A recovery ended: ``outcome`` succeeded, failed, timed_out or cancelled. The retry
    goes ahead whatever it is (as Nav2's recovery subtree does)."""

    t: float
    index: int
    loop: int
    recovery: int
    recovery_kind: str
    attempt: int
    outcome: str
    duration: float
    detail: str = ""
    amount: float | None = None  # as in RecoveryStarted


@dataclass(frozen=True)
class WaypointFinished:
    t: float
    index: int
    loop: int
    outcome: WaypointOutcome
    attempts: int
    duration: float
    distance_driven: float
    reason: str = ""  # for skipped/failed: last failure reason
    passed_through: bool = False


@dataclass(frozen=True)
class ServerStatusChanged:
    t: float
    available: bool
    reason: str = ""


@dataclass(frozen=True)
class MissionPaused:
    """The operator paused the mission: the active goal is cancelled, the clock held.

    ``state`` is what the run was doing (``active``, ``dwelling`` ...), ``index`` the
    waypoint it was at.
    """

    t: float
    index: int
    reason: str = ""
    state: str = ""


@dataclass(frozen=True)
class MissionResumed:
    """The pause ended; every deadline of the run moved on by ``paused_for`` seconds."""

    t: float
    index: int
    paused_for: float


@dataclass(frozen=True)
class WaypointHeld:
    """The fleet holds the robot back from the waypoint's goal (it waits, or gives way
    to another robot: ``reason``). The goal's timeout and stall clocks stand still until
    :class:`WaypointReleased`: the wait is the fleet's doing, not the robot's."""

    t: float
    index: int
    loop: int
    reason: str = ""


@dataclass(frozen=True)
class WaypointReleased:
    """The hold ended (the robot is back on its way, or the attempt ended while held);
    ``held_for`` seconds were not counted against the goal's timeout and stall clocks."""

    t: float
    index: int
    loop: int
    held_for: float


@dataclass(frozen=True)
class MissionFinished:
    t: float
    success: bool  # every waypoint reached
    reason: str  # "completed", "stopped: waypoint 3 failed", "interrupted", ...


MissionEvent = (
    MissionStarted
    | LoopStarted
    | WaypointStarted
    | WaypointProgress
    | WaypointPlan
    | AttemptFailed
    | WaypointDwelling
    | TaskStarted
    | TaskFinished
    | RecoveryStarted
    | RecoveryFinished
    | WaypointFinished
    | WaypointHeld
    | WaypointReleased
    | ServerStatusChanged
    | MissionPaused
    | MissionResumed
    | MissionFinished
)
