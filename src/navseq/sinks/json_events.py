"""Mission events as JSON records: ``navseq run --json``, and the public API's records.

One record per event, one line each: ``{"event": "<type>", "schema_version": 1,
"t_s": ..., ...}``. The record is the event's fields under the names the run report
uses, with the unit in the name: ``t_s``, ``duration_s``, ``distance_m``,
``distance_remaining_m``, ``dwell_s``, ``yaw_deg`` (degrees, like the report and
mission files; the executor's events carry radians). ``x`` and ``y`` are metres in the
mission's frame, ``index`` is 0-based, ``loops`` is a count or ``"forever"``. Numbers
are rounded to six decimals (micrometres, microseconds: below what any navigation
stack resolves, and ``8.7`` rather than ``8.700000000000001``). The
JSON Schema is ``docs/schemas/events.schema.json``; :data:`SCHEMA_VERSION` goes up
whenever a field is renamed, removed or changes meaning.

The renames live in one table, :data:`FIELDS`, applied to every event type, so a
field means the same in every record; a new event field without an entry is written
under its own name, and the schema test fails until the schema says what it is.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import asdict
from typing import IO, Any

from navseq.executor.events import MissionEvent, WaypointOutcome

#: Version of the record layout (``schema_version`` in every record).
SCHEMA_VERSION = 1


#: Decimals kept in every number of a record.
DECIMALS = 6


def _degrees(radians: Any) -> Any:
    return math.degrees(radians) if isinstance(radians, float | int) else radians


def _loops(loops: Any) -> Any:
    return "forever" if loops is None else loops


def _outcome(outcome: Any) -> Any:
    return WaypointOutcome(outcome).value


def _points(path: Any) -> Any:
    return [list(point) for point in path]


#: Event field -> (record field, conversion). Fields not listed keep name and value.
FIELDS: dict[str, tuple[str, Callable[[Any], Any] | None]] = {
    "t": ("t_s", None),
    "yaw": ("yaw_deg", _degrees),
    "duration": ("duration_s", None),
    "distance_driven": ("distance_m", None),
    "distance_remaining": ("distance_remaining_m", None),
    "seconds": ("dwell_s", None),
    # WaypointFinished's count; the report's ``attempts`` is the list of attempts.
    "attempts": ("attempt_count", None),
    "loops": ("loops", _loops),
    "outcome": ("outcome", _outcome),
    "path": ("path", _points),
}


def json_safe(value: Any, decimals: int | None = None) -> Any:
    """Replace non-finite floats (not valid JSON) by None, recursively; round the others
    to ``decimals`` when given."""
    if isinstance(value, float):
        if not math.isfinite(value):
            return None
        return round(value, decimals) + 0.0 if decimals is not None else value  # no -0.0
    if isinstance(value, dict):
        return {key: json_safe(item, decimals) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(item, decimals) for item in value]
    return value


def event_record(event: MissionEvent) -> dict[str, Any]:
    """``event`` as a JSON-ready dict with unit-named fields (see the module docstring)."""
    record: dict[str, Any] = {"event": type(event).__name__, "schema_version": SCHEMA_VERSION}
    for name, value in asdict(event).items():
        renamed, convert = FIELDS.get(name, (name, None))
        record[renamed] = convert(value) if convert is not None and value is not None else value
    return dict(json_safe(record, DECIMALS))


def run_finished_record(
    *,
    success: bool,
    reason: str,
    exit_code: int,
    interrupted: str | None,
    files: Mapping[str, str],
) -> dict[str, Any]:
    """The last record of ``navseq run --json``: how the run ended and what it wrote.

    ``files`` maps a role (``journal``, ``report``, ``picture``) to its path, as the
    report's ``files`` does.
    """
    return {
        "event": "RunFinished",
        "schema_version": SCHEMA_VERSION,
        "success": success,
        "reason": reason,
        "exit_code": exit_code,
        "interrupted": interrupted,
        "files": dict(files),
    }


def _dumps(record: Mapping[str, Any]) -> str:
    return json.dumps(record, ensure_ascii=False, separators=(",", ":"))


def event_to_json(event: MissionEvent) -> str:
    """One event as a single-line JSON object."""
    return _dumps(event_record(event))


class JsonProgress:
    """One JSON object per event on ``stream`` (``navseq run --json``)."""

    def __init__(self, stream: IO[str]):
        self.stream = stream

    def __enter__(self) -> JsonProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stream.flush()

    def __call__(self, event: MissionEvent) -> None:
        self.stream.write(event_to_json(event) + "\n")
        self.stream.flush()

    def run_finished(
        self,
        *,
        success: bool,
        reason: str,
        exit_code: int,
        interrupted: str | None,
        files: Mapping[str, str],
    ) -> None:
        """Write the final ``RunFinished`` record (see :func:`run_finished_record`)."""
        record = run_finished_record(
            success=success,
            reason=reason,
            exit_code=exit_code,
            interrupted=interrupted,
            files=files,
        )
        self.stream.write(_dumps(json_safe(record)) + "\n")
        self.stream.flush()
