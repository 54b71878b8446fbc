"""What a journal says about a run, folded as it is read, in bounded memory.

:func:`read_journal` streams the journal (:class:`~navseq.journal.reader.
JournalReader`) and keeps only what a resume, a rebuilt report and a rebuilt picture
need, however long the run:

- the visits, as the run itself keeps them: a :class:`~navseq.executor.result.VisitLog`
  (every visit counted per waypoint, the latest kept in full), plus the visit a run
  segment ended in without finishing it (it is run again on resume);
- where to resume (the first visit, in mission order, not reached or skipped: visits
  finish in mission order, so this is a frontier that only moves forward);
- the mission time the segments took, how the last one ended, the run options;
- the driven path and the legs planned, in a :class:`~navseq.sinks.recorder.
  RunRecorder` (bounded: an evenly thinned track, the latest legs).

A week-long patrol's journal is read in one pass at constant memory.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple, overload

from navseq.errors import NavseqError
from navseq.executor import events as ev
from navseq.executor.result import (
    AttemptResult,
    RecoveryResult,
    TaskResult,
    VisitLog,
    WaypointResult,
)
from navseq.executor.resume import ResumePoint
from navseq.journal.reader import Damaged, Entry, Event, JournalHeader, JournalReader, Resumed
from navseq.sinks.recorder import RunRecorder
from navseq.tasks.base import TaskOutcome

#: The most waypoints a journaled mission may claim: a visit log for that many is
#: built as the journal is read. Far above what a mission file can hold (a 10 MiB
#: file, 1 000 000 YAML values).
MAX_JOURNAL_WAYPOINTS = 1_000_000
#: Damaged lines listed by line number (a crash leaves one per run segment).
MAX_DAMAGED_LISTED = 100
_DONE_OUTCOMES = (ev.WaypointOutcome.REACHED, ev.WaypointOutcome.SKIPPED)


class NothingToResume(NavseqError):
    """The journal records every visit of the mission as finished.

    ``state`` is the journal read, for a caller that goes on to rebuild the outputs.
    """

    state: JournalState | None = None


class _Unnamed(NamedTuple):
    """A waypoint as a journal knows it: by its position in the mission only."""

    name: str | None
    x: float
    y: float
    yaw_rad: float


_UNNAMED = _Unnamed(None, 0.0, 0.0, 0.0)


class _UnnamedWaypoints(Sequence[_Unnamed]):
    """``count`` waypoints without names or poses (the mission is loaded later)."""

    def __init__(self, count: int):
        self._count = count

    def __len__(self) -> int:
        return self._count

    @overload
    def __getitem__(self, index: int) -> _Unnamed: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[_Unnamed]: ...

    def __getitem__(self, index: int | slice) -> _Unnamed | Sequence[_Unnamed]:
        if isinstance(index, slice):
            return [_UNNAMED] * len(range(*index.indices(self._count)))
        if not -self._count <= index < self._count:
            raise IndexError(index)
        return _UNNAMED


@dataclass
class _VisitTrail:
    """What a segment's events said about the visit being driven, attempt by attempt."""

    key: tuple[int, int]
    sent_at: dict[int, float] = field(default_factory=dict)  # attempt number -> first send
    failures: dict[int, AttemptResult] = field(default_factory=dict)
    # The stack's recovery count last journaled for the latest attempt (the journal
    # keeps every progress event whose count changed).
    recoveries: int | None = None
    # The recoveries run before its retries (RecoveryFinished), in order.
    recovery_runs: list[RecoveryResult] = field(default_factory=list)
    # Seconds the fleet held the robot back, per attempt number (WaypointReleased).
    held: dict[int, float] = field(default_factory=dict)


@dataclass
class VisitHistory:
    """The journal's visits, folded: bounded however many there were.

    ``log`` counts the visits finished for good (reached or skipped), in mission order;
    ``frontier`` is the first visit not finished for good (where a resume starts);
    ``unfinished`` is how the last segment left the frontier visit, if it ended it
    (failed, interrupted): listed in a rebuilt report, run again by a resume.
    """

    log: VisitLog | None = None  # made at the first MissionStarted (it says how many)
    frontier: tuple[int, int] = (0, 0)
    unfinished: WaypointResult | None = None
    _trail: _VisitTrail | None = None
    # The task runs of the latest visit that ran tasks, over every segment (a resume
    # does not run the ones that succeeded again), and which visit that is.
    _task_visit: tuple[int, int] | None = None
    _task_runs: list[TaskResult] = field(default_factory=list)

    @property
    def waypoint_count(self) -> int | None:
        return None if self.log is None else self.log.waypoint_count

    def held(self) -> list[WaypointResult]:
        """The visits known in full (the latest ones and the unfinished one), in order."""
        held = [] if self.log is None else self.log.held()
        return held + ([self.unfinished] if self.unfinished is not None else [])

    def log_for(self, waypoints: Sequence[Any], loops: int | None, *, unfinished: bool) -> VisitLog:
        """A new visit log for the mission's ``waypoints`` holding the journal's visits.

        ``unfinished`` adds the visit the journal left unfinished (a rebuilt report
        lists it; a resumed run drives it again instead).
        """
        if self.log is None:
            log = VisitLog(waypoints, loops)
        else:
            log = self.log.relabelled(waypoints, loops)
        visit = self.unfinished
        if unfinished and visit is not None and visit.outcome is not ev.WaypointOutcome.NOT_RUN:
            log.add(_with_pose(visit, waypoints[visit.index]))
        return log

    def loops_completed(self, loops: int | None) -> int:
        """Loops whose every visit finished (the last one may have failed)."""
        count = self.waypoint_count or 0
        completed = self.frontier[0]
        if self.unfinished is not None and self.unfinished.index == count - 1:
            completed += 1
        return completed if loops is None else min(completed, loops)

    def start_mission(self, event: ev.MissionStarted, where: str) -> None:
        self._trail = None  # a new segment: its clock starts afresh
        if self.log is not None:
            return
        count = event.waypoint_count
        if not 0 < count <= MAX_JOURNAL_WAYPOINTS:
            raise NavseqError(
                f"the journal's mission has {count} waypoints; navseq reads journals of "
                f"missions of 1 to {MAX_JOURNAL_WAYPOINTS:,} waypoints. The journal is "
                "damaged or is not a navseq journal",
                source=where,
            )
        self.log = VisitLog(_UnnamedWaypoints(count), event.loops)

    def start_visit(self, event: ev.WaypointStarted) -> None:
        key = (event.loop, event.index)
        trail = self._trail
        if trail is None or trail.key != key:
            trail = self._trail = _VisitTrail(key)
        trail.sent_at.setdefault(event.attempt, event.t)
        trail.recoveries = None

    def see_progress(self, event: ev.WaypointProgress) -> None:
        if self._trail is not None and event.recoveries is not None:
            self._trail.recoveries = event.recoveries

    def finish_task(self, event: ev.TaskFinished) -> None:
        key = (event.loop, event.index)
        if key != self._task_visit:
            self._task_visit, self._task_runs = key, []
        self._task_runs.append(_task_of(event))

    def tasks_of(self, key: tuple[int, int]) -> list[TaskResult]:
        """Every task run the journal records for visit ``key``, in order."""
        return list(self._task_runs) if key == self._task_visit else []

    def tasks_done_at(self, key: tuple[int, int]) -> int:
        """How many tasks of visit ``key`` succeeded: they run in order, so the highest
        number that succeeded (0 when none)."""
        succeeded = TaskOutcome.SUCCEEDED.value
        return max((t.number for t in self.tasks_of(key) if t.outcome == succeeded), default=0)

    def finish_recovery(self, event: ev.RecoveryFinished) -> None:
        trail = self._trail
        if trail is not None and trail.key == (event.loop, event.index):
            trail.recovery_runs.append(
                RecoveryResult(
                    number=event.recovery,
                    kind=event.recovery_kind,
                    amount=event.amount,
                    attempt=event.attempt,
                    outcome=event.outcome,
                    duration=event.duration,
                    detail=event.detail,
                )
            )

    def release(self, event: ev.WaypointReleased) -> None:
        """A hold of the fleet's ended: its time goes to the attempt last started."""
        trail = self._trail
        if trail is not None and trail.key == (event.loop, event.index) and trail.sent_at:
            attempt = max(trail.sent_at)
            trail.held[attempt] = trail.held.get(attempt, 0.0) + max(0.0, event.held_for)

    def fail_attempt(self, event: ev.AttemptFailed) -> None:
        # The visit is the one last started: older journals name no loop here.
        if self._trail is not None:
            attempt = _attempt_of(event)
            attempt.held = self._trail.held.get(event.attempt, 0.0)
            self._trail.failures[event.attempt] = attempt

    def finish_visit(self, event: ev.WaypointFinished, where: str) -> None:
        key = (event.loop, event.index)
        log = self.log
        if log is None:
            raise NavseqError(
                "a waypoint finished before the mission started; the journal is damaged",
                source=where,
            )
        count = log.waypoint_count
        if not 0 <= event.index < count or event.loop < 0:
            raise NavseqError(
                f"the journal records waypoint {event.index + 1} of loop {event.loop + 1}, "
                f"but its mission has {count} waypoint(s); the journal is damaged",
                source=where,
            )
        if key < self.frontier:
            return  # finished for good before: never run again, counted once
        if key > self.frontier:
            loop, index = self.frontier
            raise NavseqError(
                f"the journal records waypoint {event.index + 1} of loop {event.loop + 1} "
                f"finished while waypoint {index + 1} of loop {loop + 1} was not: a run "
                "visits waypoints in mission order, so the journal is damaged",
                source=where,
            )
        trail = self._trail if self._trail is not None and self._trail.key == key else None
        visit = _visit_of(event, trail, self.tasks_of(key))
        if event.outcome not in _DONE_OUTCOMES:
            self.unfinished = visit  # run again on resume, unless a later segment did
            return
        self.unfinished = None
        log.add(visit)
        loop, index = key
        self.frontier = (loop, index + 1) if index + 1 < count else (loop + 1, 0)


@dataclass
class JournalState:
    """What a journal says about a mission run (all segments, if it was resumed)."""

    path: Path
    version: int
    mission_source: str
    mission_digest: str
    started: str
    run_options: dict[str, Any] = field(default_factory=dict)  # the header's "run"
    mission_started: ev.MissionStarted | None = None  # the first segment's
    segments: int = 1  # 1 + number of resumed records
    damaged_lines: list[int] = field(default_factory=list)  # tolerated cut lines (the first)
    damaged_count: int = 0  # tolerated cut lines in all
    visits: VisitHistory = field(default_factory=VisitHistory)
    previous_duration: float = 0.0  # mission time covered by all segments (s)
    finish_reason: str | None = None  # of the last segment, if it finished
    chain: str = ""  # digest of the last intact line: a resumed run chains on from it
    size: int = 0  # bytes read: a resume appends only to the journal it read
    event_count: int = 0  # events read
    recorder: RunRecorder = field(default_factory=RunRecorder)  # path and legs, bounded

    def is_current(self) -> bool:
        """Whether the journal file is still the one read (nothing appended since)."""
        try:
            return self.path.stat().st_size == self.size
        except OSError:
            return False


def read_journal(path: str | os.PathLike[str]) -> JournalState:
    """Read a journal in one pass; a truncated last line (of any run segment) is tolerated.

    Raises :class:`NavseqError` naming ``path:line`` when the file is not a navseq
    journal or is damaged anywhere else.
    """
    with JournalReader(path) as reader:
        header = reader.header
        state = JournalState(
            path=header.path,
            version=header.version,
            mission_source=header.mission_source,
            mission_digest=header.mission_digest,
            started=header.started,
            run_options=header.run_options,
        )
        _fold(state, reader.entries())
        state.chain = reader.chain
        state.size = reader.size
    return state


def state_from_entries(header: JournalHeader, entries: Iterable[Entry]) -> JournalState:
    """What a journal with this header and these entries would say, from elsewhere.

    For a run whose journal is gone but whose events were kept another way (its MCAP
    recording: :mod:`navseq.sinks.recording.reading`); ``Resumed`` entries separate the
    segments of a resumed run. There is no chain and no size: nothing can append to it.
    """
    state = JournalState(
        path=header.path,
        version=header.version,
        mission_source=header.mission_source,
        mission_digest=header.mission_digest,
        started=header.started,
        run_options=header.run_options,
    )
    _fold(state, entries)
    return state


def _fold(state: JournalState, entries: Iterable[Entry]) -> None:
    path = state.path
    visits = state.visits
    recorder = state.recorder
    segment_start: float | None = None
    segment_end: float | None = None
    for entry in entries:
        if isinstance(entry, Damaged):
            state.damaged_count += 1
            if len(state.damaged_lines) < MAX_DAMAGED_LISTED:
                state.damaged_lines.append(entry.line)
            continue
        if isinstance(entry, Resumed):
            state.segments += 1
            state.finish_reason = None
            if segment_start is not None and segment_end is not None:
                state.previous_duration += max(0.0, segment_end - segment_start)
            segment_start = segment_end = None
            continue
        assert isinstance(entry, Event)
        event = entry.event
        state.event_count += 1
        recorder(event)
        if isinstance(event, ev.MissionStarted):
            segment_start = event.t
            if state.mission_started is None:
                state.mission_started = event
            visits.start_mission(event, f"{path}:{entry.line}")
        segment_end = event.t
        if isinstance(event, ev.WaypointProgress):
            visits.see_progress(event)
        elif isinstance(event, ev.WaypointStarted):
            visits.start_visit(event)
        elif isinstance(event, ev.AttemptFailed):
            visits.fail_attempt(event)
        elif isinstance(event, ev.WaypointReleased):
            visits.release(event)
        elif isinstance(event, ev.TaskFinished):
            visits.finish_task(event)
        elif isinstance(event, ev.RecoveryFinished):
            visits.finish_recovery(event)
        elif isinstance(event, ev.WaypointFinished):
            visits.finish_visit(event, f"{path}:{entry.line}")
        elif isinstance(event, ev.MissionFinished):
            state.finish_reason = event.reason
    if segment_start is not None and segment_end is not None:
        state.previous_duration += max(0.0, segment_end - segment_start)


def resume_point(state: JournalState, *, mission_digest: str | None = None) -> ResumePoint:
    """Where to continue: the first visit, in mission order, not yet reached or skipped.

    That is the visit that was active when the run ended (or the one after the last
    finished visit, if the run ended between two). Reached and skipped visits are not
    run again: they come with the point (``earlier``), counted. With ``mission_digest``
    (see :func:`~navseq.journal.writer.mission_digest`), a mission file that changed
    since the journal was written is refused.
    """
    source = str(state.path)
    if mission_digest is not None and mission_digest != state.mission_digest:
        raise NavseqError(
            f"the mission file changed since this journal was written (sha256 "
            f"{mission_digest[:12]}… now, {state.mission_digest[:12]}… then); resuming "
            "could skip or repeat the wrong waypoints. Restore the original mission "
            "file, or start a new run",
            source=source,
        )
    started = state.mission_started
    if started is None:
        return ResumePoint(loop=0, index=0)
    loop, index = state.visits.frontier
    if started.loops is not None and loop >= started.loops:
        nothing = NothingToResume(
            "nothing to resume: the journal records every waypoint of the mission "
            f"as finished ({state.finish_reason or 'completed'})",
            source=source,
        )
        nothing.state = state
        raise nothing
    return ResumePoint(
        loop=loop,
        index=index,
        earlier=state.visits.log,
        previous_duration=state.previous_duration,
        tasks_done=state.visits.tasks_done_at((loop, index)),
        tasks=tuple(state.visits.tasks_of((loop, index))),
    )


def _attempt_of(event: ev.AttemptFailed) -> AttemptResult:
    return AttemptResult(
        number=event.attempt,
        status=event.status,
        reason=event.reason,
        text=event.text,
        duration=event.duration,
        distance_driven=event.distance_driven,
        recoveries=event.recoveries,
    )


def _attempts_of(event: ev.WaypointFinished, trail: _VisitTrail | None) -> list[AttemptResult]:
    """The visit's attempts the journal tells about, in order.

    The last attempt ended without an AttemptFailed when it reached the waypoint or
    was ended by navseq (interrupt, operator skip): it is rebuilt from the finish.
    Only attempts the journal records are listed (never a padding of ``attempts``
    blanks: a damaged journal may give any number there).
    """
    failures = trail.failures if trail is not None else {}
    sent_at = trail.sent_at if trail is not None else {}
    last = event.attempts
    attempts = [failures[n] for n in sorted(failures) if 1 <= n <= last]
    if last >= 1 and last not in failures:
        first_sent = sent_at.get(1)
        last_sent = sent_at.get(last)
        reached = event.outcome is ev.WaypointOutcome.REACHED
        if reached:
            end = first_sent + event.duration if first_sent is not None else None
        else:
            end = event.t
        before = sum(a.distance_driven for a in attempts)
        attempts.append(
            AttemptResult(
                number=last,
                reached=reached,
                status="SUCCEEDED" if reached and not event.passed_through else None,
                reason="" if reached else event.reason,
                duration=0.0 if end is None or last_sent is None else max(0.0, end - last_sent),
                distance_driven=max(0.0, event.distance_driven - before),
                recoveries=trail.recoveries if trail is not None else None,
                held=trail.held.get(last, 0.0) if trail is not None else 0.0,
            )
        )
    return attempts


def _visit_of(
    event: ev.WaypointFinished,
    trail: _VisitTrail | None = None,
    tasks: list[TaskResult] | None = None,
) -> WaypointResult:
    """A finished visit as the result lists it (the waypoint's pose comes from the mission)."""
    return WaypointResult(
        index=event.index,
        loop=event.loop,
        name=None,
        x=0.0,
        y=0.0,
        yaw_rad=0.0,
        outcome=event.outcome,
        attempts=event.attempts,
        duration=event.duration,
        distance_driven=event.distance_driven,
        reason=event.reason,
        passed_through=event.passed_through,
        attempt_results=_attempts_of(event, trail),
        tasks=tasks or [],
        recoveries=list(trail.recovery_runs) if trail is not None else [],
    )


def _task_of(event: ev.TaskFinished) -> TaskResult:
    return TaskResult(
        number=event.task,
        kind=event.task_kind,
        outcome=event.outcome,
        attempt=event.attempt,
        duration=event.duration,
        detail=event.detail,
        files=list(event.files),
        output=list(event.output),
    )


def _with_pose(visit: WaypointResult, waypoint: Any) -> WaypointResult:
    from dataclasses import replace

    return replace(visit, name=waypoint.name, x=waypoint.x, y=waypoint.y, yaw_rad=waypoint.yaw_rad)


__all__ = [
    "MAX_JOURNAL_WAYPOINTS",
    "JournalState",
    "NothingToResume",
    "VisitHistory",
    "read_journal",
    "resume_point",
    "state_from_entries",
]
