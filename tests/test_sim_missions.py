"""Whole missions on the simulator through the executor: policies as a user sees them."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import pytest

from navseq.executor.events import WaypointOutcome
from navseq.executor.runner import run_mission
from navseq.geometry import Pose2D
from navseq.mission import FailureAction, Mission, Policy, Waypoint, load_mission
from navseq.navigators.sim import SimNavigator

ROOT = Path(__file__).resolve().parents[1]
MAP = ROOT / "maps" / "turtlebot3_world.yaml"
START = Pose2D(-2.0, -0.5, 0.0)


def sim() -> SimNavigator:
    return SimNavigator.from_map(MAP, START)


def speed_near(nav: SimNavigator, x: float, y: float, radius: float) -> float:
    """Lowest speed between recorded poses within ``radius`` of x, y (a stop shows as a gap)."""
    track = nav.trajectory
    speeds = []
    for (t0, x0, y0), (t1, x1, y1) in itertools.pairwise(track):
        if math.hypot(x0 - x, y0 - y) <= radius:
            speeds.append(math.hypot(x1 - x0, y1 - y0) / (t1 - t0))
    assert speeds, "the robot never came near"
    return min(speeds)


def test_example_mission_reaches_every_waypoint_without_collision() -> None:
    mission = load_mission(ROOT / "examples" / "turtlebot3_world.yaml")
    assert mission.map is not None and mission.start is not None
    nav = SimNavigator.from_map(mission.map, mission.start)
    result = run_mission(mission, nav)
    assert result.success and result.exit_code == 0
    assert len(result.visits) >= 6
    assert all(v.outcome is WaypointOutcome.REACHED and v.attempts == 1 for v in result.visits)
    assert nav.world.collisions == 0
    last = mission.waypoints[-1]
    pose = nav.robot_pose()
    assert pose is not None and math.hypot(pose.x - last.x, pose.y - last.y) <= 0.05


def test_pass_through_keeps_the_robot_moving() -> None:
    waypoints = (
        Waypoint(-0.55, -1.75, yaw_rad=0.0, name="corner"),
        Waypoint(1.75, -0.55, yaw_rad=math.pi / 2, name="end"),
    )
    passing = Mission(waypoints, defaults=Policy(pass_through_m=0.3))
    stopping = Mission(waypoints, defaults=Policy(pass_through_m=None))
    nav_passing, nav_stopping = sim(), sim()
    result_passing = run_mission(passing, nav_passing)
    result_stopping = run_mission(stopping, nav_stopping)
    assert result_passing.success and result_stopping.success
    assert result_passing.visits[0].passed_through
    assert not result_passing.visits[1].passed_through  # the last point always stops
    assert speed_near(nav_passing, -0.55, -1.75, 0.3) > 0.1
    assert speed_near(nav_stopping, -0.55, -1.75, 0.3) < 0.02
    assert result_passing.duration <= result_stopping.duration


def test_goal_timeout_cancels_and_skips_to_the_next_waypoint() -> None:
    mission = Mission(
        (
            Waypoint(1.75, 1.0, yaw_rad=0.0, name="far", overrides={"goal_timeout_s": 5.0}),
            Waypoint(-1.75, 0.55, yaw_rad=0.0, name="near"),
        ),
        defaults=Policy(on_failure=FailureAction.SKIP),
    )
    nav = sim()
    result = run_mission(mission, nav)
    far, near = result.visits
    assert far.outcome is WaypointOutcome.SKIPPED and far.reason == "timeout"
    assert far.duration == pytest.approx(5.0, abs=0.3)
    assert near.outcome is WaypointOutcome.REACHED
    assert not result.success and result.exit_code == 1


def test_unreachable_waypoint_is_retried_then_skipped() -> None:
    mission = Mission(
        (
            Waypoint(1.1, 1.1, yaw_rad=0.0, name="in-a-pillar"),
            Waypoint(-0.55, -1.75, yaw_rad=0.0, name="south"),
        ),
        defaults=Policy(retries=2, clear_costmaps_on_retry=True, on_failure=FailureAction.SKIP),
    )
    nav = sim()
    result = run_mission(mission, nav)
    pillar, south = result.visits
    assert pillar.outcome is WaypointOutcome.SKIPPED
    assert pillar.attempts == 3
    assert pillar.reason == "ABORTED"
    assert south.outcome is WaypointOutcome.REACHED


def test_stop_policy_ends_the_mission_at_the_first_failure() -> None:
    mission = Mission(
        (
            Waypoint(0.0, 0.0, yaw_rad=0.0, name="centre-pillar"),
            Waypoint(-0.55, -1.75, yaw_rad=0.0, name="south"),
        ),
        defaults=Policy(on_failure=FailureAction.STOP),
    )
    nav = sim()
    result = run_mission(mission, nav)
    assert [v.outcome for v in result.visits] == [WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN]
    assert nav.robot_pose() == START  # it never moved
