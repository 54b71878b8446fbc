"""One pass at one waypoint, as the result records it, and which pass follows it.

A patrol visits each waypoint once per loop. A :class:`Visit` keeps the waypoint's
:class:`~navseq.executor.result.WaypointResult` up to date as attempts start and end;
the executor decides when they do.
"""

from __future__ import annotations

from dataclasses import dataclass

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import AttemptResult, WaypointResult
from navseq.mission.model import Mission, Policy, Waypoint


@dataclass
class Visit:
    """One pass at one waypoint: its policy, its result so far, the current attempt's start."""

    loop: int
    index: int
    waypoint: Waypoint
    policy: Policy
    result: WaypointResult
    is_last: bool  # the mission's last visit: the robot stops there whatever the policy
    first_sent_at: float | None = None
    reached_at: float | None = None
    attempt_sent_at: float = 0.0  # when the current attempt's goal was first sent
    attempt_start_distance: float = 0.0  # the visit's distance driven at that moment
    # The stack's count of recovery behaviours for the current attempt's goal, when the
    # stack gives one (Nav2's number_of_recoveries); None: not known.
    attempt_recoveries: int | None = None
    attempt_held: float = 0.0  # s the fleet held the robot back during the current attempt
    # The waypoint's tasks: the 0-based position of the one to run next (tasks before it
    # have succeeded), and which run of it this is (1 + its failures so far).
    next_task: int = 0
    task_attempt: int = 1
    # The policy's recoveries before the next attempt: the 0-based position of the one to
    # run next; None when none is due.
    next_recovery: int | None = None
    # Attempts the stack rejected since the last attempt that ended otherwise: the
    # back-off before a retry grows with it (navseq.executor.backoff).
    rejections_in_row: int = 0

    @classmethod
    def of(cls, mission: Mission, loop: int, index: int) -> Visit:
        waypoint = mission.waypoints[index]
        result = WaypointResult(
            index=index,
            loop=loop,
            name=waypoint.name,
            x=waypoint.x,
            y=waypoint.y,
            yaw_rad=waypoint.yaw_rad,
        )
        last = is_last_visit(mission, loop, index)
        return cls(loop, index, waypoint, mission.policy_for(index), result, last)

    @property
    def passes_through(self) -> bool:
        """Whether the visit ends when the robot comes near, without stopping there."""
        policy = self.policy
        return (
            policy.pass_through_m is not None
            and policy.dwell_s == 0
            and not policy.tasks
            and not self.is_last
        )

    def start_attempt(self, now: float) -> None:
        self.result.attempts += 1
        self.attempt_sent_at = now
        self.attempt_start_distance = self.result.distance_driven
        self.attempt_recoveries = None
        self.attempt_held = 0.0

    def goal_sent(self, now: float) -> None:
        if self.first_sent_at is None:
            self.first_sent_at = now

    def close_attempt(
        self, now: float, *, reached: bool, status: str | None, reason: str, text: str = ""
    ) -> AttemptResult:
        """Record how the current attempt ended."""
        record = AttemptResult(
            number=self.result.attempts,
            reached=reached,
            status=status,
            reason=reason,
            text=text,
            duration=max(0.0, now - self.attempt_sent_at),
            distance_driven=self.result.distance_driven - self.attempt_start_distance,
            recoveries=self.attempt_recoveries,
            held=self.attempt_held,
        )
        self.result.attempt_results.append(record)
        return record

    def finish(
        self, now: float, outcome: WaypointOutcome, reason: str, *, passed_through: bool
    ) -> WaypointResult:
        """Record how the visit ended; an attempt still open ends with it."""
        result = self.result
        if outcome is not WaypointOutcome.REACHED and len(result.attempt_results) < result.attempts:
            # Ended by navseq while a goal was out (interrupt, operator skip, server gone).
            self.close_attempt(now, reached=False, status=None, reason=reason)
        end = self.reached_at if outcome is WaypointOutcome.REACHED else now
        start = self.first_sent_at
        result.outcome = outcome
        result.reason = reason
        result.passed_through = passed_through
        # max: a clock that jumped back (a restarted simulator) must not give a negative time
        result.duration = max(0.0, end - start) if (start is not None and end is not None) else 0.0
        return result


def is_last_visit(mission: Mission, loop: int, index: int) -> bool:
    loops = mission.loops
    return loops is not None and loop == loops - 1 and index == len(mission) - 1


def next_position(mission: Mission, loop: int, index: int) -> tuple[int, int] | None:
    """The (loop, index) of the visit after this one; None after the mission's last."""
    if index + 1 < len(mission):
        return loop, index + 1
    if mission.loops is None or loop + 1 < mission.loops:
        return loop + 1, 0
    return None


__all__ = ["Visit", "is_last_visit", "next_position"]
