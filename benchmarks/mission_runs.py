"""What one ``navseq run`` left in its output folder, read for ``bench_nav2_real.py``.

No ROS here: the journal (``journal.jsonl``) and ``report.json`` are plain files, so the
reading is tested on its own (``tests/test_bench_nav2_real.py``) and the benchmark's
numbers come from the same records a user gets, nothing the benchmark measured on the
side.

- **Mission time**: the journal's ``MissionFinished.t - MissionStarted.t``, on the clock
  navseq ran on (the stack's: Nav2's ``/clock`` from its loopback simulator, the
  stand-in's wall clock at speed 1).
- **Failed attempts**: every ``AttemptFailed`` with Nav2's status, navseq's reason and
  Nav2's text; a reason starting ``succeeded far from goal`` is a false success navseq
  caught (the stack said SUCCEEDED with the robot elsewhere).
- **Issue 16's bar**: no visit recorded reached or passed through with the robot farther
  from its point than the goal tolerance (a pass-through visit: its radius, or the
  tolerance if larger, as the executor allows) plus :data:`BAR_SLACK_M`. The journal
  keeps no pose with ``WaypointFinished``; its progress events are thinned, but it
  journals the latest pose at every arrival. Each visit is therefore judged on the
  ``WaypointProgress`` nearest in time to its ``WaypointFinished``, and the time between
  the two is kept with the check, so a table can say how far apart they were.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: Issue 16: how far beyond its tolerance (or pass-through radius) a visit may be recorded.
BAR_SLACK_M = 0.1
FAR_FROM_GOAL = "succeeded far from goal"
#: "tolerance 0.25 m / 14°" in the note navseq prints when it reads the robot from Nav2.
_TOLERANCE = re.compile(r"tolerance ([0-9.]+) m")
_NUMBER = re.compile(r"\d+(\.\d+)?")

Event = dict[str, Any]


@dataclass(frozen=True)
class Failure:
    """One failed attempt, as the journal's ``AttemptFailed`` has it."""

    status: str
    reason: str
    text: str

    @property
    def false_success(self) -> bool:
        """The stack said SUCCEEDED and navseq found the robot away from the point."""
        return self.reason.startswith(FAR_FROM_GOAL)

    def kind(self) -> str:
        """``STATUS: text`` to group like with like: Nav2's text when it gave one, else
        navseq's reason with its numbers folded (``succeeded N° off the goal yaw``)."""
        said = self.text or _NUMBER.sub("N", self.reason)
        return f"{self.status or '-'}: {said or '(no text)'}"


@dataclass(frozen=True)
class ArrivalCheck:
    """One visit recorded reached or passed through, against issue 16's bar."""

    waypoint: str
    passed_through: bool
    distance_m: float  # from the pose nearest in time to the waypoint's point
    bound_m: float
    pose_dt_s: float  # between that pose and the WaypointFinished

    @property
    def over(self) -> bool:
        return self.distance_m > self.bound_m


@dataclass(frozen=True)
class FirstResult:
    """How the first goal of a one-waypoint mission ended: the edge cases."""

    outcome: str  # the visit's outcome (failed, reached ...) or "-" when there is none
    status: str
    text: str
    seconds: float | None  # from the goal sent to its result, on navseq's clock


@dataclass
class RunRecord:
    """One ``navseq run`` of one mission on one stack."""

    stack: str
    mission: str
    run: int
    exit_code: int
    wall_s: float
    edge: bool = False  # a one-waypoint edge case (its first result is what counts)
    mission_s: float | None = None
    failures: list[Failure] = field(default_factory=list)
    arrivals: list[ArrivalCheck] = field(default_factory=list)
    after_false_success: list[str] = field(default_factory=list)  # those visits' outcomes
    recoveries: int = 0
    robot: str = ""
    tolerance_m: float | None = None
    first: FirstResult | None = None
    note: str = ""
    nav2_log: dict[str, int] = field(default_factory=dict)

    @property
    def completed(self) -> bool:
        return self.exit_code == 0


def read_events(journal: Path) -> list[Event]:
    """The journal's events in order (its header and any torn last line left out)."""
    events: list[Event] = []
    for line in journal.read_text(encoding="utf-8").splitlines():
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            continue  # a run stopped mid-write leaves at most a torn last line
        if isinstance(record, dict) and record.get("kind") == "event":
            events.append(record)
    return events


def of_type(events: list[Event], name: str) -> list[Event]:
    return [event for event in events if event.get("type") == name]


def mission_seconds(events: list[Event]) -> float | None:
    """MissionStarted to MissionFinished on navseq's clock; None if either is missing."""
    started, finished = of_type(events, "MissionStarted"), of_type(events, "MissionFinished")
    if not started or not finished:
        return None
    return float(finished[-1]["t"]) - float(started[0]["t"])


def failures(events: list[Event]) -> list[Failure]:
    return [
        Failure(str(e.get("status") or ""), str(e.get("reason") or ""), str(e.get("text") or ""))
        for e in of_type(events, "AttemptFailed")
    ]


def outcomes_after_false_success(events: list[Event]) -> list[str]:
    """What became of each visit that had a false success caught: its final outcome."""
    caught = {
        (e.get("loop", 0), e["index"])
        for e in of_type(events, "AttemptFailed")
        if str(e.get("reason", "")).startswith(FAR_FROM_GOAL)
    }
    return [
        visit_outcome(e)
        for e in of_type(events, "WaypointFinished")
        if (e.get("loop", 0), e["index"]) in caught
    ]


def visit_outcome(finished: Event) -> str:
    if finished.get("outcome") == "reached" and finished.get("passed_through"):
        return "passed through"
    return str(finished.get("outcome", "?"))


def tolerance_from(robot_source: str) -> float | None:
    """The goal tolerance (m) in navseq's note on the robot it read from the stack."""
    found = _TOLERANCE.search(robot_source)
    return float(found.group(1)) if found else None


def nearest_pose(events: list[Event], t: float, index: int) -> tuple[Event, float] | None:
    """The WaypointProgress nearest in time to ``t`` and how far apart; on a tie, the
    visit's own (``index``) and then the earlier one."""
    best: tuple[tuple[float, int, int], Event] | None = None
    for order, event in enumerate(of_type(events, "WaypointProgress")):
        gap = abs(float(event["t"]) - t)
        key = (gap, 0 if event.get("index") == index else 1, order)
        if best is None or key < best[0]:
            best = (key, event)
    if best is None:
        return None
    return best[1], best[0][0]


def arrival_checks(
    events: list[Event], tolerance_m: float, radius_m: float | None, names: list[str]
) -> list[ArrivalCheck]:
    """Every visit recorded reached or passed through, checked against the bar."""
    goals = {
        (e.get("loop", 0), e["index"]): (e["x"], e["y"]) for e in of_type(events, "WaypointStarted")
    }
    checks = []
    for finished in of_type(events, "WaypointFinished"):
        if finished.get("outcome") != "reached":
            continue
        index = int(finished["index"])
        goal = goals.get((finished.get("loop", 0), index))
        found = nearest_pose(events, float(finished["t"]), index)
        if goal is None or found is None:
            continue
        pose, gap = found
        passed = bool(finished.get("passed_through"))
        allowed = max(radius_m or 0.0, tolerance_m) if passed else tolerance_m
        name = names[index] if index < len(names) else str(index + 1)
        distance = math.hypot(float(pose["x"]) - goal[0], float(pose["y"]) - goal[1])
        checks.append(ArrivalCheck(name, passed, distance, allowed + BAR_SLACK_M, gap))
    return checks


def first_result(events: list[Event]) -> FirstResult:
    """How the first attempt of the first waypoint ended, and how long it took."""
    started = [e for e in of_type(events, "WaypointStarted") if e.get("attempt", 1) == 1]
    if not started:
        return FirstResult("-", "", "no goal was sent", None)
    sent = float(started[0]["t"])
    index = started[0]["index"]
    ends = [
        e
        for e in events
        if e.get("type") in ("AttemptFailed", "WaypointFinished") and e.get("index") == index
    ]
    finished = [e for e in ends if e.get("type") == "WaypointFinished"]
    outcome = visit_outcome(finished[0]) if finished else "-"
    if not ends:
        return FirstResult(outcome, "", "no result", None)
    end = ends[0]
    status = str(end.get("status") or ("SUCCEEDED" if outcome != "-" else ""))
    reason = str(end.get("reason") or "")
    text = str(end.get("text") or (reason if reason != status else "") or "(no text)")
    return FirstResult(outcome, status, text, float(end["t"]) - sent)


def read_run(out: Path, record: RunRecord, radius_m: float | None, names: list[str]) -> RunRecord:
    """Fill ``record`` from the run's folder (a run refused before it began has none)."""
    journal = out / "journal.jsonl"
    if not journal.is_file():
        return record
    events = read_events(journal)
    record.mission_s = mission_seconds(events)
    record.failures = failures(events)
    record.after_false_success = outcomes_after_false_success(events)
    record.first = first_result(events)
    report_file = out / "report.json"
    if report_file.is_file():
        report = json.loads(report_file.read_text(encoding="utf-8"))
        navigator = report.get("navigator", {})
        record.robot = str(navigator.get("robot_source") or navigator.get("robot") or "")
        record.tolerance_m = tolerance_from(record.robot)
        record.recoveries = sum(
            int(attempt.get("recoveries") or 0)
            for visit in report.get("visits", [])
            for attempt in visit.get("attempts", [])
        )
    if record.tolerance_m is not None:
        record.arrivals = arrival_checks(events, record.tolerance_m, radius_m, names)
    return record


__all__ = [
    "BAR_SLACK_M",
    "ArrivalCheck",
    "Failure",
    "FirstResult",
    "RunRecord",
    "arrival_checks",
    "first_result",
    "nearest_pose",
    "read_run",
    "tolerance_from",
]
