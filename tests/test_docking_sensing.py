"""The docking topics' content without ROS (:mod:`navseq.ros2.docking`): the simulated
detector sees the dock from the robot's true pose, the docking server's filtered
estimate is that sighting in the odom frame through Nav2's pose filter (so it carries
the odometry's error), and the controller's projected trajectory leads to the dock.
Robot at (-1.3, -0.5) facing +x, 0.8 m before a dock at (-0.5, -0.5) facing +x."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from navseq.geometry import Pose2D, compose
from navseq.ros2.docking import DockingServer, DockState, PoseFilter
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.docks import Dock
from navseq.sim.occupancy import load_map
from navseq.sim.world import SimWorld

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
DOCK = Dock("home_dock", "simple_charging_dock", "map", Pose2D(-0.5, -0.5, 0.0))


def _docking(drift: float = 0.0) -> tuple[Nav2StandIn, DockingServer]:
    standin = Nav2StandIn(SimWorld(load_map(MAP), Pose2D(-1.3, -0.5, 0.0)), odom_drift=drift)
    server = DockingServer(standin, [DOCK])
    standin.drivers.append(server)
    server.dock(standin.time, dock_id="home_dock", navigate_to_staging=False)
    return standin, server


def test_the_detector_sees_the_dock_ahead_and_the_estimate_stays_on_it() -> None:
    standin, server = _docking()
    robot = standin.world.robot.pose
    sighting = server.sighting(standin.time, robot, standin.localization.odom_pose)
    assert sighting is not None
    assert (sighting.detected.x, sighting.detected.y) == pytest.approx((0.8, 0.0))
    # odom starts at the start pose: the dock is 0.8 m ahead of odom's origin.
    assert (sighting.filtered.x, sighting.filtered.y) == pytest.approx((0.8, 0.0))
    trajectory = server.trajectory(robot)
    assert trajectory is not None and trajectory[0] == Pose2D(0.0, 0.0, 0.0)
    # 5 s ahead at 0.15 m/s, slowing in the last 0.15 m: straight on, short of the dock.
    assert len(trajectory) == 51
    assert trajectory[-1].y == pytest.approx(0.0)
    assert 0.7 < trajectory[-1].x < sighting.detected.x


def test_with_drifting_odometry_the_filtered_dock_carries_the_localisation_error() -> None:
    standin, server = _docking(drift=0.2)
    goal = server.active
    assert goal is not None and goal.state is DockState.CONTROLLING
    for _ in range(60):  # 3 s of docking: the robot drives 0.45 m, odometry reads more
        standin.step()
    localization = standin.localization
    sighting = server.sighting(standin.time, standin.world.robot.pose, localization.odom_pose)
    assert sighting is not None
    believed_dock = compose(localization.estimate, sighting.filtered)
    assert believed_dock.distance_to(DOCK.pose) > 0.02  # where the robot believes it is
    detected_in_map = compose(standin.world.robot.pose, sighting.detected)
    assert detected_in_map.distance_to(DOCK.pose) < 1e-6  # the sensor sees the truth


def test_nav2s_pose_filter_moves_a_tenth_of_the_way_and_restarts_after_a_timeout() -> None:
    pose_filter = PoseFilter(coef=0.1, timeout=1.0)
    assert pose_filter.update(Pose2D(1.0, 0.0, 0.0), 0.0) == Pose2D(1.0, 0.0, 0.0)
    moved = pose_filter.update(Pose2D(2.0, 0.0, math.pi / 2), 0.1)
    assert (moved.x, moved.yaw) == pytest.approx((1.1, math.pi / 20))
    assert pose_filter.update(Pose2D(5.0, 0.0, 0.0), 2.0) == Pose2D(5.0, 0.0, 0.0)


def test_nothing_is_sensed_when_no_docking_approaches() -> None:
    standin, server = _docking()
    assert server.active is not None
    server.cancel(server.active)
    robot = standin.world.robot.pose
    assert server.sighting(standin.time, robot, standin.localization.odom_pose) is None
    assert server.trajectory(robot) is None
