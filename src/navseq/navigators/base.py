"""The small interface every navigator (sim, ros1, later nav2) implements.

Nothing here names one stack's statuses: a goal ends :class:`GoalOutcome` SUCCEEDED,
FAILED or LOST, with the stack's own status name as detail.

A navigator pursues one goal at a time on behalf of the executor. It never decides
what to do next: it only reports what happened, as events the executor polls.
Time is the navigator's own (simulated for ``sim``, ROS time for ``ros1``), read
through :attr:`Navigator.now` and advanced with :meth:`Navigator.spin`.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from navseq.geometry import Pose2D
from navseq.mission.recovery import Recovery


class GoalOutcome(str, enum.Enum):
    """How a goal ended, in terms every navigation stack shares.

    Each navigator maps its stack's own terminal statuses onto these three and passes
    the stack's name for the status along (:attr:`GoalDone.status`), so the executor
    needs no stack's vocabulary while reports still say ``ABORTED`` or ``CANCELED``.
    """

    SUCCEEDED = "succeeded"  # the stack says the robot is there (the executor checks)
    FAILED = "failed"  # the stack gave up on the goal, refused it, or it was cancelled
    LOST = "lost"  # the stack lost track of the goal (server gone or restarted)


#: The status every navigator gives a goal the stack refused without pursuing it
#: (actionlib's and Nav2's name alike); the executor backs off longer after each in a row.
REJECTED_STATUS = "REJECTED"


@dataclass(frozen=True)
class Goal:
    """A pose to reach. ``goal_id`` is chosen by the executor and echoed in events."""

    goal_id: int
    pose: Pose2D
    z: float = 0.0
    frame: str = "map"


@dataclass(frozen=True)
class GoalAccepted:
    goal_id: int


@dataclass(frozen=True)
class GoalFeedback:
    """The robot is on its way. ``distance_remaining`` is along the plan when known.

    ``recoveries`` (how many recovery behaviours the stack ran for this goal) and
    ``navigation_time`` (seconds the stack has been on it, on its clock) are given by
    stacks that count them (Nav2's ``number_of_recoveries`` and ``navigation_time``);
    None elsewhere.
    """

    goal_id: int
    pose: Pose2D
    distance_remaining: float | None = None
    recoveries: int | None = None
    navigation_time: float | None = None


@dataclass(frozen=True)
class GoalPlan:
    """The global plan the navigation stack chose for the goal (mission frame, metres)."""

    goal_id: int
    path: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class GoalDone:
    """The goal ended: ``outcome`` for the executor, ``status`` and ``text`` for people.

    ``status`` is the stack's own name of its terminal status (actionlib's ``ABORTED``,
    ``PREEMPTED``, Nav2's ``CANCELED`` ...), kept verbatim in the journal and report;
    ``text`` the stack's own words about it (may be empty).
    """

    goal_id: int
    outcome: GoalOutcome
    status: str = ""
    text: str = ""

    @classmethod
    def succeeded(cls, goal_id: int, text: str = "", status: str = "SUCCEEDED") -> GoalDone:
        return cls(goal_id, GoalOutcome.SUCCEEDED, status, text)

    @classmethod
    def failed(cls, goal_id: int, status: str, text: str = "") -> GoalDone:
        return cls(goal_id, GoalOutcome.FAILED, status, text)

    @classmethod
    def lost(cls, goal_id: int, text: str = "", status: str = "LOST") -> GoalDone:
        return cls(goal_id, GoalOutcome.LOST, status, text)


@dataclass(frozen=True)
class ServerLost:
    """The navigation server disappeared; any active goal is as good as LOST."""

    reason: str = ""


@dataclass(frozen=True)
class ServerBack:
    """The navigation server is reachable again after :class:`ServerLost`."""


@dataclass(frozen=True)
class RecoveryDone:
    """A recovery the executor asked for (``run_recovery``) ended by itself.

    ``succeeded`` False with ``detail`` in the stack's words (``COLLISION_AHEAD``, ...).
    """

    recovery_id: int
    succeeded: bool
    detail: str = ""


@dataclass(frozen=True)
class GoalHeld:
    """The fleet holds the robot back from goal ``goal_id``: it waits, or was sent aside,
    while another robot passes (navseq's fleet coordinator, the simulator's right of way).

    The goal stays the mission's; the wait is the fleet's doing, not the robot's, so the
    executor stops the goal's timeout and stall clocks until :class:`GoalReleased`. The
    holder bounds the wait itself (the coordinator's ``hold_limit`` / ``yield_limit``,
    the rule's ``yield_limit``). ``reason`` says for whom, in people's words.
    """

    goal_id: int
    reason: str = ""


@dataclass(frozen=True)
class GoalReleased:
    """The robot is back on its way to goal ``goal_id`` after :class:`GoalHeld`."""

    goal_id: int


NavEvent = (
    GoalAccepted
    | GoalFeedback
    | GoalPlan
    | GoalDone
    | GoalHeld
    | GoalReleased
    | ServerLost
    | ServerBack
    | RecoveryDone
)


@runtime_checkable
class Navigator(Protocol):
    """What the executor needs from a navigation stack."""

    def now(self) -> float:
        """Current time in seconds on the navigator's clock."""
        ...

    def wait_for_server(self, timeout: float) -> bool:
        """Block up to ``timeout`` seconds of wall time for the server; True when it is there."""
        ...

    def send_goal(self, goal: Goal) -> None:
        """Start pursuing ``goal``; any goal still active is replaced."""
        ...

    def cancel_goal(self) -> None:
        """Cancel the active goal, if any. Safe to call at any time, also twice."""
        ...

    def clear_costmaps(self) -> None:
        """Forget transient obstacles before a retry (no-op where unsupported)."""
        ...

    def robot_pose(self) -> Pose2D | None:
        """Latest known robot pose in the mission frame, or None if unknown."""
        ...

    def odometry_pose(self) -> Pose2D | None:
        """The robot's pose in the odometry frame, or None if unknown.

        Continuous (no localisation jumps, unlike the map pose), so the executor adds
        up distance driven from it; its origin does not matter.
        """
        ...

    def poll(self) -> list[NavEvent]:
        """Events since the last call, oldest first. Never blocks."""
        ...

    def spin(self, seconds: float) -> None:
        """Let ``seconds`` of navigator time pass (simulate, or sleep on ROS time)."""
        ...

    def close(self) -> None:
        """Release resources; cancels an active goal first."""
        ...


@runtime_checkable
class RecoveryRunner(Protocol):
    """What a navigator that runs recoveries (a retry's ``recovery:`` list) adds.

    One recovery at a time, never while a goal is out; its end is reported by
    :meth:`Navigator.poll` as :class:`RecoveryDone`. Which kinds a navigator runs is
    declared by its kind (``NavigatorKind.recoveries``) and checked before the run.
    """

    def run_recovery(self, recovery_id: int, recovery: Recovery) -> None:
        """Start ``recovery``; any recovery still running is stopped first."""
        ...

    def cancel_recovery(self) -> None:
        """Stop the running recovery and the robot, if one runs (no RecoveryDone follows)."""
        ...


#: Where a navigator that can record its stack's topics (``navseq run --record-topics``,
#: an optional ``record_topics(topics, write)`` method) hands each message, as published:
#: ``write(topic, type name, full message definition, serialised bytes, time in s)``.
PublishedSink = Callable[[str, str, str, bytes, float], None]
