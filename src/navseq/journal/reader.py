"""Reading a journal line by line, in bounded memory, checking it as it goes.

A patrol journals for weeks: its journal may hold millions of lines. The reader never
holds more than one line: :class:`JournalReader` checks the header first (so a wrong
file fails fast), then yields the records one at a time (:meth:`JournalReader.entries`)
while it checks the chain digest of every line. What a caller keeps of them is its own
business (:mod:`navseq.journal.state` folds them into a bounded state).

Against hostile input, what is bounded is each line (:data:`MAX_LINE_BYTES`), not the
whole file: a legitimate journal of a week-long patrol is read whatever its size.

Damage a crash can leave is tolerated: a line cut short (``kill -9`` while writing) as
the last line of the journal or of a run segment (when a resumed run appended after
it: the ``resumed`` record follows). Any other damage is refused with its line number.
An empty journal (:class:`EmptyJournal`) is said to be one: its run never began.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

from navseq.errors import NavseqError
from navseq.executor import events as ev
from navseq.files import open_input_file
from navseq.journal.format import (
    CHAINED_SINCE,
    JOURNAL_FORMAT,
    JOURNAL_VERSION,
    MAX_HEADER_BYTES,
    MAX_LINE_BYTES,
    event_from_record,
    next_chain,
)
from navseq.text import printable

#: open_input_file wants a size limit; a journal has none (its lines have).
_ANY_SIZE = 1 << 62


@dataclass
class JournalHeader:
    """The journal's first line."""

    path: Path
    version: int
    mission_source: str
    mission_digest: str
    started: str
    run_options: dict[str, Any] = field(default_factory=dict)  # the header's "run"


@dataclass(frozen=True)
class Resumed:
    """A ``resumed`` record: a later process continued the run from here."""

    line: int
    loop: Any
    index: Any


@dataclass(frozen=True)
class Damaged:
    """A line a crash cut short (tolerated: the last line, or the last of a segment)."""

    line: int


@dataclass(frozen=True)
class Event:
    """One journaled mission event and its line number."""

    line: int
    event: ev.MissionEvent


Entry = Event | Resumed | Damaged


class EmptyJournal(NavseqError):
    """A journal file with nothing in it, not even the header.

    The run writes the header before anything else it does, so only a run killed in
    the moment between creating the file and writing that line leaves one (and runs
    of navseq before it did, which got as far as a second in): nothing had happened.
    """


class JournalReader:
    """A journal opened for reading: ``header`` checked, ``entries()`` to go through.

    ::

        with JournalReader(path) as journal:
            for entry in journal.entries():
                ...
            journal.chain  # the digest the next appended line chains on from

    Raises :class:`NavseqError` naming ``path:line`` when the file is not a navseq
    journal, is damaged other than by a crash, or was altered.
    """

    def __init__(self, path: str | os.PathLike[str]):
        self.path = Path(path)
        self.chain = ""  # of the last intact line read
        self.size = 0  # bytes read so far
        self._handle: BinaryIO | None = None
        self.header = self._open()

    def __enter__(self) -> JournalReader:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def close(self) -> None:
        if self._handle is not None:
            self._handle.close()
            self._handle = None

    def _open(self) -> JournalHeader:
        path = self.path
        self._handle = open_input_file(path, what="journal", max_bytes=_ANY_SIZE)
        try:
            # Check the header before reading on, so a huge wrong file fails fast.
            first = self._read_line(MAX_HEADER_BYTES, 1)
            if first is None:
                raise EmptyJournal(
                    "the journal is empty: its run was stopped before it began (nothing "
                    "was driven, nothing journaled), so there is nothing to resume or "
                    "report. Start the mission again (navseq run MISSION)",
                    source=f"{path}:1",
                )
            header = _parse_line(first, f"{path}:1")
            if header is None or header.get("kind") != "header":
                raise NavseqError("not a navseq journal (no header line)", source=f"{path}:1")
            if header.get("format") != JOURNAL_FORMAT:
                raise NavseqError(
                    f"not a navseq journal (format {printable(repr(header.get('format')))[:60]})",
                    source=f"{path}:1",
                )
            version = header.get("version")
            if (
                not isinstance(version, int)
                or isinstance(version, bool)
                or version > JOURNAL_VERSION
            ):
                raise NavseqError(
                    f"journal format version {printable(repr(version))[:40]} is not one this "
                    f"navseq understands (up to {JOURNAL_VERSION}); upgrade navseq",
                    source=f"{path}:1",
                )
            for key in ("mission_source", "mission_digest", "started"):
                _check_header_text(header.get(key, ""), key, f"{path}:1")
            self._chained = version >= CHAINED_SINCE
            if self._chained:
                self._check_chain(first, 1)
        except BaseException:
            self.close()
            raise
        run = header.get("run")
        return JournalHeader(
            path=path,
            version=version,
            mission_source=str(header.get("mission_source", "")),
            mission_digest=str(header.get("mission_digest", "")),
            started=str(header.get("started", "")),
            run_options=dict(run) if isinstance(run, dict) else {},
        )

    def entries(self) -> Iterator[Entry]:
        """The records after the header, one at a time, checked as they are read."""
        path = self.path
        number = 1
        cut: int | None = None  # an unreadable line, waiting to see what follows it
        while True:
            number += 1
            line = self._read_line(MAX_LINE_BYTES, number)
            if line is None:
                break
            if not line.strip():
                continue
            record = _parse_line(line, f"{path}:{number}")
            if record is None:
                if cut is not None:
                    break  # two in a row: the first is in the middle (refused below)
                cut = number
                continue
            kind = record.get("kind")
            if cut is not None:
                if kind != "resumed":
                    break
                yield Damaged(cut)  # the resumed run chained on from the line before it
                cut = None
            if kind == "resumed":
                entry: Entry = Resumed(number, record.get("loop"), record.get("index"))
            elif kind == "event":
                event = event_from_record(record, f"{path}:{number}")
                if event is None:
                    self._check_chain(line, number)
                    continue  # an event type from a newer navseq: not needed to resume
                entry = Event(number, event)
            else:
                raise NavseqError(
                    f"unknown journal record kind {printable(repr(kind))[:40]}",
                    source=f"{path}:{number}",
                )
            self._check_chain(line, number)
            yield entry
        if cut is not None:
            if line is not None:  # a damaged line with more journal after it
                raise NavseqError(
                    "damaged journal line (not JSON) in the middle of the journal",
                    source=f"{path}:{cut}",
                )
            yield Damaged(cut)
        self.close()

    def _read_line(self, limit: int, number: int) -> bytes | None:
        """The next line without its newline; None at the end of the file."""
        assert self._handle is not None
        try:
            line = self._handle.readline(limit + 1)
        except OSError as error:
            raise NavseqError(
                f"cannot read the journal: {error.strerror}", source=str(self.path)
            ) from None
        if not line:
            return None
        self.size += len(line)
        if line.endswith(b"\n"):
            return line[:-1]
        if len(line) > limit:
            raise NavseqError(
                f"a line over {limit / 2**20:g} MiB: longer than any journal record; the "
                "journal is damaged or is not a navseq journal",
                source=f"{self.path}:{number}",
            )
        return line  # the last line, without a newline (possibly cut short)

    def _check_chain(self, line: bytes, number: int) -> None:
        if not self._chained:
            return
        chain = next_chain(self.chain, line)
        if chain is None:
            raise NavseqError(
                "the journal was altered here (a line edited, removed or moved: its chain "
                "digest does not follow from the lines before); navseq does not resume "
                "from an altered journal, which could re-run reached waypoints or skip "
                "others. Start a new run, or restore the original journal",
                source=f"{self.path}:{number}",
            )
        self.chain = chain


def journal_events(path: str | os.PathLike[str]) -> Iterator[ev.MissionEvent]:
    """The mission events a journal holds, in order, read one at a time (checked)."""
    with JournalReader(path) as reader:
        for entry in reader.entries():
            if isinstance(entry, Event):
                yield entry.event


def _check_header_text(value: Any, key: str, where: str) -> None:
    """The header's texts name files and digests: no NUL, nothing a path cannot hold."""
    if not isinstance(value, str) or "\0" in value or not _is_path_text(value):
        raise NavseqError(
            f"the header's {key} is not a valid text or path "
            f"({printable(repr(value))[:60]}); the journal is damaged",
            source=where,
        )


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


__all__ = [
    "MAX_LINE_BYTES",
    "Damaged",
    "EmptyJournal",
    "Entry",
    "Event",
    "JournalHeader",
    "JournalReader",
    "Resumed",
    "journal_events",
]
