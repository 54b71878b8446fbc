"""navseq against the real Nav2 (Jazzy) on Nav2's loopback simulator.

The stand-in (``navseq sim --ros2``) is navseq's own reading of Nav2; these tests hold
navseq's word against the real servers: bt_navigator with its default tree, NavFn, Regulated
Pure Pursuit, the behaviour server, the goal checker's 0.25 m tolerance read from Nav2's own
parameters. One bringup serves the module (it takes about 10 s and four processes' worth
of CPU); every test puts the robot back at its start first. Skipped with the reason where
the real Nav2 tree is not unpacked (``scripts/install-nav2.sh``); ``.ci/run`` unpacks it and
sets ``NAVSEQ_EXPECT_NAV2=1``, which turns that skip into a failure.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cli_support import NAVSEQ, TURTLEBOT3_MAP, write_mission
from nav2_behavior_cases import CASES, BehaviorCase
from nav2_real_support import RealNav2, nav2_missing_reason
from test_ros2_sim import client_command

pytestmark = [pytest.mark.ros2, pytest.mark.slow]

MISSING = nav2_missing_reason()
START = (-2.0, -0.5, 0.0)
# Nav2's goal checker (nav2_bringup: 0.25 m), read by navseq from controller_server.
NAV2_XY_TOLERANCE = 0.25
SLACK = 0.10  # issue 16's bar: no visit recorded reached farther than tolerance + 0.1 m
RUN_TIMEOUT = 240.0


def test_the_real_nav2_is_there_when_ci_unpacked_it() -> None:
    if os.environ.get("NAVSEQ_EXPECT_NAV2") != "1":
        pytest.skip("NAVSEQ_EXPECT_NAV2 is not set (CI sets it after unpacking the real Nav2)")
    assert MISSING is None, MISSING


@pytest.fixture(scope="module")
def nav2(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RealNav2]:
    if MISSING is not None:
        pytest.skip(MISSING)
    stack = RealNav2(TURTLEBOT3_MAP, tmp_path_factory.mktemp("nav2-logs"))
    try:
        stack.place(*START)
        yield stack
    finally:
        stack.stop()


@pytest.fixture
def placed(nav2: RealNav2) -> RealNav2:
    nav2.place(*START)
    return nav2


def run(nav2: RealNav2, mission: Path, out: Path, *extra: Any) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--out", str(out)]
        + [str(arg) for arg in extra],
        env=nav2.env,
        cwd=mission.parent,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
    )


def journal(out: Path) -> list[dict[str, Any]]:
    lines = (out / "journal.jsonl").read_text().splitlines()
    return [record for record in map(json.loads, lines) if record.get("kind") == "event"]


def robot_at(events: list[dict[str, Any]], t: float) -> tuple[float, float]:
    """The robot's last journaled position at or before ``t``."""
    poses = [(e["x"], e["y"]) for e in events if e["type"] == "WaypointProgress" and e["t"] <= t]
    return poses[-1]


def test_stopping_at_each_waypoint_reaches_every_one_within_nav2s_tolerance(
    placed: RealNav2, tmp_path: Path
) -> None:
    mission = write_mission(
        tmp_path / "stops.yaml",
        "  - {name: gate, x: -0.55, y: -1.75, yaw: 0}\n"
        "  - {name: inner, x: 0.55, y: -0.55, yaw: 90}\n"
        "  - {name: home, x: -2.0, y: -0.5, yaw: 0}\n",
        header="defaults: {retries: 2, on_failure: stop}\n",
    )
    result = run(placed, mission, tmp_path / "out")
    assert result.returncode == 0, result.stdout + result.stderr
    # The robot navseq judges arrival by is the one Nav2 drives: its tolerance is Nav2's.
    assert "robot from Nav2's parameters" in result.stderr
    assert f"tolerance {NAV2_XY_TOLERANCE:g} m" in result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert [visit["outcome"] for visit in report["visits"]] == ["reached"] * 3
    for visit in report["visits"]:
        assert visit["attempts"][-1]["status"] == "SUCCEEDED"


def test_passing_through_on_nav2_completes_and_records_no_false_success(
    placed: RealNav2, tmp_path: Path
) -> None:
    # Nav2 ends a goal that preempted another SUCCEEDED when the robot reaches the old goal
    # before its tree re-plans (1 Hz): navseq must record that as a failed attempt, retry,
    # and never call a point passed with the robot away from it.
    mission = write_mission(
        tmp_path / "pass.yaml",
        "  - {name: a, x: -0.55, y: -1.75, yaw: 0}\n"
        "  - {name: b, x: 0.55, y: -0.55, yaw: 90}\n"
        "  - {name: c, x: 0.55, y: 0.55, yaw: 180}\n"
        "  - {name: home, x: -0.55, y: 0.55, yaw: 180}\n",
        header="defaults: {retries: 2, on_failure: stop, pass_through: 0.4}\n",
    )
    out = tmp_path / "out"
    result = run(placed, mission, out)
    assert result.returncode == 0, result.stdout + result.stderr
    events = journal(out)
    finished = [e for e in events if e["type"] == "WaypointFinished"]
    assert [e["passed_through"] for e in finished] == [True, True, True, False]
    points = [(-0.55, -1.75), (0.55, -0.55), (0.55, 0.55), (-0.55, 0.55)]
    for event, (x, y) in zip(finished, points, strict=True):
        if event["passed_through"]:
            # Passed where the robot was within the radius: the pose that decided it.
            rx, ry = robot_at(events, event["t"])
            assert ((rx - x) ** 2 + (ry - y) ** 2) ** 0.5 <= 0.4 + SLACK, event
    for failed in (e for e in events if e["type"] == "AttemptFailed"):
        if failed["status"] == "SUCCEEDED":
            assert failed["reason"].startswith("succeeded far from goal"), failed


def test_ctrl_c_cancels_nav2s_goal_and_exits_130(placed: RealNav2, tmp_path: Path) -> None:
    mission = write_mission(tmp_path / "far.yaml", "  - {name: far, x: 1.75, y: 0.55, yaw: 0}\n")
    process = subprocess.Popen(
        [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--out", str(tmp_path / "out")],
        env=placed.env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60
        journal_path = tmp_path / "out" / "journal.jsonl"
        while time.monotonic() < deadline:
            if journal_path.exists() and '"WaypointProgress"' in journal_path.read_text():
                break
            time.sleep(0.2)
        time.sleep(2.0)  # the robot is driving
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130, stdout + stderr
    # Nav2's own log says the goal was cancelled: navseq did not just walk away.
    deadline = time.monotonic() + 10
    while "cancel" not in placed.log_tail(20000).lower() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert "cancel" in placed.log_tail(20000).lower()


def test_a_goal_inside_a_pillar_is_never_recorded_reached(placed: RealNav2, tmp_path: Path) -> None:
    # (1.1, 0.0) is inside the arena's east pillar. Nav2's planner ends within its 0.5 m
    # tolerance and the goal may end SUCCEEDED that far away: navseq must not believe it.
    mission = write_mission(
        tmp_path / "pillar.yaml",
        "  - {name: pillar, x: 1.1, y: 0.0, yaw: 0}\n",
        header="defaults: {retries: 0, on_failure: skip}\n",
    )
    result = run(placed, mission, tmp_path / "out", "--no-preflight")
    assert result.returncode == 1, result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    [visit] = report["visits"]
    assert visit["outcome"] == "skipped"
    [attempt] = visit["attempts"]
    if attempt["status"] == "SUCCEEDED":
        assert attempt["reason"].startswith("succeeded far from goal")
    else:
        # A failed server names its error_code; a tree node that timed out on a loaded
        # machine ends the goal with error_code 0 and no words, as Nav2 reports it.
        assert attempt["status"] == "ABORTED", attempt
        assert attempt["text"] == "" or "error_code" in attempt["text"], attempt


def test_a_goal_in_an_unknown_frame_fails_with_nav2s_words(
    placed: RealNav2, tmp_path: Path
) -> None:
    mission = write_mission(
        tmp_path / "frame.yaml",
        "  - {name: nowhere, x: 0.5, y: 0.0, yaw: 0}\n",
        header="frame: nowhere\ndefaults: {retries: 0, on_failure: skip, goal_timeout: 60}\n",
    )
    result = run(placed, mission, tmp_path / "out", "--no-preflight")
    assert result.returncode == 1, result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    [visit] = report["visits"]
    assert visit["outcome"] == "skipped"
    assert visit["attempts"][0]["status"] in ("ABORTED", "REJECTED"), visit


def test_a_patrol_loops_on_nav2(placed: RealNav2, tmp_path: Path) -> None:
    mission = write_mission(
        tmp_path / "patrol.yaml",
        "  - {name: south, x: -1.75, y: -1.0, yaw: 0}\n"
        "  - {name: west, x: -2.0, y: -0.5, yaw: 0}\n",
        header="loops: 2\ndefaults: {retries: 2, on_failure: stop}\n",
    )
    result = run(placed, mission, tmp_path / "out")
    assert result.returncode == 0, result.stdout + result.stderr
    events = journal(tmp_path / "out")
    finished = [
        (e["loop"], e["index"], e["outcome"]) for e in events if e["type"] == "WaypointFinished"
    ]
    assert finished == [(0, 0, "reached"), (0, 1, "reached"), (1, 0, "reached"), (1, 1, "reached")]


def manage_nodes(nav2: RealNav2, command: int) -> None:
    """Nav2's lifecycle manager: PAUSE (1) deactivates the navigation servers, RESUME (2)."""
    service = "/lifecycle_manager_navigation/manage_nodes"
    request = f"{{command: {command}}}"
    result = subprocess.run(
        ["ros2", "service", "call", service, "nav2_msgs/srv/ManageLifecycleNodes", request],
        env=nav2.env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert "success=True" in result.stdout, result.stdout + result.stderr


def test_goals_an_inactive_nav2_rejects_are_failed_attempts_saying_so(
    placed: RealNav2, tmp_path: Path
) -> None:
    mission = write_mission(
        tmp_path / "paused.yaml",
        "  - {name: a, x: -1.75, y: -1.0, yaw: 0}\n",
        header="defaults: {retries: 1, on_failure: skip}\n",
    )
    manage_nodes(placed, 1)
    try:
        result = run(placed, mission, tmp_path / "out", "--server-timeout", 10)
    finally:
        manage_nodes(placed, 2)
    assert result.returncode == 1, result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    [visit] = report["visits"]
    assert visit["outcome"] == "skipped"
    assert [a["status"] for a in visit["attempts"]] == ["REJECTED", "REJECTED"]
    assert "is bt_navigator active?" in visit["attempts"][0]["text"]


def test_preflight_checks_the_map_nav2_publishes_before_anything_moves(
    placed: RealNav2, tmp_path: Path
) -> None:
    mission = write_mission(
        tmp_path / "pillar.yaml",
        "  - {name: fine, x: -1.75, y: -1.0, yaw: 0}\n  - {name: pillar, x: 1.1, y: 0.0, yaw: 0}\n",
    )
    result = run(placed, mission, tmp_path / "out")
    assert result.returncode == 2, result.stdout + result.stderr
    assert "pre-flight on the map on /map: 384 x 384 cells" in result.stderr
    # The arena's pillars are unknown inside (as the map file says): not a place to drive to.
    assert "1 problem found" in result.stderr and "waypoint 2 'pillar'" in result.stderr
    assert not (tmp_path / "out").exists()  # nothing written, nothing moved


@pytest.mark.parametrize("case", CASES, ids=[case.name for case in CASES])
def test_the_real_behaviour_server_answers_as_the_stand_in_does(
    placed: RealNav2, case: BehaviorCase
) -> None:
    """``tests/nav2_behavior_cases.py`` against Nav2's own behaviour server: the stand-in's
    tests hold the same table, so a difference fails one side."""
    done = subprocess.run(
        client_command("behavior", (case.kind,), {"timeout": 60, **case.options}),
        env=placed.env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    shown = {key: value for key, value in seen.items() if key != "feedback"}
    assert (seen["status"], seen["error_code"]) == (case.status, case.error_code), shown
    assert case.check(seen), shown


def test_a_retrys_recoveries_run_on_nav2s_behaviour_server(
    placed: RealNav2, tmp_path: Path
) -> None:
    # A goal in an unknown frame fails at once, twice; between the attempts the real
    # behaviour server turns the robot and waits, and both costmaps are cleared.
    mission = write_mission(
        tmp_path / "recover.yaml",
        "  - {name: nowhere, x: 0.5, y: 0.0, yaw: 0}\n",
        header="frame: nowhere\ndefaults: {retries: 1, on_failure: skip, goal_timeout: 60, "
        "recovery: [spin: 90, wait: 1, clear_costmaps]}\n",
    )
    result = run(placed, mission, tmp_path / "out", "--no-preflight")
    assert result.returncode == 1, result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    [visit] = report["visits"]
    assert len(visit["attempts"]) == 2
    runs = [(r["kind"], r["outcome"]) for r in visit["recoveries_run"]]
    assert runs == [("spin", "succeeded"), ("wait", "succeeded"), ("clear_costmaps", "succeeded")]
    assert visit["recoveries_run"][1]["duration_s"] >= 1.0


def test_the_real_map_server_answers_a_bad_map_url_as_the_stand_in_does(
    nav2: RealNav2, tmp_path: Path
) -> None:
    """tests/test_ros2_world.py expects these codes of the stand-in: an empty URL 1
    (MAP_DOES_NOT_EXIST), a YAML that is not there 3 (INVALID_MAP_METADATA), a YAML whose
    image is not there 2 (INVALID_MAP_DATA). A failed load leaves the map as it was."""
    no_image = tmp_path / "no_image.yaml"
    no_image.write_text(
        "image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    script = Path(__file__).with_name("nav2") / "load_map_codes.py"
    done = subprocess.run(
        [sys.executable, str(script), "", str(tmp_path / "nowhere.yaml"), str(no_image)],
        env=nav2.env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1]) == [1, 3, 2]
