"""Nav2's collision monitor in the stand-in, without ROS: its polygons' rules
(:mod:`navseq.sim.collision_monitor`) and what they do to the simulated robot when a
command would drive it into a wall (:class:`navseq.ros2.standin.Nav2StandIn`)."""

from __future__ import annotations

import numpy as np
import pytest

from navseq.geometry import Pose2D
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.collision_monitor import (
    ActionType,
    CollisionMonitor,
    MonitorPolygon,
    nav2_bringup_polygons,
    points_inside,
)
from navseq.sim.footprint import TURTLEBOT3_BURGER
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.world import SimWorld

FOOTPRINT = TURTLEBOT3_BURGER.polygon  # front edge 0.041 m ahead of the centre
STOP_BOX = np.array([[0.3, 0.2], [0.3, -0.2], [0.0, -0.2], [0.0, 0.2]])


def wall_at(x: float) -> np.ndarray:
    """Points of a wall across the robot's way, ``x`` metres ahead (robot frame)."""
    ys = np.linspace(-0.5, 0.5, 41)
    return np.column_stack((np.full_like(ys, x), ys))


def test_points_inside_counts_by_the_crossing_rule() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    points = np.array([[0.5, 0.5], [0.2, 0.9], [1.5, 0.5], [-0.1, 0.2], [0.5, 1.2]])
    assert points_inside(square, points) == 2
    assert points_inside(square, np.empty((0, 2))) == 0


def test_a_stop_polygon_stops_a_command_and_says_so_until_toggled_off() -> None:
    monitor = CollisionMonitor(
        (MonitorPolygon("PolygonStop", ActionType.STOP, STOP_BOX, min_points=4),), FOOTPRINT
    )
    free = monitor.check(0.2, 0.1, wall_at(1.0))
    assert (free.v, free.w, free.action) == (0.2, 0.1, ActionType.DO_NOTHING)
    stopped = monitor.check(0.2, 0.1, wall_at(0.25))
    assert (stopped.v, stopped.w) == (0.0, 0.0)
    assert (stopped.action, stopped.polygon) == (ActionType.STOP, "PolygonStop")
    assert [change.polygon for change in monitor.changes] == ["PolygonStop"]
    monitor.enabled = False  # collision_monitor/toggle enable: false
    passed = monitor.check(0.2, 0.1, wall_at(0.25))
    assert (passed.v, passed.w, passed.action) == (0.2, 0.1, ActionType.DO_NOTHING)


def test_slowdown_and_limit_polygons_scale_the_command() -> None:
    slow = CollisionMonitor(
        (MonitorPolygon("Slow", ActionType.SLOWDOWN, STOP_BOX, slowdown_ratio=0.3),), FOOTPRINT
    ).check(0.2, 1.0, wall_at(0.25))
    assert (slow.v, slow.w) == pytest.approx((0.06, 0.3))
    limit = CollisionMonitor(
        (MonitorPolygon("Limit", ActionType.LIMIT, STOP_BOX, linear_limit=0.1),), FOOTPRINT
    ).check(0.2, 1.0, wall_at(0.25))
    assert (limit.v, limit.w) == pytest.approx((0.1, 0.5))  # the curvature is kept


def test_footprint_approach_slows_in_proportion_to_the_time_left() -> None:
    monitor = CollisionMonitor(nav2_bringup_polygons(), FOOTPRINT)
    far = monitor.check(0.2, 0.0, wall_at(1.0))  # 4.8 s away: more than 1.2 s
    assert far.action is ActionType.DO_NOTHING and far.v == 0.2
    near = monitor.check(0.2, 0.0, wall_at(0.041 + 0.13))  # about 0.6 s away
    assert near.action is ActionType.APPROACH and near.polygon == "FootprintApproach"
    assert 0.2 * 0.4 / 1.2 <= near.v <= 0.2 * 0.7 / 1.2
    touching = monitor.check(0.2, 0.0, wall_at(0.05))  # within the first 0.1 s step
    assert touching.v == 0.0
    backing_away = monitor.check(-0.2, 0.0, wall_at(0.05))
    assert backing_away.v == -0.2


def _corridor() -> OccupancyGrid:
    """A 4 m x 1 m free strip walled all round, 5 cm cells; the far wall at x = 3.5."""
    data = np.zeros((24, 84), dtype=np.int8)
    data[:2, :] = data[-2:, :] = 100
    data[:, :2] = 100
    data[:, 72:] = 100  # x >= 3.6 - 0.1: the wall's face at x = 3.5
    return OccupancyGrid(data, 0.05, Pose2D(-0.1, -0.6, 0.0))


def _drive_at_the_wall(enabled: bool) -> tuple[float, int, list[ActionType]]:
    """Teleop through the monitor at 0.2 m/s towards the wall for 20 s: where the
    robot's front ends, how often the body refused a move, the monitor's states."""
    standin = Nav2StandIn(SimWorld(_corridor(), Pose2D(2.5, 0.0, 0.0)))
    standin.monitor.monitor.enabled = enabled
    states: list[ActionType] = []
    for _ in range(400):
        standin.command_smoothed(0.2, 0.0)
        standin.step()
        states += [change.action for change in standin.monitor.monitor.changes]
        standin.monitor.monitor.changes.clear()
    front = standin.world.robot.pose.x + 0.041
    return front, standin.world.collisions, states


def test_the_monitor_stops_the_robot_short_of_a_wall_and_toggled_off_lets_it_hit() -> None:
    front, refused, states = _drive_at_the_wall(enabled=True)
    assert 3.5 - 0.05 < front < 3.5
    assert refused == 0
    assert states[0] is ActionType.APPROACH
    front_off, refused_off, states_off = _drive_at_the_wall(enabled=False)
    assert refused_off > 0  # it drove on until the body refused to enter the wall
    assert front_off > front
    assert states_off == []
