"""Differential-drive kinematics: limits, acceleration, exact arcs."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from navseq.geometry import Pose2D, normalize_angle
from navseq.sim.robot import DiffDriveLimits, DiffDriveRobot

DT = 0.05


def run(robot: DiffDriveRobot, cmd_v: float, cmd_w: float, seconds: float) -> None:
    for _ in range(round(seconds / DT)):
        robot.step(cmd_v, cmd_w, DT)


def test_straight_line_at_top_speed_after_acceleration() -> None:
    robot = DiffDriveRobot(Pose2D(1.0, 2.0, math.pi / 2))
    run(robot, 1.0, 0.0, 10.0)  # asks for more than the burger can do
    assert robot.v == pytest.approx(0.22)
    # 10 s at 0.22 m/s minus what the 0.088 s acceleration ramp lost (about 1 cm).
    assert robot.pose.y - 2.0 == pytest.approx(2.2, abs=0.015)
    assert robot.pose.y - 2.0 < 2.2
    assert robot.pose.x == pytest.approx(1.0, abs=1e-9)


def test_acceleration_limits_the_change_per_step() -> None:
    limits = DiffDriveLimits()
    robot = DiffDriveRobot(Pose2D(0.0, 0.0), limits)
    robot.step(0.22, 2.75, DT)
    assert robot.v == pytest.approx(limits.acc_v * DT)
    assert robot.w == pytest.approx(limits.acc_w * DT)
    robot.step(-0.22, -2.75, DT)  # reversing also needs time
    assert robot.v == pytest.approx(0.0)
    assert robot.w == pytest.approx(0.0)


def test_turn_in_place_keeps_position_and_respects_max_turn_rate() -> None:
    robot = DiffDriveRobot(Pose2D(0.5, -0.5, 0.0))
    run(robot, 0.0, 10.0, 2.0)
    assert robot.w == pytest.approx(2.75)
    assert (robot.pose.x, robot.pose.y) == (0.5, -0.5)
    assert -math.pi <= robot.pose.yaw < math.pi


def test_constant_command_drives_an_exact_circle() -> None:
    # Start at rest velocity already reached so the whole run is one circle.
    robot = DiffDriveRobot(Pose2D(0.0, 0.0, 0.0))
    robot.v, robot.w = 0.2, 0.5  # radius 0.4 m, centre (0, 0.4)
    period = 2 * math.pi / 0.5
    for _ in range(1000):
        robot.step(0.2, 0.5, period / 1000)
        assert math.hypot(robot.pose.x, robot.pose.y - 0.4) == pytest.approx(0.4, abs=1e-9)
    assert robot.pose.x == pytest.approx(0.0, abs=1e-9)
    assert robot.pose.y == pytest.approx(0.0, abs=1e-9)
    assert normalize_angle(robot.pose.yaw) == pytest.approx(0.0, abs=1e-9)


@given(
    v=st.floats(-0.22, 0.22),
    w=st.floats(-2.75, 2.75),
    yaw=st.floats(-math.pi, math.pi),
    dt=st.floats(0.001, 0.5),
)
def test_one_big_step_equals_many_small_ones(v: float, w: float, yaw: float, dt: float) -> None:
    """Arc integration is exact, so splitting a step changes nothing."""
    whole = DiffDriveRobot(Pose2D(0.0, 0.0, yaw))
    split = DiffDriveRobot(Pose2D(0.0, 0.0, yaw))
    whole.v, whole.w, split.v, split.w = v, w, v, w
    whole.step(v, w, dt)
    for _ in range(10):
        split.step(v, w, dt / 10)
    assert whole.pose.x == pytest.approx(split.pose.x, abs=1e-9)
    assert whole.pose.y == pytest.approx(split.pose.y, abs=1e-9)
    assert normalize_angle(whole.pose.yaw - split.pose.yaw) == pytest.approx(0.0, abs=1e-9)


def test_predict_does_not_move_and_matches_step() -> None:
    robot = DiffDriveRobot(Pose2D(0.0, 0.0, 0.3))
    predicted, v, w = robot.predict(0.2, 1.0, DT)
    assert robot.pose == Pose2D(0.0, 0.0, 0.3)
    assert robot.step(0.2, 1.0, DT) == predicted
    assert (robot.v, robot.w) == (v, w)


def test_teleport_places_the_robot_at_rest() -> None:
    robot = DiffDriveRobot(Pose2D(0.0, 0.0))
    run(robot, 0.2, 1.0, 1.0)
    robot.teleport(Pose2D(3.0, 4.0, 7.0))
    assert (robot.v, robot.w) == (0.0, 0.0)
    assert robot.pose.x == 3.0 and robot.pose.y == 4.0
    assert robot.pose.yaw == pytest.approx(normalize_angle(7.0))
