"""The mission ETA: the leg-duration model, the prediction before the start, the live time
to go in ``--json`` and the display, and the report's prediction against the actual end.

The accuracy promised (within 3 % on the simulator) is measured by
``benchmarks/bench_eta.py``; the bounds here are looser, so that a test fails on a broken
model, not on a machine's noise.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from cli_support import EXAMPLES, TURTLEBOT3_MAP, navseq, printed_events, write_mission
from navseq.eta.drive import DriveModel, drive_path, turn_time, turn_until
from navseq.eta.live import EtaEstimator
from navseq.eta.predict import MissionPrediction, TaskTime, predict_legs, predict_mission
from navseq.eta.text import format_duration
from navseq.geometry import Pose2D
from navseq.mission import load_mission
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.route.legs import StraightLegs

EXAMPLE = EXAMPLES / "turtlebot3_world.yaml"
MODEL = DriveModel.of(DEFAULT_PROFILE)  # the burger: 0.22 m/s, 2.5 m/s², turns at 2 rad/s


def straight_seconds(length: float) -> float:
    """A straight leg from rest to rest, by hand: the speed ramps up at ``accel`` (losing
    v / 2a against cruising), the robot arrives ``latch`` short of the end (it will rest
    within the goal tolerance) and then stops at ``accel``."""
    v, a = MODEL.max_speed, MODEL.accel
    latch = MODEL.xy_tolerance / (1.0 + MODEL.approach_decel / a)
    return (length - latch) / v + v / (2.0 * a) + v / a


def test_a_straight_leg_takes_its_length_at_top_speed_plus_starting_and_stopping() -> None:
    driven = drive_path([(0.0, 0.0), (2.0, 0.0)], MODEL, start_heading=0.0, goal_yaw=0.0)
    # The braking profile before the goal costs a few hundredths more than the sum.
    assert driven.duration_s == pytest.approx(straight_seconds(2.0), abs=0.05)
    assert driven.end_speed == 0.0


def test_turning_in_place_is_a_trapezoid_in_turn_rate() -> None:
    # Up to 2 rad/s at 3.2 rad/s², down at 2 rad/s²: 0.625 s + 1 s of ramps covering
    # 1.625 rad, the rest of a half turn at 2 rad/s.
    assert turn_time(math.pi, MODEL) == pytest.approx(0.625 + 1.0 + (math.pi - 1.625) / 2.0)
    # Too small to reach the top rate: a triangle.
    peak = math.sqrt(2 * 0.5 * 3.2 * 2.0 / 5.2)
    assert turn_time(0.5, MODEL) == pytest.approx(peak / 3.2 + peak / 2.0)


def test_a_leg_behind_the_robot_costs_a_turn_in_place_and_the_goal_yaw_another() -> None:
    ahead = drive_path([(0.0, 0.0), (2.0, 0.0)], MODEL, start_heading=0.0, goal_yaw=0.0)
    behind = drive_path([(0.0, 0.0), (2.0, 0.0)], MODEL, start_heading=math.pi, goal_yaw=0.0)
    # The controller turns in place until the path is within rotate_until of its heading.
    assert behind.duration_s - ahead.duration_s == pytest.approx(
        turn_until(math.pi, MODEL.rotate_until, MODEL), abs=0.05
    )
    facing_up = drive_path([(0.0, 0.0), (2.0, 0.0)], MODEL, start_heading=0.0, goal_yaw=math.pi / 2)
    assert facing_up.duration_s - ahead.duration_s == pytest.approx(
        turn_until(math.pi / 2, MODEL.yaw_tolerance, MODEL), abs=0.01
    )


def test_a_pass_through_point_keeps_the_speed_and_ends_at_its_radius() -> None:
    passing = drive_path(
        [(0.0, 0.0), (2.0, 0.0)], MODEL, start_heading=0.0, goal_yaw=math.pi, pass_radius=0.3
    )
    assert passing.end_speed == pytest.approx(MODEL.max_speed)
    assert passing.end_point[0] == pytest.approx(1.7, abs=0.03)
    # No stop, no turn to the goal's yaw: the ramp up only.
    v, a = MODEL.max_speed, MODEL.accel
    assert passing.duration_s == pytest.approx(1.7 / v + v / (2 * a), abs=0.15)


def test_the_mission_adds_loops_and_dwell_and_the_upper_bound_adds_task_timeouts() -> None:
    mission = load_mission(EXAMPLE)
    once = predict_mission(mission, StraightLegs(), MODEL, mission.start)
    twice = predict_mission(
        mission.__class__(**{**mission.__dict__, "loops": 2}), StraightLegs(), MODEL, mission.start
    )
    assert once.expected_s is not None and twice.expected_s is not None
    # The second loop starts at home, not at the start pose: close to the first, not equal.
    assert twice.expected_s == pytest.approx(2 * once.expected_s, rel=0.2)
    assert once.upper_s == once.expected_s  # no tasks: nothing to wait longer for
    with_tasks = predict_mission(
        mission, StraightLegs(), MODEL, mission.start, task_times=lambda i, w: TaskTime(2.0, 5.0)
    )
    assert with_tasks.expected_s == pytest.approx(once.expected_s + 7 * 2.0)
    assert with_tasks.upper_s == pytest.approx(once.expected_s + 7 * 5.0)


def test_a_patrol_that_loops_forever_has_no_end_but_a_period() -> None:
    patrol = load_mission(EXAMPLES / "patrol.yaml")
    prediction = predict_mission(patrol, StraightLegs(), MODEL, patrol.start)
    assert prediction.expected_s is None and prediction.upper_s is None
    assert prediction.loop_expected_s > 10.0
    estimator = EtaEstimator(prediction)
    assert estimator.eta_s is None


def test_durations_read_as_people_say_them() -> None:
    assert format_duration(42.4) == "42 s"
    assert format_duration(70.1) == "1 min 10 s"
    assert format_duration(7325) == "2 h 02 min"
    assert format_duration(None) == "-"


def test_the_example_s_eta_on_the_simulator_is_close_before_the_start_and_halfway() -> None:
    from navseq.run import RunRequest, prepare

    session = prepare(RunRequest(mission=EXAMPLE, outputs=None))
    session.run()
    estimator = session.eta()
    assert estimator is not None
    accuracy = estimator.accuracy()
    assert accuracy is not None
    by_percent = {check["at_percent"]: check for check in accuracy["checkpoints"]}
    assert set(by_percent) == {0, 25, 50, 75}
    # bench_eta.py measures within 3 %; a broken model is far off.
    assert abs(by_percent[0]["error_percent"]) < 15.0
    assert abs(by_percent[50]["error_percent"]) < 15.0


def test_plan_and_validate_print_the_expected_duration_and_upper_bound(tmp_path: Path) -> None:
    prediction = predict_legs(
        load_mission(EXAMPLE), StraightLegs(), DEFAULT_PROFILE, load_mission(EXAMPLE).start
    )
    assert prediction.expected_s is not None
    for command in ("plan", "validate"):
        done = navseq(command, EXAMPLE, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        assert "expected duration: ~1 min" in done.stdout
        assert "upper bound: " in done.stdout
    route = json.loads(navseq("plan", EXAMPLE, "--json", cwd=tmp_path).stdout)
    assert 50.0 < route["expected_duration_s"] < 90.0
    assert route["upper_bound_s"] == route["expected_duration_s"]
    assert all(leg["drive_s"] > 0 for leg in route["legs"])
    assert sum(leg["drive_s"] for leg in route["legs"]) == pytest.approx(
        route["expected_duration_s"], abs=0.5
    )


def test_json_progress_carries_the_time_to_go_and_the_report_its_accuracy(
    tmp_path: Path,
) -> None:
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {x: 0.5, y: -1.6, yaw: 0, dwell: 2}\n  - {x: 1.6, y: 0.5, yaw: 90}\n",
        f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n",
    )
    done = navseq("run", mission, "--json", "--out", tmp_path / "out", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    progress = printed_events(done.stdout, "WaypointProgress")
    etas = [record["eta_s"] for record in progress]
    assert all(eta is not None and eta >= 0 for eta in etas)
    assert etas[0] > 10.0 and etas[-1] < 2.0  # counts down to the end
    assert all(record["eta_upper_s"] >= record["eta_s"] for record in progress)
    finished = printed_events(done.stdout, "MissionFinished")[0]["t_s"]
    # Halfway, the time to go is within a few seconds of what it was.
    halfway = min(progress, key=lambda record: abs(record["t_s"] - finished / 2))
    assert halfway["t_s"] + halfway["eta_s"] == pytest.approx(finished, rel=0.15)
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    eta = report["eta"]
    assert eta["actual_s"] == pytest.approx(finished, abs=0.1)
    assert [check["at_percent"] for check in eta["checkpoints"]] == [0, 25, 50, 75]
    for check in eta["checkpoints"]:
        assert check["error_s"] == pytest.approx(check["predicted_s"] - eta["actual_s"], abs=0.11)
        assert abs(check["error_percent"]) < 15.0


def test_the_log_lines_say_when_the_mission_ends() -> None:
    import io

    from navseq.executor.events import MissionStarted, WaypointProgress, WaypointStarted
    from navseq.sinks.progress import LogProgress

    mission = load_mission(EXAMPLE)
    estimator = EtaEstimator(predict_mission(mission, StraightLegs(), MODEL, mission.start))
    out = io.StringIO()
    log = LogProgress(mission, out, progress_period=0.0, eta=estimator)
    for event in (
        MissionStarted(0.0, 7, 1),
        WaypointStarted(0.0, 0, 0, 1, 1, -0.55, -1.75, 0.0),
        WaypointProgress(0.5, 0, -1.9, -0.55, 0.0, 1.5, 0.1),
    ):
        estimator(event)
        log(event)
    assert "; mission ends in ~" in out.getvalue()


def test_a_huge_mission_plans_its_first_visits_and_paces_the_rest() -> None:
    from navseq.eta.text import prediction_lines

    mission = load_mission(EXAMPLE)
    whole = predict_mission(mission, StraightLegs(), MODEL, mission.start)
    paced = predict_mission(mission, StraightLegs(), MODEL, mission.start, planned_visits=3)
    assert paced.paced == 4 and whole.paced == 0
    assert whole.expected_s is not None and paced.expected_s is not None
    # The last 4 legs at the seconds per metre of the first 3: close, not equal.
    assert paced.expected_s == pytest.approx(whole.expected_s, rel=0.3)
    assert paced.expected_s != whole.expected_s
    assert (
        "the last 4 legs at the pace of the first 3" in prediction_lines(paced, has_start=True)[0]
    )


def test_the_ros_status_messages_carry_the_time_to_go() -> None:
    from navseq.executor.events import MissionStarted, WaypointProgress, WaypointStarted
    from navseq.sinks.mission_status import MissionStatus

    mission = load_mission(EXAMPLE)
    estimator = EtaEstimator(predict_mission(mission, StraightLegs(), MODEL, mission.start))
    status = MissionStatus(mission)
    status.eta = estimator
    update = None
    for event in (
        MissionStarted(0.0, 7, 1),
        WaypointStarted(0.0, 0, 0, 1, 1, -0.55, -1.75, 0.0),
        WaypointProgress(0.5, 0, -1.9, -0.55, 0.0, 1.5, 0.1),
    ):
        estimator(event)
        update = status.update(event)
    assert update is not None
    assert update.status["eta_s"] == pytest.approx(estimator.eta_s, abs=0.05)
    assert update.status["eta_upper_s"] >= update.status["eta_s"] > 30.0


def test_without_a_start_pose_the_first_leg_is_counted_from_the_robot_s_first_pose() -> None:
    import dataclasses

    from navseq.executor.events import MissionStarted, WaypointProgress, WaypointStarted

    mission = dataclasses.replace(load_mission(EXAMPLE), start=None)  # as a ROS node has it
    startless = predict_mission(mission, StraightLegs(), MODEL, None)
    assert startless.first_loop[0].drive_s == 0.0  # nowhere to drive from

    def from_pose(pose: Pose2D) -> MissionPrediction:
        return predict_mission(mission, StraightLegs(), MODEL, pose)

    estimator = EtaEstimator(startless, from_pose)
    for event in (
        MissionStarted(0.0, 7, 1),
        WaypointStarted(0.0, 0, 0, 1, 1, -0.55, -1.75, 0.0),
        WaypointProgress(0.1, 0, -2.0, -0.5, 0.0, 1.9, 0.0),
    ):
        estimator(event)
    assert startless.expected_s is not None and estimator.eta_s is not None
    assert estimator.eta_s > startless.expected_s + 5.0  # the way to waypoint 1 counts
    assert estimator.prediction.first_loop[0].drive_s > 5.0


def test_a_missions_own_tasks_count_wait_as_expected_and_timeouts_as_the_bound() -> None:
    """``wait: 2`` is two seconds expected; a run with ``timeout: 20`` may take twenty;
    an operator's input without timeout leaves no upper bound."""
    from navseq.eta.predict import time_of_tasks
    from navseq.mission.tasks import InputTask, RunTask, WaitTask

    assert time_of_tasks([]) == TaskTime(0.0, 0.0)
    timed = time_of_tasks([WaitTask(2.0), RunTask(argv=("true",), timeout_s=20.0)])
    assert timed == TaskTime(2.0, 22.0)
    assert time_of_tasks([InputTask(prompt="ok?")]).upper_s == float("inf")


def test_plan_counts_the_example_missions_tasks(tmp_path: Path) -> None:
    done = navseq("plan", str(EXAMPLES / "tasks.yaml"), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    plan = json.loads(done.stdout)
    # 2 s of wait at north-dock expected; 60 + 20 + 2 + 300 s of task timeouts at most.
    assert plan["upper_bound_s"] - plan["expected_duration_s"] == pytest.approx(380.0, abs=1.0)
