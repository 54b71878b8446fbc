"""The mission journal: an append-only JSON-lines record of a run, enough to resume it.

Writing::

    journal = JournalWriter("run.journal", "mission.yaml", mission_digest("mission.yaml"))
    run_mission(mission, navigator, [journal])

Resuming after a crash (``navseq run --resume run.journal``)::

    state = read_journal("run.journal")
    point = resume_point(state, mission_digest=mission_digest(state.mission_source))
    journal = JournalWriter.resume("run.journal", point)
    run_mission(mission, navigator, [journal], resume=point)

The first line is a header (format, version, mission source and its sha256, wall
start time); every further line is one mission event (``{"kind": "event", "type":
"WaypointStarted", "t": ..., ...}``) or a ``resumed`` record. Each line is written
with a single ``write`` call on a file opened in append mode, so a crash (even
``kill -9``) leaves at most one truncated last line; the reader tolerates it, and a
resumed run starts a fresh line after it. ``WaypointProgress`` events are thinned out
to at most one per second of mission time; everything else is kept.

Every line ends with ``"chain"``: the first 16 hex digits of the sha256 of the previous
line's chain and this line's record. A journal whose lines were edited, deleted or
reordered by hand no longer chains, and is refused with the line number where the
chain breaks: resuming from it could re-run reached waypoints or skip unreached ones.
The header records the run's options (``run``: loops, navigator, ...), so that a resume
continues the mission as it was started.

Fields added to an event type later (``AttemptFailed``'s ``status``, ``text``,
``duration``, ``distance_driven``, ``loop``) default when an older journal lacks them,
so journals written by earlier versions still read and resume.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import enum
import errno
import functools
import hashlib
import json
import os
import types
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union, get_args, get_origin, get_type_hints

from navseq.errors import NavseqError
from navseq.executor import events as ev
from navseq.executor.result import AttemptResult, WaypointResult
from navseq.executor.resume import ResumePoint
from navseq.files import limit_from_environment, open_input_file
from navseq.mission.reading import MAX_MISSION_BYTES
from navseq.text import printable

JOURNAL_FORMAT = "navseq-journal"
JOURNAL_VERSION = 2
#: From this version on every line carries a chain digest.
_CHAINED_SINCE = 2
_CHAIN_KEY = b', "chain": "'
_CHAIN_DIGITS = 16
_CHAIN_SUFFIX_LENGTH = len(_CHAIN_KEY) + _CHAIN_DIGITS + 2  # digits, closing quote and brace
#: Mission time between two journaled WaypointProgress events (s).
PROGRESS_INTERVAL = 1.0
_MAX_HEADER_BYTES = 64 * 1024
# Progress is journaled once a second: 64 MiB hold days of patrolling. The variable
# raises the limit for a journal that legitimately grew beyond it.
MAX_JOURNAL_BYTES_VARIABLE = "NAVSEQ_MAX_JOURNAL_BYTES"
DEFAULT_MAX_JOURNAL_BYTES = 64 * 1024 * 1024

_EVENT_TYPES: dict[str, type] = {
    cls.__name__: cls
    for cls in (
        ev.MissionStarted,
        ev.LoopStarted,
        ev.WaypointStarted,
        ev.WaypointProgress,
        ev.WaypointPlan,
        ev.AttemptFailed,
        ev.WaypointDwelling,
        ev.WaypointFinished,
        ev.MissionPaused,
        ev.MissionResumed,
        ev.ServerStatusChanged,
        ev.MissionFinished,
    )
}
_DONE_OUTCOMES = (ev.WaypointOutcome.REACHED, ev.WaypointOutcome.SKIPPED)


def mission_digest(path: str | os.PathLike[str]) -> str:
    """sha256 (hex) of a mission file's bytes: a resumed run must use the same mission.

    The file gets the checks of any mission file (a regular file of at most
    ``MAX_MISSION_BYTES``): a journal may name ``/dev/zero`` or a FIFO.
    """
    digest = hashlib.sha256()
    source = Path(path)
    with open_input_file(source, what="mission file", max_bytes=MAX_MISSION_BYTES) as stream:
        try:
            for chunk in iter(lambda: stream.read(1 << 20), b""):
                digest.update(chunk)
                if stream.tell() > MAX_MISSION_BYTES:  # it grew after the check
                    raise NavseqError(
                        f"is over {MAX_MISSION_BYTES / 2**20:g} MiB, too big for a mission file",
                        source=str(source),
                    )
        except OSError as error:
            raise NavseqError(
                f"cannot read the mission file: {error.strerror or error}", source=str(source)
            ) from None
    return digest.hexdigest()


class NothingToResume(NavseqError):
    """The journal records every visit of the mission as finished."""


class JournalWriter:
    """A mission listener that appends every event to a journal file, one JSON per line.

    A new journal refuses to replace an existing non-empty file unless ``overwrite``;
    use :meth:`resume` to continue one. ``fsync`` makes every line durable against
    power loss too (slower); without it a killed process still loses nothing.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        mission_source: str,
        mission_digest: str,
        *,
        overwrite: bool = False,
        fsync: bool = False,
        run_options: Mapping[str, Any] | None = None,
    ):
        self.path = Path(path)
        self._chain = ""
        if not overwrite and self.path.exists() and self.path.stat().st_size > 0:
            raise NavseqError(
                "a journal already exists here; resume it, or choose another journal path",
                source=str(self.path),
            )
        self._open(os.O_TRUNC, fsync)
        self._write(
            {
                "kind": "header",
                "format": JOURNAL_FORMAT,
                "version": JOURNAL_VERSION,
                "mission_source": mission_source,
                "mission_digest": mission_digest,
                "started": _wall_clock(),
                "run": dict(run_options or {}),
            }
        )

    @classmethod
    def resume(
        cls, path: str | os.PathLike[str], point: ResumePoint, *, fsync: bool = False
    ) -> JournalWriter:
        """Continue an existing journal: append a ``resumed`` record, then the new events."""
        writer = cls.__new__(cls)  # skip __init__: no new header
        writer.path = Path(path)
        # Refuse to append to something that is not an intact journal; go on with its chain.
        writer._chain = read_journal(writer.path).chain
        writer._open(0, fsync)
        if not _ends_with_newline(writer.path) and writer._fd is not None:
            os.write(writer._fd, b"\n")  # end the line a crash cut short
        writer._write(
            {
                "kind": "resumed",
                "loop": point.loop,
                "index": point.index,
                "at": _wall_clock(),
            }
        )
        return writer

    def _open(self, extra_flags: int, fsync: bool) -> None:
        flags = os.O_WRONLY | os.O_CREAT | os.O_APPEND | extra_flags
        try:
            self._fd: int | None = os.open(self.path, flags, 0o644)
        except OSError as error:
            raise NavseqError(
                f"cannot write the journal: {error.strerror}", source=str(self.path)
            ) from None
        self._fsync = fsync
        self._failed = False
        self._last_progress_t: float | None = None

    def __call__(self, event: ev.MissionEvent) -> None:
        if self._failed:
            return  # said once, when it failed; the run is being stopped
        if isinstance(event, ev.WaypointProgress):
            last = self._last_progress_t
            # A resumed run's clock may start again from zero: t < last also passes.
            if last is not None and 0.0 <= event.t - last < PROGRESS_INTERVAL:
                return
            self._last_progress_t = event.t
        record = {"kind": "event", "type": type(event).__name__, **dataclasses.asdict(event)}
        self._write(record)

    def _write(self, record: Mapping[str, Any]) -> None:
        if self._fd is None:
            raise ValueError(f"journal {self.path} is closed")
        data = _sealed(json.dumps(record, default=_json_default).encode(), self._chain)
        self._chain = data[-_CHAIN_DIGITS - 3 : -3].decode()
        view = memoryview(data)
        try:
            while view:  # one write call in practice; loop only if the OS writes less
                written = os.write(self._fd, view)
                view = view[written:]
            if self._fsync:
                os.fsync(self._fd)
        except OSError as error:
            self._failed = True
            why = "the disk is full" if error.errno == errno.ENOSPC else error.strerror
            raise NavseqError(
                f"cannot write the journal: {why}; the run was stopped, since a run that "
                "cannot be journaled cannot be resumed",
                source=str(self.path),
            ) from None

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> JournalWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


@dataclass
class JournalState:
    """What a journal says about a mission run (all segments, if it was resumed)."""

    path: Path
    version: int
    mission_source: str
    mission_digest: str
    started: str
    events: list[ev.MissionEvent] = field(default_factory=list)
    segments: int = 1  # 1 + number of resumed records
    damaged_lines: list[int] = field(default_factory=list)  # tolerated truncated lines
    visits: dict[tuple[int, int], WaypointResult] = field(default_factory=dict)
    previous_duration: float = 0.0  # mission time covered by all segments (s)
    finish_reason: str | None = None  # of the last segment, if it finished
    run_options: dict[str, Any] = field(default_factory=dict)  # the header's "run"
    chain: str = ""  # digest of the last intact line: a resumed run chains on from it

    @property
    def mission_started(self) -> ev.MissionStarted | None:
        return next((e for e in self.events if isinstance(e, ev.MissionStarted)), None)


def read_journal(path: str | os.PathLike[str]) -> JournalState:
    """Read a journal; a truncated last line (of any run segment) is tolerated.

    Raises :class:`NavseqError` naming ``path:line`` when the file is not a navseq
    journal or is damaged anywhere else.
    """
    path = Path(path)
    header, records = _read_records(path)
    state = JournalState(
        path=path,
        version=header["version"],
        mission_source=str(header.get("mission_source", "")),
        mission_digest=str(header.get("mission_digest", "")),
        started=str(header.get("started", "")),
        run_options=dict(header["run"]) if isinstance(header.get("run"), dict) else {},
    )
    _replay(state, records)  # first: its messages about damaged lines are the more precise
    if "_lines" in header:
        first, lines = header["_lines"]
        state.chain = _check_chain(path, first, lines, records)
    return state


def _read_records(path: Path) -> tuple[dict[str, Any], list[tuple[int, dict[str, Any] | None]]]:
    """The header, then (line number, record or None if unreadable) for every other line."""
    limit = limit_from_environment(MAX_JOURNAL_BYTES_VARIABLE, DEFAULT_MAX_JOURNAL_BYTES)

    def too_big(size: int, cap: int) -> str:
        return (
            f"is {size / 2**20:.1f} MiB; navseq reads journals up to {cap / 2**20:g} MiB "
            f"(set the environment variable {MAX_JOURNAL_BYTES_VARIABLE} to raise it)"
        )

    with open_input_file(path, what="journal", max_bytes=limit, too_big=too_big) as handle:
        try:
            # Check the header before reading on, so a huge wrong file fails fast.
            first = handle.readline(_MAX_HEADER_BYTES).rstrip(b"\n")
            header = _parse_line(first, f"{path}:1")
            if header is None or header.get("kind") != "header":
                raise NavseqError("not a navseq journal (no header line)", source=f"{path}:1")
            rest = handle.read(limit + 1)
        except OSError as error:
            raise NavseqError(
                f"cannot read the journal: {error.strerror}", source=str(path)
            ) from None
    if len(rest) > limit:
        raise NavseqError(too_big(len(rest), limit), source=str(path))
    if header.get("format") != JOURNAL_FORMAT:
        raise NavseqError(
            f"not a navseq journal (format {printable(repr(header.get('format')))[:60]})",
            source=f"{path}:1",
        )
    version = header.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version > JOURNAL_VERSION:
        raise NavseqError(
            f"journal format version {printable(repr(version))[:40]} is not one this navseq "
            f"understands (up to {JOURNAL_VERSION}); upgrade navseq",
            source=f"{path}:1",
        )
    for key in ("mission_source", "mission_digest", "started"):
        _check_header_text(header.get(key, ""), key, f"{path}:1")
    lines = rest.split(b"\n")
    if lines[-1] == b"":
        lines.pop()
    records = [
        (number, _parse_line(line, f"{path}:{number}"))
        for number, line in enumerate(lines, start=2)
        if line.strip()
    ]
    if version >= _CHAINED_SINCE:
        header["_lines"] = (first, lines)
    return header, records


def _sealed(record: bytes, previous_chain: str) -> bytes:
    """The journal line for a JSON object: the record plus its chain digest, and a newline."""
    digest = hashlib.sha256(previous_chain.encode() + record).hexdigest()[:_CHAIN_DIGITS]
    return record[:-1] + _CHAIN_KEY + digest.encode() + b'"}\n'


def _unsealed(line: bytes) -> tuple[bytes, str] | None:
    """(the record as it was hashed, its chain digest), or None if the line has no chain."""
    suffix = line[-_CHAIN_SUFFIX_LENGTH:]
    if len(line) <= _CHAIN_SUFFIX_LENGTH or not (
        suffix.startswith(_CHAIN_KEY) and suffix.endswith(b'"}')
    ):
        return None
    return line[:-_CHAIN_SUFFIX_LENGTH] + b"}", suffix[len(_CHAIN_KEY) : -2].decode(
        "ascii", "replace"
    )


def _check_chain(
    path: Path,
    header_line: bytes,
    lines: list[bytes],
    records: list[tuple[int, dict[str, Any] | None]],
) -> str:
    """The chain digest of the last intact line; NavseqError where the chain breaks.

    Unreadable lines are left to the replay, which tolerates a line a crash cut short
    (they never joined the chain: the run that resumed chained on from the line before).
    """
    chain = ""
    readable = {number for number, record in records if record is not None}
    numbered = [(1, header_line)] + [
        (number, line) for number, line in enumerate(lines, start=2) if number in readable
    ]
    for number, line in numbered:
        parts = _unsealed(line)
        expected = None
        if parts is not None:
            expected = hashlib.sha256(chain.encode() + parts[0]).hexdigest()[:_CHAIN_DIGITS]
        if parts is None or parts[1] != expected:
            raise NavseqError(
                "the journal was altered here (a line edited, removed or moved: its chain "
                "digest does not follow from the lines before); navseq does not resume "
                "from an altered journal, which could re-run reached waypoints or skip "
                "others. Start a new run, or restore the original journal",
                source=f"{path}:{number}",
            )
        chain = parts[1]
    return chain


@dataclass
class _VisitTrail:
    """What a segment's events said about the visit being driven, attempt by attempt."""

    key: tuple[int, int]
    sent_at: dict[int, float] = field(default_factory=dict)  # attempt number -> first send
    failures: dict[int, AttemptResult] = field(default_factory=dict)
    # The stack's recovery count last journaled for the latest attempt (thinned
    # WaypointProgress events: the count may lag the live report's by a second).
    recoveries: int | None = None


def _check_header_text(value: Any, key: str, where: str) -> None:
    """The header's texts name files and digests: no NUL, nothing a path cannot hold."""
    if not isinstance(value, str) or "\0" in value or not _is_path_text(value):
        raise NavseqError(
            f"the header's {key} is not a valid text or path "
            f"({printable(repr(value))[:60]}); the journal is damaged",
            source=where,
        )


def _replay(state: JournalState, records: list[tuple[int, dict[str, Any] | None]]) -> None:
    """Fill ``state`` from the records after the header, segment by segment."""
    path = state.path
    segment_start: float | None = None
    segment_end: float | None = None
    trail: _VisitTrail | None = None
    for position, (number, record) in enumerate(records):
        if record is None:
            following = records[position + 1][1] if position + 1 < len(records) else None
            if position + 1 == len(records) or (following or {}).get("kind") == "resumed":
                state.damaged_lines.append(number)  # a crash cut this line short
                continue
            raise NavseqError(
                "damaged journal line (not JSON) in the middle of the journal",
                source=f"{path}:{number}",
            )
        kind = record.get("kind")
        if kind == "resumed":
            state.segments += 1
            state.finish_reason = None
            if segment_start is not None and segment_end is not None:
                state.previous_duration += max(0.0, segment_end - segment_start)
            segment_start = segment_end = None
            continue
        if kind != "event":
            raise NavseqError(f"unknown journal record kind {kind!r}", source=f"{path}:{number}")
        event = _event_from_record(record, f"{path}:{number}")
        if event is None:
            continue  # an event type from a newer navseq: not needed to resume
        state.events.append(event)
        if isinstance(event, ev.MissionStarted):
            segment_start = event.t
            trail = None  # a new segment: its clock starts afresh
        segment_end = event.t
        if isinstance(event, ev.WaypointStarted):
            key = (event.loop, event.index)
            if trail is None or trail.key != key:
                trail = _VisitTrail(key)
            trail.sent_at.setdefault(event.attempt, event.t)
            trail.recoveries = None
        elif isinstance(event, ev.WaypointProgress) and trail is not None:
            if event.recoveries is not None:
                trail.recoveries = event.recoveries
        elif isinstance(event, ev.AttemptFailed) and trail is not None:
            # The visit is the one last started: older journals name no loop here.
            trail.failures[event.attempt] = _attempt_of(event)
        elif isinstance(event, ev.WaypointFinished):
            key = (event.loop, event.index)
            state.visits[key] = _visit_of(event, trail if trail and trail.key == key else None)
        elif isinstance(event, ev.MissionFinished):
            state.finish_reason = event.reason
    if segment_start is not None and segment_end is not None:
        state.previous_duration += max(0.0, segment_end - segment_start)


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
            )
        )
    return attempts


def _visit_of(event: ev.WaypointFinished, trail: _VisitTrail | None = None) -> WaypointResult:
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
    )


def resume_point(state: JournalState, *, mission_digest: str | None = None) -> ResumePoint:
    """Where to continue: the first visit, in mission order, not yet reached or skipped.

    That is the visit that was active when the run ended (or the one after the last
    finished visit, if the run ended between two). Reached and skipped visits are not
    run again. With ``mission_digest`` (see :func:`mission_digest`), a mission file
    that changed since the journal was written is refused.
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
    count, loops = started.waypoint_count, started.loops
    if count <= 0:
        raise NavseqError("the journal records a mission without waypoints", source=source)
    loop, index = 0, 0
    while state.visits.get((loop, index)) is not None and (
        state.visits[(loop, index)].outcome in _DONE_OUTCOMES
    ):
        index += 1
        if index == count:
            loop, index = loop + 1, 0
        if loops is not None and loop >= loops:
            raise NothingToResume(
                "nothing to resume: the journal records every waypoint of the mission "
                f"as finished ({state.finish_reason or 'completed'})",
                source=source,
            )
    done = tuple(
        visit
        for key, visit in sorted(state.visits.items())
        if key < (loop, index) and visit.outcome in _DONE_OUTCOMES
    )
    return ResumePoint(loop=loop, index=index, done=done, previous_duration=state.previous_duration)


def _is_path_text(value: str) -> bool:
    """False for a lone surrogate other than a file name's undecodable byte."""
    try:
        os.fsencode(value)
    except UnicodeEncodeError:
        return False
    return True


def _parse_line(line: bytes, where: str) -> dict[str, Any] | None:
    """One JSON record; None for a line that is not one (e.g. cut short by a crash)."""
    try:
        record = json.loads(line)
    except (ValueError, UnicodeDecodeError):
        return None
    except RecursionError:
        # No journal record nests more than a few levels; this one is no journal line.
        raise NavseqError(
            "a line nests JSON lists or objects too deeply to be a journal "
            "record; the journal is damaged or is not a navseq journal",
            source=where,
        ) from None
    return record if isinstance(record, dict) else None


def _event_from_record(record: dict[str, Any], where: str) -> ev.MissionEvent | None:
    cls = _EVENT_TYPES.get(str(record.get("type")))
    if cls is None:
        return None
    hints = _field_types(cls)
    values: dict[str, Any] = {}
    try:
        for spec in dataclasses.fields(cls):
            if spec.name in record:
                values[spec.name] = _coerce(record[spec.name], hints[spec.name])
        return cls(**values)
    except (TypeError, ValueError) as error:
        raise NavseqError(
            f"journal event {cls.__name__} is malformed: {error}", source=where
        ) from None


@functools.cache
def _field_types(cls: type) -> dict[str, Any]:
    """The event's field types, evaluated once per class (not once per journal line)."""
    return get_type_hints(cls)


def _coerce(value: Any, hint: Any) -> Any:
    """Check a JSON value against the event field's type and rebuild enums and tuples."""
    origin = get_origin(hint)
    if origin in (Union, types.UnionType):
        options = get_args(hint)
        if value is None and type(None) in options:
            return None
        for option in options:
            if option is not type(None):
                with contextlib.suppress(TypeError, ValueError):
                    return _coerce(value, option)
        raise TypeError(f"{value!r} is not a {hint}")
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        return hint(value)
    if origin is tuple:
        if not isinstance(value, list):
            raise TypeError(f"expected a list, got {value!r}")
        inner = get_args(hint)
        if len(inner) == 2 and inner[1] is Ellipsis:
            return tuple(_coerce(item, inner[0]) for item in value)
        if len(value) != len(inner):
            raise TypeError(f"expected {len(inner)} items, got {len(value)}")
        return tuple(_coerce(item, kind) for item, kind in zip(value, inner, strict=True))
    if isinstance(value, bool) and hint is not bool:
        raise TypeError(f"expected a {hint.__name__}, got {value!r}")
    if hint is float and isinstance(value, (int, float)):
        return float(value)
    if hint in (int, str, bool) and isinstance(value, hint):
        return value
    raise TypeError(f"expected a {getattr(hint, '__name__', hint)}, got {value!r}")


def _json_default(value: Any) -> Any:
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot journal a {type(value).__name__}")


def _ends_with_newline(path: Path) -> bool:
    with path.open("rb") as handle:
        handle.seek(0, os.SEEK_END)
        if handle.tell() == 0:
            return True
        handle.seek(-1, os.SEEK_END)
        return handle.read(1) == b"\n"


def _wall_clock() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


__all__ = [
    "JOURNAL_FORMAT",
    "JOURNAL_VERSION",
    "PROGRESS_INTERVAL",
    "JournalState",
    "JournalWriter",
    "NothingToResume",
    "mission_digest",
    "read_journal",
    "resume_point",
]
