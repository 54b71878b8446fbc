"""The studio's live view of a run, folded from the mission's events."""

from __future__ import annotations

from navseq.executor import events as ev
from navseq.studio.runs import LiveView


def progress(t: float) -> ev.WaypointProgress:
    return ev.WaypointProgress(
        t=t, index=0, x=t, y=0.0, yaw=0.0, distance_remaining=None, distance_driven=t
    )


def test_the_clock_holds_through_a_pause_and_does_not_jump_on_resume() -> None:
    view = LiveView(1, footprint=[])
    view(ev.MissionStarted(t=100.0, waypoint_count=1, loops=None))
    view(progress(110.0))
    view(ev.MissionPaused(t=110.0, index=0))
    assert view.clock_s == 10.0
    view(ev.MissionResumed(t=170.0, index=0, paused_for=60.0))
    assert view.clock_s == 10.0  # not 70: the minute paused is not running time
    view(progress(175.0))
    assert view.clock_s == 15.0


def test_a_visit_the_operator_stopped_shows_stopped_and_a_failed_one_failed() -> None:
    view = LiveView(2, footprint=[])
    view(ev.MissionStarted(t=0.0, waypoint_count=2, loops=None))
    failed = ev.WaypointOutcome.FAILED
    view(ev.WaypointFinished(0.0, 0, 0, failed, 3, 5.0, 1.0, reason="ABORTED"))
    view(
        ev.WaypointFinished(
            9.0, 1, 0, failed, 1, 4.0, 1.0, reason="cancelled by the operator (the studio)"
        )
    )
    assert view.waypoints == ["failed", "stopped"]
