"""Mission events as JSON records: ``navseq run --json``, and the public API's records.

One record per event, one line each: ``{"event": "<type>", "schema_version": 4,
"t_s": ..., ...}``. The record is the event's fields under the names the run report
uses, with the unit in the name: ``t_s``, ``duration_s``, ``distance_m``,
``distance_remaining_m``, ``navigation_time_s``, ``dwell_s``, ``yaw_deg`` (degrees, like
the report and mission files; the executor's events carry radians). ``x`` and ``y``
are metres in the mission's frame, ``index`` is 0-based (the position in the mission
run: in a part of a file, ``--from``/``--to``/``--only``, the position in the part) and
``number`` the waypoint's 1-based number in the file (what messages and the summary
table say, as in the report's visits), ``loops`` is a count or ``"forever"``. Numbers
are rounded to six decimals (micrometres, microseconds: below what any navigation
stack resolves, and ``8.7`` rather than ``8.700000000000001``). The
JSON Schema is ``docs/schemas/events.schema.json``; :data:`SCHEMA_VERSION` goes up
whenever a field is renamed, removed or changes meaning, and when one is added
(version 2: ``recoveries`` and ``navigation_time_s`` in ``WaypointProgress``,
``recoveries`` in ``AttemptFailed``, from stacks that count them, like Nav2; version 3:
``number`` beside every ``index``, and ``RunFinished``'s ``clock``; version 6: ``robot``
in every record of ``navseq run --fleet --json``, and ``WaypointHeld`` and
``WaypointReleased``, a fleet holding a robot back).

The renames live in one table, :data:`FIELDS`, applied to every event type, so a
field means the same in every record; a new event field without an entry is written
under its own name, and the schema test fails until the schema says what it is.
"""

from __future__ import annotations

import contextlib
import json
import math
from collections.abc import Callable, Mapping, Sequence
from contextlib import AbstractContextManager
from dataclasses import asdict
from typing import IO, Any, Protocol

from navseq.executor.events import MissionEvent, WaypointOutcome, WaypointProgress

#: Version of the record layout (``schema_version`` in every record).
SCHEMA_VERSION = 6


#: Decimals kept in every number of a record.
DECIMALS = 6


def _degrees(radians: Any) -> Any:
    return math.degrees(radians) if isinstance(radians, float | int) else radians


def _loops(loops: Any) -> Any:
    return "forever" if loops is None else loops


def _outcome(outcome: Any) -> Any:
    if isinstance(outcome, WaypointOutcome):
        return outcome.value
    return outcome  # a task's outcome is its text already (TaskFinished)


def _points(path: Any) -> Any:
    return [list(point) for point in path]


#: Event field -> (record field, conversion). Fields not listed keep name and value.
FIELDS: dict[str, tuple[str, Callable[[Any], Any] | None]] = {
    "t": ("t_s", None),
    "yaw": ("yaw_deg", _degrees),
    "duration": ("duration_s", None),
    "distance_driven": ("distance_m", None),
    "distance_remaining": ("distance_remaining_m", None),
    "navigation_time": ("navigation_time_s", None),
    "seconds": ("dwell_s", None),
    "held_for": ("held_s", None),  # WaypointReleased, as the report's held_s
    # WaypointFinished's count; the report's ``attempts`` is the list of attempts.
    "attempts": ("attempt_count", None),
    "loops": ("loops", _loops),
    "outcome": ("outcome", _outcome),
    "path": ("path", _points),
    "task_kind": ("kind", None),  # TaskStarted / TaskFinished, as the report's tasks say
    "recovery_kind": ("kind", None),  # RecoveryStarted / RecoveryFinished, likewise
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


def event_record(event: MissionEvent, numbers: Sequence[int] | None = None) -> dict[str, Any]:
    """``event`` as a JSON-ready dict with unit-named fields (see the module docstring).

    ``numbers``: the waypoints' 0-based positions in the mission file when the mission
    run is a part of it (``Mission.numbers``), for the ``number`` beside ``index``.
    """
    record: dict[str, Any] = {"event": type(event).__name__, "schema_version": SCHEMA_VERSION}
    for name, value in asdict(event).items():
        renamed, convert = FIELDS.get(name, (name, None))
        record[renamed] = convert(value) if convert is not None and value is not None else value
        if name == "index" and isinstance(value, int):
            in_file = numbers is not None and 0 <= value < len(numbers)
            record["number"] = (numbers[value] if numbers is not None and in_file else value) + 1
    return dict(json_safe(record, DECIMALS))


def event_fields(record: Mapping[str, Any]) -> dict[str, Any]:
    """The event's own fields (radians, ``distance_driven`` ...) of an :func:`event_record`,
    under ``type``: what the journal keeps of an event, to be read back as one
    (:func:`navseq.journal.format.event_from_record`). Numbers keep the record's six
    decimals."""
    names = {renamed: name for name, (renamed, _) in FIELDS.items()}
    fields: dict[str, Any] = {"type": record.get("event")}
    for key, value in record.items():
        if key in ("event", "schema_version", "number"):
            continue
        name = names.get(key, key)
        if name == "yaw" and isinstance(value, float | int):
            value = math.radians(value)
        elif name == "loops" and value == "forever":
            value = None
        fields[name] = value
    return fields


def clock_record(navigator_seconds: float, wall_seconds: float) -> dict[str, float | None]:
    """How fast the navigator's clock ran: the report's and ``RunFinished``'s ``clock``.

    ``navigator_s`` is the run's time on the navigator's clock (simulated time on the
    simulator, ROS time with ros1), ``wall_s`` the wall time it took, and
    ``real_time_factor`` their ratio (``121.3``: 121 times faster than real time; None
    when no wall time passed).
    """
    factor = navigator_seconds / wall_seconds if wall_seconds > 0.0 else None
    return {
        "navigator_s": round(navigator_seconds, 3),
        "wall_s": round(wall_seconds, 6),
        "real_time_factor": round(factor, 3) if factor is not None else None,
    }


def run_finished_record(
    *,
    success: bool,
    reason: str,
    exit_code: int,
    interrupted: str | None,
    files: Mapping[str, str],
    clock: Mapping[str, float | None],
) -> dict[str, Any]:
    """The last record of ``navseq run --json``: how the run ended and what it wrote.

    ``files`` maps a role (``journal``, ``report``, ``picture``) to its path, as the
    report's ``files`` does; ``clock`` is :func:`clock_record`'s, as the report's.
    """
    return {
        "event": "RunFinished",
        "schema_version": SCHEMA_VERSION,
        "success": success,
        "reason": reason,
        "exit_code": exit_code,
        "interrupted": interrupted,
        "files": dict(files),
        "clock": dict(clock),
    }


def _rounded(seconds: float | None) -> float | None:
    """Seconds to go as a record has them: tenths, never negative, None when unknown."""
    if seconds is None or not math.isfinite(seconds):
        return None
    return round(max(seconds, 0.0), 1)


def _dumps(record: Mapping[str, Any]) -> str:
    return json.dumps(record, ensure_ascii=False, separators=(",", ":"))


def event_to_json(event: MissionEvent, numbers: Sequence[int] | None = None) -> str:
    """One event as a single-line JSON object (``numbers``: see :func:`event_record`)."""
    return _dumps(event_record(event, numbers))


class Eta(Protocol):
    """The run's time to go (:class:`navseq.eta.live.EtaEstimator`), as sinks read it."""

    eta_s: float | None
    eta_upper_s: float | None


class JsonProgress:
    """One JSON object per event on ``stream`` (``navseq run --json``).

    ``numbers``: the waypoints' positions in the file when the mission is a part of it.
    ``eta``: the run's ETA; each ``WaypointProgress`` record then carries ``eta_s`` and
    ``eta_upper_s``.
    """

    def __init__(
        self,
        stream: IO[str],
        numbers: Sequence[int] | None = None,
        eta: Eta | None = None,
        *,
        robot: str | None = None,
        lock: AbstractContextManager[Any] | None = None,
    ):
        self.stream = stream
        self.numbers = numbers
        self.eta = eta
        #: A fleet's robot: every record names it (``robot``), and the robots' threads
        #: take ``lock`` to write whole lines to the one stream.
        self.robot = robot
        self._lock = lock if lock is not None else contextlib.nullcontext()

    def __enter__(self) -> JsonProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stream.flush()

    def __call__(self, event: MissionEvent) -> None:
        record = event_record(event, self.numbers)
        if self.eta is not None and isinstance(event, WaypointProgress):
            record["eta_s"] = _rounded(self.eta.eta_s)
            record["eta_upper_s"] = _rounded(self.eta.eta_upper_s)
        self._write(record)

    def run_finished(
        self,
        *,
        success: bool,
        reason: str,
        exit_code: int,
        interrupted: str | None,
        files: Mapping[str, str],
        clock: Mapping[str, float | None],
    ) -> None:
        """Write the final ``RunFinished`` record (see :func:`run_finished_record`)."""
        record = run_finished_record(
            success=success,
            reason=reason,
            exit_code=exit_code,
            interrupted=interrupted,
            files=files,
            clock=clock,
        )
        self._write(json_safe(record))

    def _write(self, record: dict[str, Any]) -> None:
        if self.robot is not None:  # after event and schema_version, as the schema lists it
            head: dict[str, Any] = {
                key: record.pop(key) for key in ("event", "schema_version") if key in record
            }
            record = {**head, "robot": self.robot, **record}
        with self._lock:
            self.stream.write(_dumps(record) + "\n")
            self.stream.flush()
