"""A patrol that loops for days keeps bounded visit records, and counts every visit."""

from __future__ import annotations

import json

from helpers_executor import Harness, line_mission
from navseq.executor.events import WaypointOutcome
from navseq.executor.result import KEEP_LAST_VISITS, KEEP_NOT_REACHED_VISITS, VisitLog
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction
from navseq.sinks.report import SCHEMA_VERSION, build_report


def _patrol(visits: int, *, fail_every: int = 0) -> Harness:
    """A 3-waypoint patrol (skip on failure) run for ``visits`` visits, then interrupted."""
    mission = line_mission(3, loops=None, on_failure=FailureAction.SKIP)
    harness = Harness(mission)
    harness.start(0.0)
    t = 0.0
    for n in range(visits):
        t += 1.0
        if fail_every and n % fail_every == 0:
            harness.done("ABORTED", t)
        else:
            harness.succeed(t, pose=Pose2D(float(n % 3 + 1), 0.0, 0.0))
    harness.interrupt(t + 0.5, "interrupted: SIGINT")
    return harness


def test_a_long_patrol_lists_the_latest_visits_and_counts_all_of_them() -> None:
    harness = _patrol(5000)
    result = harness.executor.result
    # 5000 finished visits and the one the interrupt ended.
    assert result.total_visits == 5001
    assert len(result.visits) == KEEP_LAST_VISITS
    assert [(v.loop, v.index) for v in result.visits[-2:]] == [(1666, 1), (1666, 2)]
    assert result.visits[-1].outcome is WaypointOutcome.FAILED
    counts = result.outcome_counts()
    assert counts[WaypointOutcome.REACHED] == 5000 and counts[WaypointOutcome.FAILED] == 1
    per_waypoint = [(t.visits, t.reached, t.failed) for t in result.waypoints]
    assert per_waypoint == [(1667, 1667, 0), (1667, 1667, 0), (1667, 1666, 1)]


def test_visits_not_reached_are_kept_up_to_a_cap_besides_the_latest() -> None:
    harness = _patrol(3 * KEEP_NOT_REACHED_VISITS * 2, fail_every=2)
    result = harness.executor.result
    listed = result.visits
    not_reached = [v for v in listed if v.outcome is not WaypointOutcome.REACHED]
    # the earliest skipped visits up to the cap, then every visit of the latest ones
    assert len(listed) == KEEP_LAST_VISITS + KEEP_NOT_REACHED_VISITS
    assert (listed[0].loop, listed[0].index) == (0, 0)
    assert listed[0].outcome is WaypointOutcome.SKIPPED
    assert listed == sorted(listed, key=lambda v: (v.loop, v.index))
    # every other one of the latest visits was skipped, and the interrupted one failed
    assert len(not_reached) == KEEP_NOT_REACHED_VISITS + KEEP_LAST_VISITS // 2
    assert result.outcome_counts()[WaypointOutcome.SKIPPED] == 3 * KEEP_NOT_REACHED_VISITS


def test_the_report_of_a_long_patrol_says_what_it_aggregated() -> None:
    harness = _patrol(4000)
    mission = line_mission(3, loops=None, on_failure=FailureAction.SKIP)
    report = build_report(
        mission, harness.executor.result, exit_code=130, navigator={"kind": "scripted"}
    )
    report = json.loads(json.dumps(report))
    assert report["schema_version"] == SCHEMA_VERSION == 9
    assert report["totals"]["visits"] == 4001 and report["totals"]["reached"] == 4000
    assert report["visits_listed"]["listed"] == len(report["visits"]) == KEEP_LAST_VISITS
    assert report["visits_listed"]["omitted"] == 4001 - KEEP_LAST_VISITS
    assert "last 1000 visits" in report["visits_listed"]["kept"]
    assert [w["visits"] for w in report["waypoints"]] == [1334, 1334, 1333]
    assert sum(w["reached"] for w in report["waypoints"]) == 4000
    assert report["waypoints"][0]["name"] == "p1"


def test_a_small_mission_still_lists_every_visit_and_the_ones_not_run() -> None:
    mission = line_mission(3, loops=2)
    harness = Harness(mission)
    harness.start(0.0)
    harness.succeed(1.0, pose=Pose2D(1.0, 0.0, 0.0))
    harness.interrupt(2.0, "interrupted: SIGTERM")
    result = harness.executor.result
    assert [v.outcome.value for v in result.visits] == [
        "reached",
        "failed",
        "not_run",
        "not_run",
        "not_run",
        "not_run",
    ]
    report = build_report(mission, result, exit_code=143, navigator={"kind": "scripted"})
    assert report["visits_listed"] == {"listed": 6, "omitted": 0, "kept": "every visit"}
    assert report["totals"]["not_run"] == 4
    assert [w["not_run"] for w in report["waypoints"]] == [1, 1, 2]


def test_a_huge_finite_mission_counts_the_visits_it_does_not_list() -> None:
    mission = line_mission(5000, loops=1)
    log = VisitLog(mission.waypoints, mission.loops)
    result = log.result(success=False, reason="interrupted", duration=0.0, loops_completed=0)
    assert result.visits == [] and result.total_visits == 5000
    assert result.outcome_counts()[WaypointOutcome.NOT_RUN] == 5000
