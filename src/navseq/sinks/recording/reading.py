"""A run read back from its recordings, for ``navseq report`` when the journal is gone.

A recording keeps every mission event (``/navseq/events``) and, in its ``navseq.run``
metadata record, what a journal's header says: the mission file, its sha256 and the
run's options. :func:`read_recordings` turns the folder's ``run.mcap``, ``run-2.mcap``
... (one per run segment, in order) into the :class:`~navseq.journal.state.JournalState`
the journal would have given. The files are read in file order with the streaming
reader, so one cut short by a crash reads up to its last complete chunk.
"""

from __future__ import annotations

import json
import re
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.executor.events import MissionEvent
from navseq.journal.reader import Entry, Event, JournalHeader, Resumed
from navseq.journal.state import JournalState
from navseq.sinks.recording.sink import EVENTS_TOPIC, RUN_METADATA

RECORDING_NAME = re.compile(r"run(?:-([0-9]+))?\.mcap")
#: The journal format version the header fields follow.
HEADER_VERSION = 1


def run_metadata(
    mission_source: str, mission_digest: str, started: str, run_options: dict[str, Any]
) -> dict[str, str]:
    """The ``navseq.run`` metadata record's fields (MCAP metadata holds strings only)."""
    return {
        "mission_source": mission_source,
        "mission_digest": mission_digest,
        "started": started,
        "run_options": json.dumps(run_options),
    }


def recordings_in(folder: Path) -> list[Path]:
    """The folder's recordings, in the order the run wrote them (run.mcap, run-2.mcap ...)."""
    found = []
    for path in folder.iterdir():
        match = RECORDING_NAME.fullmatch(path.name)
        if match and path.is_file():
            found.append((int(match.group(1) or 1), path))
    return [path for _, path in sorted(found)]


def read_recordings(paths: list[Path]) -> JournalState:
    """The run the recordings ``paths`` (one per segment, in order) hold, as a journal would.

    Raises :class:`NavseqError` naming the file when a recording has no ``navseq.run``
    metadata (not navseq's, or cut before its first chunk).
    """
    from navseq.journal.state import state_from_entries

    header: JournalHeader | None = None
    entries: list[Entry] = []
    for number, path in enumerate(paths):
        metadata, events = _read(path)
        if metadata is None:
            raise NavseqError(
                "holds no navseq run (no navseq.run metadata): not a navseq recording, or "
                "one cut short before anything was written",
                source=str(path),
            )
        if header is None:
            header = _header(path, metadata)
        if number:
            entries.append(Resumed(0, None, None))
        entries.extend(events)
    assert header is not None, "no recordings given"
    return state_from_entries(header, entries)


def recorded_events(paths: list[Path]) -> Iterator[MissionEvent]:
    """Every mission event the recordings ``paths`` hold, in order (as far as each reads)."""
    for path in paths:
        for entry in _read(path)[1]:
            if isinstance(entry, Event):
                yield entry.event


def _header(path: Path, metadata: dict[str, str]) -> JournalHeader:
    try:
        options = json.loads(metadata.get("run_options", "{}"))
        return JournalHeader(
            path=path,
            version=HEADER_VERSION,
            mission_source=metadata["mission_source"],
            mission_digest=metadata["mission_digest"],
            started=metadata.get("started", ""),
            run_options=options if isinstance(options, dict) else {},
        )
    except (KeyError, ValueError) as error:
        raise NavseqError(
            f"its navseq.run metadata is malformed ({error})", source=str(path)
        ) from None


def _read(path: Path) -> tuple[dict[str, str] | None, list[Entry]]:
    """The run metadata and the events of one recording, as far as it reads."""
    from mcap.records import Channel, Message, Metadata

    from navseq.journal.format import event_from_record
    from navseq.sinks.json_events import event_fields

    metadata: dict[str, str] | None = None
    events_channel: int | None = None
    entries: list[Entry] = []
    for record in _records(path):
        if isinstance(record, Metadata) and record.name == RUN_METADATA:
            metadata = dict(record.metadata)
        elif isinstance(record, Channel) and record.topic == EVENTS_TOPIC:
            events_channel = record.id
        elif isinstance(record, Message) and record.channel_id == events_channel:
            where = f"{path}: event {len(entries) + 1}"
            try:
                fields = event_fields(json.loads(record.data))
            except ValueError as error:
                raise NavseqError(f"an event is not JSON ({error})", source=where) from None
            event = event_from_record(fields, where)
            if event is not None:
                entries.append(Event(len(entries) + 1, event))
    return metadata, entries


def _records(path: Path) -> Iterator[Any]:
    """Every record of an MCAP file in file order, up to where it ends or was cut."""
    from mcap.exceptions import EndOfFile, McapError
    from mcap.stream_reader import StreamReader

    try:
        with path.open("rb") as stream:
            try:
                yield from StreamReader(stream).records
            except (EndOfFile, struct.error):
                return  # a file a crash cut short: what is complete has been read
    except McapError as error:
        raise NavseqError(f"is not a readable MCAP file ({error})", source=str(path)) from None
    except OSError as error:
        raise NavseqError(f"cannot read it: {error.strerror}", source=str(path)) from None


__all__ = ["read_recordings", "recorded_events", "recordings_in", "run_metadata"]
