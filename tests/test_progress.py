"""Terminal progress: live panel, plain log lines and JSON lines (the table: test_summary)."""

from __future__ import annotations

import io
import math

from rich.console import Console

from navseq.executor.events import (
    AttemptFailed,
    LoopStarted,
    MissionFinished,
    MissionStarted,
    ServerStatusChanged,
    WaypointDwelling,
    WaypointFinished,
    WaypointOutcome,
    WaypointPlan,
    WaypointProgress,
    WaypointStarted,
)
from navseq.mission.model import Mission, Waypoint
from navseq.sinks.json_events import JsonProgress
from navseq.sinks.progress import (
    LiveProgress,
    LogProgress,
    RunView,
    make_progress,
)

MISSION = Mission(
    waypoints=(
        Waypoint(1.0, 0.0, yaw_rad=0.0, name="dock"),
        Waypoint(2.0, 0.0, yaw_rad=math.pi / 2),
        Waypoint(2.0, 2.0, yaw_rad=math.pi, name="desk"),
    ),
    loops=2,
    source="office.yaml",
)


def run_events() -> list:
    """A loop where waypoint 1 is reached, 2 fails once then is skipped, 3 is reached."""
    return [
        MissionStarted(0.0, 3, 2),
        LoopStarted(0.0, 0),
        WaypointStarted(0.0, 0, 0, 1, 1, 1.0, 0.0, 0.0),
        WaypointPlan(0.0, 0, ((0.0, 0.0), (1.0, 0.0))),
        WaypointProgress(0.5, 0, 0.5, 0.0, 0.0, 0.5, 0.5),
        WaypointProgress(3.0, 0, 0.8, 0.0, 0.0, 0.2, 0.8),
        WaypointProgress(12.0, 0, 0.9, 0.0, 0.0, 0.1, 0.9),
        WaypointFinished(13.0, 0, 0, WaypointOutcome.REACHED, 1, 13.0, 1.0),
        WaypointStarted(13.0, 1, 0, 1, 2, 2.0, 0.0, math.pi / 2),
        AttemptFailed(20.0, 1, 1, "ABORTED", True),
        WaypointStarted(21.0, 1, 0, 2, 3, 2.0, 0.0, math.pi / 2),
        ServerStatusChanged(22.0, False, "no heartbeat"),
        ServerStatusChanged(23.0, True),
        AttemptFailed(25.0, 1, 2, "timeout", False),
        WaypointFinished(25.0, 1, 0, WaypointOutcome.SKIPPED, 2, 12.0, 0.4, reason="timeout"),
        WaypointStarted(25.0, 2, 0, 1, 4, 2.0, 2.0, math.pi),
        WaypointProgress(26.0, 2, 2.0, 0.5, 1.0, 1.5, 0.5),
        WaypointDwelling(30.0, 2, 5.0),
        WaypointFinished(35.0, 2, 0, WaypointOutcome.REACHED, 1, 10.0, 2.0),
        MissionFinished(35.0, False, "interrupted: SIGINT"),
    ]


def test_run_view_follows_the_current_waypoint_and_counts_outcomes():
    view = RunView(MISSION)
    for event in run_events()[:12]:
        view.update(event)
    assert view.waypoint_label(view.index) == "waypoint 2/3"
    assert view.attempt == 2
    assert "server lost" in view.status
    assert view.loop_label() == "loop 1/2"
    assert view.elapsed == 22.0
    for event in run_events()[12:]:
        view.update(event)
    assert view.totals[WaypointOutcome.REACHED] == 2
    assert view.totals[WaypointOutcome.SKIPPED] == 1
    assert view.status == "interrupted: SIGINT"


def test_log_lines_say_what_happened_to_each_waypoint():
    out = io.StringIO()
    sink = LogProgress(MISSION, out, progress_period=10.0)
    with sink:
        for event in run_events():
            sink(event)
    lines = out.getvalue().splitlines()
    text = out.getvalue()
    assert "office.yaml: 3 waypoints, 2 loops" in lines[0]
    assert any("loop 1/2" in line for line in lines)
    assert "waypoint 1/3 'dock': going to (1.00, 0.00, 0°), attempt 1" in text
    assert "waypoint 2/3: attempt 1 failed (ABORTED), will retry" in text
    assert "waypoint 2/3: skipped (timeout) after 12.0 s, 0.40 m, 2 attempts" in text
    assert "waypoint 3/3 'desk': dwelling 5 s" in text
    assert "navigation server lost: no heartbeat" in text
    assert "mission finished: interrupted: SIGINT; not every waypoint reached" in lines[-1]
    # Elapsed mission time prefixes every line.
    assert lines[-1].startswith("[    35.0 s]")


def test_log_progress_lines_are_throttled_to_the_period():
    out = io.StringIO()
    sink = LogProgress(MISSION, out, progress_period=10.0)
    for event in run_events()[:8]:
        sink(event)
    progress_lines = [line for line in out.getvalue().splitlines() if "m to go" in line]
    # Feedback at 0.5 s and 3 s is within 10 s of the goal being sent; 12 s is not.
    assert progress_lines == [
        "[    12.0 s] waypoint 1/3 'dock': 0.10 m to go (~0 s at 0.22 m/s), 0.90 m driven"
    ]


def test_make_progress_is_plain_when_not_a_terminal_and_json_when_asked():
    assert isinstance(make_progress(MISSION, json_lines=False, stream=io.StringIO()), LogProgress)
    assert isinstance(make_progress(MISSION, json_lines=True, stream=io.StringIO()), JsonProgress)


def test_live_panel_shows_waypoint_status_distance_loop_and_attempt():
    console = Console(file=io.StringIO(), width=100, force_terminal=True, color_system=None)
    live = LiveProgress(MISSION, console)
    for event in run_events()[:6]:
        live(event)
    render = Console(file=io.StringIO(), width=100, record=True)
    render.print(live.render())
    text = render.export_text()
    assert "waypoint 1/3 'dock'" in text
    assert "attempt 1" in text and "driving" in text
    assert "0.20 m to go" in text
    assert "loop 1/2" in text
    assert "elapsed     3.0 s" in text
    # The latest notable event is shown under the current state.
    assert "[    0.0 s] waypoint 1/3 'dock': going to (1.00, 0.00, 0°), attempt 1" in text


def test_a_parts_panel_and_lines_number_waypoints_as_the_file_does():
    """``--from 4`` of a five-waypoint file: the part's waypoints are the file's 4 and 5."""
    import dataclasses

    from navseq.mission.part import PartSpec

    whole = dataclasses.replace(MISSION, waypoints=MISSION.waypoints + MISSION.waypoints[:2])
    part = PartSpec(first=4).select(whole).apply(whole)
    console = Console(file=io.StringIO(), width=100, force_terminal=True, color_system=None)
    live = LiveProgress(part, console)
    for event in (
        MissionStarted(0.0, 2, 1, resumed_from=1),
        WaypointStarted(0.0, 1, 0, 1, 1, 1.0, 0.0, 0.0),
        WaypointFinished(5.0, 1, 0, WaypointOutcome.FAILED, 1, 5.0, 1.0, reason="ABORTED"),
        MissionFinished(5.0, False, "stopped: waypoint 5 failed (ABORTED)"),
    ):
        live(event)
    render = Console(file=io.StringIO(), width=100, record=True)
    render.print(live.render())
    text = render.export_text()
    assert "4· 5✗" in text  # the marks under the panel
    assert "resuming at waypoint 5" in text
    assert "waypoint 5 (2/2): failed (ABORTED)" in text
    assert "waypoint 2" not in text


def test_log_lines_give_the_time_still_to_go_at_the_robots_top_speed() -> None:
    from navseq.executor.events import WaypointProgress, WaypointStarted
    from navseq.mission.robot import TURTLEBOT3_WAFFLE
    from navseq.sinks.progress import LogProgress

    stream = io.StringIO()
    log = LogProgress(MISSION, stream, progress_period=1.0, robot=TURTLEBOT3_WAFFLE)
    log(WaypointStarted(t=0.0, index=0, loop=0, attempt=1, goal_id=1, x=1.0, y=0.0, yaw=0.0))
    log(
        WaypointProgress(
            t=2.0, index=0, x=0.0, y=0.0, yaw=0.0, distance_remaining=2.6, distance_driven=0.5
        )
    )
    assert "2.60 m to go (~10 s at 0.26 m/s)" in stream.getvalue()
