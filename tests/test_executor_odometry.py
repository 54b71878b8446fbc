"""Distance driven comes from odometry when the navigator gives it, not from map poses.

amcl's map pose jumps as it corrects itself: a robot turning in place "drove" 0.16 m.
Odometry is continuous, so the executor adds up odometry poses when it has them.
"""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import pytest

from cli_support import navseq, write_mission
from helpers_executor import Harness, line_mission
from navseq.executor.runner import run_mission
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.navigators.scripted import ScriptedNavigator
from navseq.navigators.sim import SimNavigator
from navseq.sinks.report import build_report

ROOT = Path(__file__).resolve().parents[1]


def jittered(pose: Pose2D, rng: random.Random, amount: float = 0.03) -> Pose2D:
    return Pose2D(pose.x + rng.uniform(-amount, amount), pose.y + rng.uniform(-amount, amount),
                  pose.yaw)  # fmt: skip


def test_turning_in_place_with_a_jittering_map_pose_drives_no_distance() -> None:
    rng = random.Random(8)
    with_odometry, map_only = Harness(line_mission(1)), Harness(line_mission(1))
    for h in (with_odometry, map_only):
        h.start(0.0)
    for step in range(50):
        odom = Pose2D(0.0, 0.0, 0.1 * step)  # turning on the spot
        seen = jittered(odom, rng)
        with_odometry.tick(0.1 * step, seen, odom)
        map_only.tick(0.1 * step, seen)
    assert with_odometry.executor.result.distance_driven == 0.0
    assert map_only.executor.result.distance_driven > 0.5  # what the jitter made up


def test_distance_follows_odometry_whatever_frame_it_is_in() -> None:
    h = Harness(line_mission(1))
    h.start(0.0)
    rng = random.Random(3)
    for step in range(11):  # 1 m along +x in the map, along +y in the odom frame
        h.tick(0.1 * step, jittered(Pose2D(0.1 * step, 0.0), rng), Pose2D(5.0, 0.1 * step, 1.57))
    assert h.executor.result.distance_driven == pytest.approx(1.0)


def test_odometry_gone_for_a_while_is_not_counted_twice() -> None:
    h = Harness(line_mission(1))
    h.start(0.0)
    h.tick(0.0, Pose2D(0.0, 0.0), Pose2D(0.0, 0.0))
    h.tick(1.0, Pose2D(0.5, 0.0), None)  # no odometry: the map pose counts
    h.tick(2.0, Pose2D(1.0, 0.0), Pose2D(1.0, 0.0))  # back: counts from here on
    h.tick(3.0, Pose2D(1.0, 0.0), Pose2D(1.25, 0.0))
    assert h.executor.result.distance_driven == pytest.approx(0.75)


class JitteringLocalisation(ScriptedNavigator):
    """A scripted robot whose map pose jumps around like amcl's; odometry stays clean."""

    def __init__(self) -> None:
        super().__init__(speed=0.5)
        self._rng = random.Random(1)

    def robot_pose(self) -> Pose2D | None:
        pose = super().robot_pose()
        assert pose is not None
        return jittered(pose, self._rng, amount=0.02)


def test_the_runner_adds_up_odometry_when_the_navigator_has_it() -> None:
    result = run_mission(line_mission(3), JitteringLocalisation())
    assert result.success
    assert result.distance_driven == pytest.approx(3.0, abs=0.02)


def test_the_simulator_and_the_scripted_navigator_give_odometry_from_their_start() -> None:
    sim = SimNavigator.from_map(ROOT / "maps" / "turtlebot3_world.yaml", Pose2D(-2.0, -0.5, 0.0))
    assert sim.odometry_pose() == Pose2D(0.0, 0.0, 0.0)
    scripted = ScriptedNavigator(start=Pose2D(3.0, 4.0, math.pi / 2))
    odom = scripted.odometry_pose()
    assert odom is not None
    assert (odom.x, odom.y, odom.yaw) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    corner = Mission((Waypoint(-0.55, -1.75, yaw_rad=0.0),))  # 1.45 m ahead, 1.25 m right of start
    assert run_mission(corner, sim).success
    odom = sim.odometry_pose()
    assert odom is not None and (odom.x, odom.y) == pytest.approx((1.45, -1.25), abs=0.06)


# ---------------------------------------------------------------- start pose


def test_the_report_start_is_the_robots_first_pose() -> None:
    navigator = ScriptedNavigator(start=Pose2D(0.5, -0.25, 0.0))
    mission = line_mission(1)
    result = run_mission(mission, navigator)
    assert result.start_pose == Pose2D(0.5, -0.25, 0.0)
    planned = Pose2D(-2.0, -0.5, 0.0)  # what the mission file said
    report = build_report(
        mission, result, exit_code=0, navigator={}, start=planned, start_source="mission start:"
    )
    assert report["start"] == {"x": 0.5, "y": -0.25, "yaw_deg": 0.0}
    assert report["start_source"] == "robot"
    assert report["planned_start"] == {"x": -2.0, "y": -0.5, "yaw_deg": 0.0}


def test_without_a_robot_pose_the_report_start_is_the_planned_one() -> None:
    h = Harness(line_mission(1))
    h.start(0.0)
    h.succeed(1.0)
    report = build_report(
        line_mission(1), h.executor.result, exit_code=0, navigator={},
        start=Pose2D(1.0, 2.0, 0.0), start_source="--start",
    )  # fmt: skip
    assert report["start_source"] == "--start" and report["start"]["x"] == 1.0


def test_cli_report_names_where_its_start_came_from(tmp_path: Path) -> None:
    mission = write_mission(
        tmp_path / "m.yaml", "  - {x: 1.0, y: 0.0, yaw: 0}\n", header="start: {x: 0.5, y: 0.0}\n"
    )
    run = navseq(
        "run", mission, "--navigator", "scripted", "--start", "0.25,0,0",
        "--out", tmp_path / "out", cwd=tmp_path,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["start_source"] == "robot" and report["start"]["x"] == 0.25
    assert report["planned_start"]["x"] == 0.25
