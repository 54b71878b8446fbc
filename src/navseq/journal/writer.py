"""The mission journal: an append-only JSON-lines record of a run, enough to resume it.

Writing::

    journal = JournalWriter("run.journal", "mission.yaml", mission_digest("mission.yaml"))
    run_mission(mission, navigator, [journal])

Resuming after a crash (``navseq run --resume run.journal``)::

    state = read_journal("run.journal")
    point = resume_point(state, mission_digest=mission_digest(state.mission_source))
    journal = JournalWriter.resume("run.journal", point, history=state)
    run_mission(mission, navigator, [journal], resume=point)

The first line is a header (format, version, mission source and its sha256, wall
start time); every further line is one mission event (``{"kind": "event", "type":
"WaypointStarted", "t": ..., ...}``) or a ``resumed`` record. Each line is written
with a single ``write`` call on a file opened in append mode, so a crash (even
``kill -9``) leaves at most one truncated last line; the reader tolerates it, and a
resumed run starts a fresh line after it.

A patrol journals for weeks, so the journal grows with the events that matter, not
with time: every visit's start, finish and failed attempts are kept, with the first
plan of each attempt (as corners, :data:`PATH_TOLERANCE`); the driven path is kept as
a thinned polyline of ``WaypointProgress`` events (:mod:`navseq.journal.path`:
its corners, the pose at every arrival, every change of the stack's recovery count,
and one at least every :data:`HEARTBEAT` seconds). Positions in progress and plans are
written to 0.1 mm.

Every line ends with ``"chain"``: the first 16 hex digits of the sha256 of the previous
line's chain and this line's record. A journal whose lines were edited, deleted or
reordered by hand no longer chains, and is refused with the line number where the
chain breaks: resuming from it could re-run reached waypoints or skip unreached ones.
The header records the run's options (``run``: loops, navigator, ...), so that a resume
continues the mission as it was started.

Reading (:func:`read_journal`, :mod:`navseq.journal.state`) streams the journal
and folds it into a bounded state. Fields added to an event type later
(``AttemptFailed``'s ``status``, ``text``, ``duration``, ``distance_driven``, ``loop``)
default when an older journal lacks them, so journals written by earlier versions
(progress once a second, every plan) still read and resume.
"""

from __future__ import annotations

import dataclasses
import datetime
import errno
import hashlib
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.executor import events as ev
from navseq.executor.resume import ResumePoint
from navseq.files import open_input_file
from navseq.journal.format import (
    CHAIN_DIGITS,
    JOURNAL_FORMAT,
    JOURNAL_VERSION,
    chain_of,
    json_default,
    sealed,
)
from navseq.journal.path import HEARTBEAT, PATH_TOLERANCE, ProgressThinner
from navseq.journal.reader import MAX_LINE_BYTES
from navseq.journal.state import (
    JournalState,
    NothingToResume,
    read_journal,
    resume_point,
)
from navseq.mission.reading import MAX_MISSION_BYTES
from navseq.track import simplify_path

#: Decimals of the positions (m), angles (rad) and distances written in progress and
#: plan records: 0.1 mm, where the full float took 18 digits for nothing.
POSITION_DECIMALS = 4


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


class JournalWriter:
    """A mission listener that appends the run's events to a journal file, one per line.

    Progress and plans are thinned (see the module docstring); every other event is
    written as it comes. A new journal refuses to replace an existing non-empty file
    unless ``overwrite``; use :meth:`resume` to continue one. ``fsync`` makes every
    line durable against power loss too (slower); without it a killed process still
    loses nothing.
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
        cls,
        path: str | os.PathLike[str],
        point: ResumePoint,
        *,
        fsync: bool = False,
        history: JournalState | None = None,
    ) -> JournalWriter:
        """Continue an existing journal: append a ``resumed`` record, then the new events.

        ``history`` is the journal as :func:`read_journal` read it (the resume point
        came from it): it is not read again unless it changed since (then it is, and
        must still be intact).
        """
        writer = cls.__new__(cls)  # skip __init__: no new header
        writer.path = Path(path)
        # Refuse to append to something that is not an intact journal; go on with its chain.
        if history is not None and _same_file(writer.path, history.path) and history.is_current():
            writer._chain = history.chain
        else:
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
        self._progress = ProgressThinner()
        self._plan_journaled = False  # for the current attempt

    def __call__(self, event: ev.MissionEvent) -> None:
        if self._failed:
            return  # said once, when it failed; the run is being stopped
        if isinstance(event, ev.WaypointProgress):
            for kept in self._progress.offer(event):
                self._write_event(kept)
            return
        if isinstance(event, ev.WaypointPlan):
            if self._plan_journaled or not event.path:
                return  # a replan of the same attempt: the picture draws each leg's first
            self._plan_journaled = True
        elif isinstance(event, ev.MissionStarted):
            self._progress.restart()
            self._plan_journaled = False
        elif isinstance(event, ev.WaypointStarted):
            self._plan_journaled = False
        elif isinstance(event, _ARRIVALS):
            latest = self._progress.flush()  # where the robot was when it arrived or stopped
            if latest is not None:
                self._write_event(latest)
        self._write_event(event)

    def _write_event(self, event: ev.MissionEvent) -> None:
        record = {"kind": "event", "type": type(event).__name__, **dataclasses.asdict(event)}
        if isinstance(event, ev.WaypointProgress):
            for name in _PROGRESS_DEFAULT_NONE:  # only stacks that count them fill these
                if record[name] is None:
                    del record[name]
            # Not t: the other records' times are exact, and times must stay in order.
            for name in (
                "x",
                "y",
                "yaw",
                "distance_remaining",
                "distance_driven",
                "navigation_time",
            ):
                if name in record:
                    record[name] = _rounded(record[name])
        elif isinstance(event, ev.WaypointPlan):
            corners = simplify_path(event.path, PATH_TOLERANCE)
            record["path"] = [[_rounded(x), _rounded(y)] for x, y in corners]
        self._write(record)

    def _write(self, record: Mapping[str, Any]) -> None:
        if self._fd is None:
            raise ValueError(f"journal {self.path} is closed")
        data = sealed(json.dumps(record, default=json_default).encode(), self._chain)
        self._chain = chain_of(data[:-1])
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


#: Progress fields that default to None, left out when None (the reader restores them).
_PROGRESS_DEFAULT_NONE = tuple(
    spec.name for spec in dataclasses.fields(ev.WaypointProgress) if spec.default is None
)
#: Events before which the latest pose is journaled, so the path ends where the robot was.
_ARRIVALS = (
    ev.WaypointDwelling,
    ev.TaskStarted,
    ev.WaypointFinished,
    ev.MissionPaused,
    ev.MissionFinished,
)


def _rounded(value: float | None) -> float | None:
    if value is None:
        return None
    return round(value, POSITION_DECIMALS)


def _same_file(path: Path, other: Path) -> bool:
    try:
        return path.samefile(other)
    except OSError:
        return False


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
    "CHAIN_DIGITS",
    "HEARTBEAT",
    "JOURNAL_FORMAT",
    "JOURNAL_VERSION",
    "MAX_LINE_BYTES",
    "PATH_TOLERANCE",
    "JournalState",
    "JournalWriter",
    "NothingToResume",
    "mission_digest",
    "read_journal",
    "resume_point",
]
