"""The sim robot node's body and its map messages, without a rosmaster (fast).

The body (:class:`navseq.sim.base.SimulatedBase`) is free of ROS, so its tests run
everywhere; only the map message tests need rospy and carry the ``ros`` marker.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D, compose
from navseq.sim.base import SimulatedBase
from navseq.sim.occupancy import OccupancyGrid


def corridor() -> OccupancyGrid:
    """A 4 m x 2 m free room (5 cm cells) with a wall across x = 3 m."""
    data = np.zeros((40, 80), dtype=np.int8)
    data[:, 60:62] = 100
    data[0, :] = data[-1, :] = 100
    data[:, 0] = data[:, -1] = 100
    return OccupancyGrid(data=data, resolution=0.05, origin=Pose2D(0.0, 0.0, 0.0))


def drive(base: SimulatedBase, v: float, w: float, seconds: float, dt: float = 0.05) -> None:
    for _ in range(round(seconds / dt)):
        base.command(v, w)
        base.step(dt)


def test_the_robot_drives_until_the_wall_and_stops_there():
    base = SimulatedBase(Pose2D(1.0, 1.0, 0.0), corridor())
    drive(base, 0.22, 0.0, 20.0)
    # The wall's face is at x = 3.0; the footprint's nose is 0.041 m ahead of the centre.
    assert 2.85 < base.pose.x < 3.0 - 0.041
    assert base.refused_steps > 0
    assert base.robot.v == 0.0


def test_without_fresh_commands_the_robot_coasts_to_a_stop():
    base = SimulatedBase(Pose2D(1.0, 1.0, 0.0), corridor(), cmd_vel_timeout=0.5)
    drive(base, 0.2, 0.0, 1.0)
    for _ in range(40):  # 2 s without any cmd_vel
        base.step(0.05)
    assert base.robot.v == 0.0
    stopped_at = base.pose.x
    base.step(0.05)
    assert base.pose.x == stopped_at


def test_teleport_moves_the_robot_and_keeps_odometry_continuous():
    base = SimulatedBase(Pose2D(1.0, 1.0, 0.0), corridor())
    drive(base, 0.2, 0.5, 2.0)
    odom_before = base.odom_pose
    assert base.teleport(Pose2D(2.0, 0.5, math.pi / 2))
    assert base.pose == Pose2D(2.0, 0.5, math.pi / 2)
    assert base.odom_pose.x == pytest.approx(odom_before.x)
    assert base.odom_pose.y == pytest.approx(odom_before.y)
    assert base.odom_pose.yaw == pytest.approx(odom_before.yaw)
    # map -> odom -> base still composes to the true pose.
    again = compose(base.map_to_odom, base.odom_pose)
    assert (again.x, again.y, again.yaw) == pytest.approx((2.0, 0.5, math.pi / 2))


def test_teleport_into_the_wall_is_refused():
    base = SimulatedBase(Pose2D(1.0, 1.0, 0.0), corridor())
    assert not base.teleport(Pose2D(3.05, 1.0, 0.0))
    assert base.pose == Pose2D(1.0, 1.0, 0.0)


def ros_conversions():
    """:mod:`navseq.ros1.conversions`, or a skip where rospy cannot be imported."""
    return pytest.importorskip("navseq.ros1.conversions", reason="rospy not importable")


@pytest.mark.ros
def test_map_message_round_trip_keeps_cells_resolution_and_origin():
    conversions = ros_conversions()
    grid = corridor()
    grid = OccupancyGrid(
        data=grid.data, resolution=0.05, origin=Pose2D(-1.0, 2.0, 0.3), source="test"
    )
    msg = conversions.grid_to_msg(grid, "map", conversions.rospy.Time(0))
    assert (msg.info.width, msg.info.height) == (80, 40)
    back = conversions.grid_from_msg(msg, source="topic /map")
    assert np.array_equal(back.data, grid.data)
    assert back.resolution == pytest.approx(0.05)
    assert (back.origin.x, back.origin.y, back.origin.yaw) == pytest.approx((-1.0, 2.0, 0.3))


@pytest.mark.ros
def test_a_truncated_map_message_is_a_clear_error():
    conversions = ros_conversions()
    msg = conversions.grid_to_msg(corridor(), "map", conversions.rospy.Time(0))
    msg.data = msg.data[:-1]
    with pytest.raises(NavseqError, match="80 x 40 cells but carries 3199"):
        conversions.grid_from_msg(msg, source="topic /map")
