"""A retry's recoveries as a user writes and runs them: the ``recovery:`` list (every
bad entry refused with its file:line), the simulator spinning and backing up the robot
with Nav2's behaviours, what the report, journal and terminal say, what a navigator
cannot run refused before anything moves, and a stopped recovery stopping the robot."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from cli_support import TURTLEBOT3_MAP, assert_clean_error, journal_events, navseq
from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission import load_mission, validate_mission_file
from navseq.mission.recovery import Recovery
from navseq.mission.writer import dump_mission_yaml
from navseq.navigators.base import RecoveryDone
from navseq.navigators.plain_recoveries import PlainRecoveries
from navseq.navigators.sim import SimNavigator
from navseq.sim.occupancy import load_map
from navseq.sim.world import SimWorld

START = Pose2D(-2.0, -0.5, 0.0)  # the TurtleBot3 arena's open start, facing +x


def mission_file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "m.yaml"
    path.write_text(text)
    return path


# --- the recovery: list ------------------------------------------------------------


def test_the_list_reads_each_kind_with_its_amount(tmp_path: Path) -> None:
    path = mission_file(
        tmp_path,
        "defaults:\n  retries: 2\n  recovery: [spin: -90, backup: 0.15, wait: 2, clear_costmaps]\n"
        "waypoints:\n  - {x: 1, y: 0}\n  - {x: 2, y: 0, recovery: [wait: 0.5]}\n",
    )
    mission = load_mission(path)
    assert mission.defaults.recoveries == (
        Recovery("spin", -90.0),
        Recovery("backup", 0.15),
        Recovery("wait", 2.0),
        Recovery("clear_costmaps"),
    )
    assert mission.policy_for(1).recoveries == (Recovery("wait", 0.5),)


def test_written_missions_read_back_with_their_recoveries(tmp_path: Path) -> None:
    path = mission_file(
        tmp_path,
        "defaults: {retries: 1, recovery: [spin: 90, clear_costmaps]}\n"
        "waypoints:\n  - {x: 1, y: 0, recovery: [backup: 0.2]}\n  - {x: 2, y: 0}\n",
    )
    mission = load_mission(path)
    again = mission_file(tmp_path / "..", dump_mission_yaml(mission))
    assert load_mission(again) == mission


def test_a_mission_without_recoveries_is_written_without_the_key(tmp_path: Path) -> None:
    mission = load_mission(mission_file(tmp_path, "waypoints:\n  - {x: 1, y: 0}\n"))
    assert "recovery" not in dump_mission_yaml(mission)


def test_every_bad_entry_is_refused_with_its_line(tmp_path: Path) -> None:
    path = mission_file(
        tmp_path,
        "defaults:\n  recovery: [spin: 0, twirl: 3]\n"
        "waypoints:\n  - {x: 1, y: 0, recovery: [backup: -1, clear_costmaps: 2, wait, 7]}\n"
        "  - {x: 2, y: 0, recovery: spin}\n",
    )
    texts = [str(e) for e in validate_mission_file(path)]
    assert texts == [
        f"{path}:2, defaults, field recovery 1 (spin): must not be 0 degrees",
        f"{path}:2, defaults, field recovery 2: unknown recovery 'twirl' "
        "(known: spin, backup, wait, clear_costmaps)",
        f"{path}:4, waypoint 1, field recovery 1 (backup): must be > 0 m, got -1",
        f"{path}:4, waypoint 1, field recovery 2: clear_costmaps takes no amount; write it "
        "alone: clear_costmaps",
        f"{path}:4, waypoint 1, field recovery 3: wait needs an amount in s: wait: <s>",
        f"{path}:4, waypoint 1, field recovery 4: must be a recovery such as spin: 90, "
        "backup: 0.15, wait: 2 or clear_costmaps, got 7",
        f"{path}:5, waypoint 2, field recovery: must be a list, got text 'spin'",
    ]


def test_validate_refuses_a_bad_recovery_with_one_clear_message(tmp_path: Path) -> None:
    mission_file(tmp_path, "waypoints:\n  - {x: 1, y: 0, recovery: [spin: 720]}\n")
    result = navseq("validate", "m.yaml", cwd=tmp_path)
    assert result.returncode == 2
    assert_clean_error(result)
    assert "m.yaml:2, waypoint 1, field recovery 1 (spin): must be within ±360 degrees" in (
        result.stderr
    )


# --- the simulator runs them on the robot --------------------------------------------


@pytest.fixture
def navigator() -> SimNavigator:
    return SimNavigator(SimWorld(load_map(TURTLEBOT3_MAP), START))


def run_until_done(navigator: SimNavigator, seconds: float = 30.0) -> RecoveryDone:
    for _ in range(round(seconds / 0.1)):
        navigator.spin(0.1)
        ended = [e for e in navigator.poll() if isinstance(e, RecoveryDone)]
        if ended:
            return ended[0]
    raise AssertionError("the recovery never ended")


def test_spin_turns_the_simulated_robot_in_place(navigator: SimNavigator) -> None:
    navigator.run_recovery(1, Recovery("spin", 90.0))
    done = run_until_done(navigator)
    assert done == RecoveryDone(1, True)
    pose = navigator.robot_pose()
    assert pose is not None
    assert math.degrees(pose.yaw) == pytest.approx(90.0, abs=5.0)
    assert math.hypot(pose.x - START.x, pose.y - START.y) < 0.02


def test_backup_drives_the_simulated_robot_backwards(navigator: SimNavigator) -> None:
    navigator.run_recovery(2, Recovery("backup", 0.15))
    assert run_until_done(navigator).succeeded
    pose = navigator.robot_pose()
    assert pose is not None
    assert START.x - pose.x == pytest.approx(0.15, abs=0.03)


def test_backup_into_a_wall_fails_with_nav2s_words() -> None:
    # Facing +x with the arena's west wall close behind.
    navigator = SimNavigator(SimWorld(load_map(TURTLEBOT3_MAP), Pose2D(-2.0, -0.5, 0.0)))
    navigator.run_recovery(3, Recovery("backup", 5.0))
    done = run_until_done(navigator, 60.0)
    assert (done.succeeded, done.detail) == (False, "COLLISION_AHEAD")


def test_a_cancelled_recovery_stops_the_robot(navigator: SimNavigator) -> None:
    navigator.run_recovery(4, Recovery("spin", 180.0))
    navigator.spin(0.5)
    navigator.cancel_recovery()
    navigator.spin(1.0)
    turned = navigator.robot_pose()
    navigator.spin(2.0)
    assert navigator.robot_pose() == turned  # at rest
    assert navigator.world.robot.w == 0.0
    assert [e for e in navigator.poll() if isinstance(e, RecoveryDone)] == []


# --- a whole run ---------------------------------------------------------------------

RUN_MISSION = f"""\
map: {TURTLEBOT3_MAP}
start: {{x: -2.0, y: -0.5, yaw: 0}}
defaults:
  goal_timeout: 3
  retries: 1
  on_failure: skip
  recovery: [spin: 90, backup: 0.1, wait: 1, clear_costmaps]
waypoints:
  - {{x: 1.5, y: -0.5}}
"""


def test_a_run_reports_and_journals_the_recoveries_before_its_retry(tmp_path: Path) -> None:
    mission_file(tmp_path, RUN_MISSION)
    result = navseq("run", "m.yaml", "--out", "out", cwd=tmp_path)
    assert result.returncode == 1, result.stderr  # the far goal times out twice
    assert "recovery 1 spin 90° before attempt 2" in result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    (visit,) = report["visits"]
    assert [(r["kind"], r["outcome"], r["attempt"]) for r in visit["recoveries_run"]] == [
        ("spin", "succeeded", 2),
        ("backup", "succeeded", 2),
        ("wait", "succeeded", 2),
        ("clear_costmaps", "succeeded", 2),
    ]
    started = journal_events(tmp_path / "out" / "journal.jsonl", "RecoveryStarted")
    assert [e["description"] for e in started] == [
        "spin 90°",
        "backup 0.1 m",
        "wait 1 s",
        "clear_costmaps",
    ]


def test_ros1_refuses_spin_and_backup_before_anything_moves(tmp_path: Path) -> None:
    mission_file(
        tmp_path,
        "defaults: {retries: 1, recovery: [wait: 1, clear_costmaps]}\n"
        "waypoints:\n  - {x: 1, y: 0}\n  - {x: 2, y: 0, recovery: [spin: 90, backup: 0.1]}\n",
    )
    result = navseq("run", "m.yaml", "--navigator", "ros1", "--out", "out", cwd=tmp_path)
    assert result.returncode == 2
    assert_clean_error(result)
    assert "m.yaml:4, waypoint 2, recovery 1: the ros1 navigator cannot run the recovery " in (
        result.stderr
    )
    assert "recovery 2: the ros1 navigator cannot run the recovery backup 0.1 m" in result.stderr
    assert not (tmp_path / "out").exists()


def test_wait_and_clear_run_without_a_behaviour_server() -> None:
    clock = [10.0]
    cleared: list[bool] = []
    plain = PlainRecoveries(lambda: clock[0], lambda: cleared.append(True))
    plain.run(1, Recovery("clear_costmaps"))
    assert plain.poll() == [RecoveryDone(1, True)] and cleared == [True]
    plain.run(2, Recovery("wait", 2.0))
    clock[0] = 11.9
    assert plain.poll() == []
    clock[0] = 12.0
    assert plain.poll() == [RecoveryDone(2, True)]
    plain.run(3, Recovery("wait", 2.0))
    plain.cancel()
    clock[0] = 20.0
    assert plain.poll() == []


def test_a_navigator_of_the_api_without_recoveries_has_them_refused(tmp_path: Path) -> None:
    from navseq.navigators.recovery_check import recovery_problems

    path = mission_file(tmp_path, "defaults: {recovery: [wait: 1]}\nwaypoints:\n  - {x: 1, y: 0}\n")
    mission = load_mission(path)
    (problem,) = recovery_problems(mission, "mine", frozenset())
    assert isinstance(problem, NavseqError)
    assert "the mine navigator cannot run the recovery wait 1 s (it runs none)" in str(problem)


def test_a_report_rebuilt_from_the_journal_lists_the_recoveries(tmp_path: Path) -> None:
    mission_file(tmp_path, RUN_MISSION)
    assert navseq("run", "m.yaml", "--out", "out", cwd=tmp_path).returncode == 1
    report = tmp_path / "out" / "report.json"
    written = json.loads(report.read_text())
    report.unlink()
    rebuilt = navseq("report", "out", cwd=tmp_path)
    assert rebuilt.returncode in (0, 1), rebuilt.stderr
    again = json.loads(report.read_text())
    assert again["visits"][0]["recoveries_run"] == written["visits"][0]["recoveries_run"]


def test_leaving_a_run_during_a_spin_stops_the_robot(tmp_path: Path) -> None:
    # What Ctrl-C does through the runner: the run ends, the recovery is cancelled first.
    from navseq.executor.events import RecoveryStarted
    from navseq.executor.runner import iter_mission

    mission = load_mission(mission_file(tmp_path, RUN_MISSION.replace("spin: 90", "spin: 270")))
    navigator = SimNavigator(SimWorld(load_map(TURTLEBOT3_MAP), START))
    events = iter_mission(mission, navigator)
    for event in events:
        if isinstance(event, RecoveryStarted):
            break
    navigator.spin(0.5)  # the spin is under way
    assert navigator.world.robot.w != 0.0
    events.close()
    navigator.spin(1.0)
    assert navigator.world.robot.w == 0.0 and navigator.world.robot.v == 0.0
