"""The outcome of a mission run, per waypoint visit, as the report and exit code see it.

The fields keep the names the journal has always used (``duration``,
``distance_driven``); the ``*_s`` / ``*_m`` / ``yaw_deg`` properties say the unit in
the name, as the report and the ``--json`` events do, and are what the public API
documents.
"""

from __future__ import annotations

import math
from collections import Counter, deque
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from navseq.executor.events import WaypointOutcome
from navseq.geometry import Pose2D


@dataclass
class AttemptResult:
    """One goal sent for a visit, and how it ended.

    ``status`` is the terminal status the navigation stack reported, in its own
    words (``SUCCEEDED``, ``ABORTED``, ``CANCELED`` ...), or None when navseq ended
    the attempt itself (timeout, stalled, skip, interrupt). ``reason`` is empty for
    the attempt that reached the waypoint, else why it failed; ``text`` is the
    stack's own result text.
    """

    number: int  # 1-based
    reached: bool = False
    status: str | None = None
    reason: str = ""
    text: str = ""
    duration: float = 0.0  # s from the goal sent to its end
    distance_driven: float = 0.0  # m
    # Recovery behaviours the stack ran for this goal (Nav2's number_of_recoveries, as
    # last reported); None where the stack does not count them.
    recoveries: int | None = None
    # s of ``duration`` the fleet held the robot back (waiting, or giving way to another
    # robot): not counted against the goal's timeout and stall clocks.
    held: float = 0.0

    @property
    def duration_s(self) -> float:
        """Seconds (navigator clock) from the goal sent to its end."""
        return self.duration

    @property
    def distance_m(self) -> float:
        """Metres driven during this attempt."""
        return self.distance_driven

    @property
    def held_s(self) -> float:
        """Seconds of the attempt the fleet held the robot back (waiting, giving way)."""
        return self.held


@dataclass
class TaskResult:
    """One run of one task at a visit (a retried task has one per run)."""

    number: int  # 1-based position in the waypoint's task list
    kind: str
    outcome: str  # a navseq.tasks.base.TaskOutcome value
    attempt: int = 1
    duration: float = 0.0  # s, navigator clock
    detail: str = ""
    files: list[str] = field(default_factory=list)
    output: list[str] = field(default_factory=list)


@dataclass
class RecoveryResult:
    """One recovery run before a retry of a visit."""

    number: int  # 1-based position in the waypoint's recovery list
    kind: str
    amount: float | None
    attempt: int  # the attempt it prepared
    outcome: str  # succeeded, failed, timed_out, cancelled
    duration: float = 0.0  # s, navigator clock
    detail: str = ""


@dataclass
class WaypointResult:
    """One visit of one waypoint (a patrol visits each waypoint once per loop)."""

    index: int  # 0-based position in the mission
    loop: int  # 0-based
    name: str | None
    x: float
    y: float
    yaw_rad: float
    outcome: WaypointOutcome = WaypointOutcome.NOT_RUN
    attempts: int = 0
    duration: float = 0.0  # s from first goal sent to reached/given up
    distance_driven: float = 0.0  # m
    reason: str = ""
    passed_through: bool = False
    attempt_results: list[AttemptResult] = field(default_factory=list)  # in order
    tasks: list[TaskResult] = field(default_factory=list)  # every task run, in order
    recoveries: list[RecoveryResult] = field(default_factory=list)  # run before retries

    @property
    def held_s(self) -> float:
        """Seconds the fleet held the robot back during this visit (waiting, giving way
        to another robot), all attempts together; part of ``duration_s``."""
        return sum(attempt.held for attempt in self.attempt_results)

    @property
    def yaw_deg(self) -> float:
        """The waypoint's heading in degrees."""
        return math.degrees(self.yaw_rad)

    @property
    def duration_s(self) -> float:
        """Seconds (navigator clock) from the first goal sent to reached / given up."""
        return self.duration

    @property
    def distance_m(self) -> float:
        """Metres driven during this visit, all attempts together."""
        return self.distance_driven

    @property
    def last_failure(self) -> AttemptResult | None:
        """The latest attempt that did not reach the waypoint, if any."""
        return next((a for a in reversed(self.attempt_results) if not a.reached), None)


@dataclass
class MissionResult:
    """A run's outcome.

    ``visits`` lists visits in full, in mission order: every visit of a small finite
    mission; of a longer run (a patrol, a huge mission) the ones a :class:`VisitLog`
    keeps. ``waypoints`` counts every visit per waypoint and ``visit_count`` is the
    number of visits in all (not run ones of a finite mission included); a result
    built by hand without them describes exactly its ``visits``.
    """

    success: bool
    reason: str
    visits: list[WaypointResult] = field(default_factory=list)
    duration: float = 0.0
    distance_driven: float = 0.0
    loops_completed: int = 0
    start_pose: Pose2D | None = None  # the robot's first known pose of the run
    waypoints: list[WaypointTotals] = field(default_factory=list)
    visit_count: int | None = None  # None: len(visits)

    @property
    def total_visits(self) -> int:
        """Visits in all, listed in full or only counted."""
        return len(self.visits) if self.visit_count is None else self.visit_count

    @property
    def omitted_visits(self) -> int:
        """Visits counted in ``waypoints`` but not listed in ``visits``."""
        return max(0, self.total_visits - len(self.visits))

    def outcome_counts(self) -> dict[WaypointOutcome, int]:
        """How many visits ended each way, over all visits (listed or only counted)."""
        if not self.waypoints:
            counts = Counter(WaypointOutcome(v.outcome) for v in self.visits)
            return {outcome: counts.get(outcome, 0) for outcome in WaypointOutcome}
        return {
            WaypointOutcome.REACHED: sum(t.reached for t in self.waypoints),
            WaypointOutcome.SKIPPED: sum(t.skipped for t in self.waypoints),
            WaypointOutcome.FAILED: sum(t.failed for t in self.waypoints),
            WaypointOutcome.NOT_RUN: sum(t.not_run for t in self.waypoints),
        }

    @property
    def duration_s(self) -> float:
        """Seconds of mission time (navigator clock; simulated time on the simulator)."""
        return self.duration

    @property
    def distance_m(self) -> float:
        """Metres driven during the whole run."""
        return self.distance_driven

    @property
    def exit_code(self) -> int:
        """0 only if every waypoint was reached, 1 otherwise."""
        return 0 if self.success else 1

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        for visit in data["visits"]:
            visit["outcome"] = WaypointOutcome(visit["outcome"]).value
        return data


#: Visits a result lists in full: the most recent ones ...
KEEP_LAST_VISITS = 1000
#: ... and, besides those, earlier visits that were not reached, up to this many.
KEEP_NOT_REACHED_VISITS = 1000


@dataclass(slots=True)
class WaypointTotals:
    """One waypoint's visits over every loop, counted (a patrol may make millions).

    ``visits`` counts the finished ones (reached, skipped or failed); ``not_run`` the
    visits a finite mission still had to make when it ended.
    """

    index: int  # 0-based position in the mission
    name: str | None
    x: float
    y: float
    yaw_rad: float
    visits: int = 0
    reached: int = 0
    skipped: int = 0
    failed: int = 0
    not_run: int = 0
    attempts: int = 0
    duration: float = 0.0  # s, summed over the visits
    distance_driven: float = 0.0  # m, summed over the visits

    def add(self, visit: WaypointResult) -> None:
        outcome = WaypointOutcome(visit.outcome)
        if outcome is WaypointOutcome.NOT_RUN:
            self.not_run += 1
            return
        self.visits += 1
        if outcome is WaypointOutcome.REACHED:
            self.reached += 1
        elif outcome is WaypointOutcome.SKIPPED:
            self.skipped += 1
        else:
            self.failed += 1
        self.attempts += visit.attempts
        self.duration += visit.duration
        self.distance_driven += visit.distance_driven


class VisitLog:
    """Every finished visit of a run, in bounded memory.

    A patrol that loops for days makes a visit every few seconds: keeping each one
    (with its attempts) grew the process and the report without bound. The log keeps
    per-waypoint totals of all visits, the last ``keep_last`` visits in full, and,
    besides those, the first ``keep_not_reached`` earlier visits that were not reached
    (the ones an operator looks into). Visits must be added in mission order.
    """

    def __init__(
        self,
        waypoints: Sequence[Any],
        loops: int | None,
        *,
        keep_last: int = KEEP_LAST_VISITS,
        keep_not_reached: int = KEEP_NOT_REACHED_VISITS,
    ):
        self._waypoints = waypoints
        self._loops = loops
        # Made on a waypoint's first visit: a log of a journal's visits is folded before
        # its mission is known, for as many waypoints as the journal claims.
        self._totals: dict[int, WaypointTotals] = {}
        self._recent: deque[WaypointResult] = deque(maxlen=max(1, keep_last))
        self._not_reached: list[WaypointResult] = []
        self._keep_not_reached = keep_not_reached
        self._keys: set[tuple[int, int]] = set()  # of the visits held in full
        self.finished = 0  # visits added
        self.reached = 0
        self.omitted = 0  # finished visits no longer held in full

    def add(self, visit: WaypointResult) -> None:
        """Count a finished visit and keep it in full for now."""
        self._total(visit.index).add(visit)
        self.finished += 1
        if visit.outcome is WaypointOutcome.REACHED:
            self.reached += 1
        recent = self._recent
        if len(recent) == recent.maxlen:
            oldest = recent.popleft()
            if (
                oldest.outcome is not WaypointOutcome.REACHED
                and len(self._not_reached) < self._keep_not_reached
            ):
                self._not_reached.append(oldest)
            else:
                self._keys.discard((oldest.loop, oldest.index))
                self.omitted += 1
        recent.append(visit)
        self._keys.add((visit.loop, visit.index))

    def _total(self, index: int) -> WaypointTotals:
        total = self._totals.get(index)
        if total is None:
            waypoint = self._waypoints[index]
            total = WaypointTotals(index, waypoint.name, waypoint.x, waypoint.y, waypoint.yaw_rad)
            self._totals[index] = total
        return total

    @property
    def waypoint_count(self) -> int:
        """How many waypoints the mission has (visits name one of them)."""
        return len(self._waypoints)

    def held(self) -> list[WaypointResult]:
        """The visits kept in full, in mission order."""
        return sorted((*self._not_reached, *self._recent), key=lambda v: (v.loop, v.index))

    def relabelled(self, waypoints: Sequence[Any], loops: int | None) -> VisitLog:
        """A copy for ``waypoints`` (as many as this log's): names and poses taken from them.

        A journal's visits are counted as the journal is read, before its mission is
        loaded; the copy describes them with the mission's waypoints, and is the log a
        resumed run goes on adding to (this one is left as it is).
        """
        if len(waypoints) != len(self._waypoints):
            raise ValueError(
                f"a log of {len(self._waypoints)} waypoints relabelled with {len(waypoints)}"
            )
        copy = VisitLog(
            waypoints,
            loops,
            keep_last=self._recent.maxlen or 1,
            keep_not_reached=self._keep_not_reached,
        )

        def named(visit: WaypointResult) -> WaypointResult:
            waypoint = waypoints[visit.index]
            return replace(
                visit,
                name=waypoint.name,
                x=waypoint.x,
                y=waypoint.y,
                yaw_rad=waypoint.yaw_rad,
                attempt_results=[replace(a) for a in visit.attempt_results],
                tasks=[replace(t) for t in visit.tasks],
            )

        for index, total in self._totals.items():
            waypoint = waypoints[index]
            copy._totals[index] = replace(
                total, name=waypoint.name, x=waypoint.x, y=waypoint.y, yaw_rad=waypoint.yaw_rad
            )
        copy._recent.extend(named(v) for v in self._recent)
        copy._not_reached = [named(v) for v in self._not_reached]
        copy._keys = set(self._keys)
        copy.finished, copy.reached, copy.omitted = self.finished, self.reached, self.omitted
        return copy

    def __contains__(self, key: tuple[int, int]) -> bool:
        """Whether the visit (loop, index) is held in full."""
        return key in self._keys

    @property
    def expected(self) -> int | None:
        """How many visits the mission makes in all; None for a patrol that loops forever."""
        return None if self._loops is None else self._loops * len(self._waypoints)

    def all_reached(self, active: WaypointResult | None = None) -> bool:
        """Every visit so far reached (and, for a finite mission, every visit made)."""
        if active is not None or self.reached != self.finished:
            return False
        expected = self.expected
        return expected is None or self.finished == expected

    def not_reached(self, active: WaypointResult | None = None) -> int:
        """Visits not reached: failed, skipped, and (finite missions) not run."""
        expected = self.expected
        missing = self.finished - self.reached
        if expected is not None:
            return missing + max(0, expected - self.finished)
        return missing + (active is not None)

    def result(
        self,
        *,
        success: bool,
        reason: str,
        duration: float,
        loops_completed: int,
        start_pose: Pose2D | None = None,
        active: WaypointResult | None = None,
    ) -> MissionResult:
        """The run so far; ``active`` is the visit under way (listed, not yet counted)."""
        held = [*self._not_reached, *self._recent]
        if active is not None:
            held.append(active)
        expected = self.expected
        if expected is not None and expected <= (self._recent.maxlen or 0):
            # A small finite mission lists every visit, the ones not run too.
            known = {(v.loop, v.index): v for v in held}
            held = [
                known.get((loop, index)) or self._not_run(loop, index)
                for loop in range(self._loops or 0)
                for index in range(len(self._waypoints))
            ]
        visits = sorted((replace(v) for v in held), key=lambda v: (v.loop, v.index))
        totals = [
            replace(self._totals[i]) if i in self._totals else self._no_visits(i)
            for i in range(len(self._waypoints))
        ]
        counted = self.finished
        if active is not None:
            totals[active.index].not_run += 1
            counted += 1
        if self._loops is not None:
            for total in totals:
                total.not_run = max(0, self._loops - total.visits)
            counted = max(counted, expected or 0)
        distance = sum(t.distance_driven for t in totals)
        if active is not None:
            distance += active.distance_driven
        return MissionResult(
            success=success,
            reason=reason,
            visits=visits,
            duration=duration,
            distance_driven=distance,
            loops_completed=loops_completed,
            start_pose=start_pose,
            waypoints=totals,
            visit_count=counted,
        )

    def _no_visits(self, index: int) -> WaypointTotals:
        waypoint = self._waypoints[index]
        return WaypointTotals(index, waypoint.name, waypoint.x, waypoint.y, waypoint.yaw_rad)

    def _not_run(self, loop: int, index: int) -> WaypointResult:
        waypoint = self._waypoints[index]
        return WaypointResult(index, loop, waypoint.name, waypoint.x, waypoint.y, waypoint.yaw_rad)
