"""A simulated robot base: commanded velocity in, pose in the map and odom frames out.

This is the body that navseq's sim robot ROS node (:mod:`navseq.ros1.sim_robot_node`)
wraps. It has no sensors and no physics beyond differential-drive kinematics
(:class:`navseq.sim.robot.DiffDriveRobot`), and it behaves like a real base driver in the
two ways a navigation stack notices: it stops when velocity commands stop coming, and
its odometry is continuous even when the robot is teleported (the ``map -> odom``
transform jumps instead, as after a localisation correction).

In a fleet the caller tells the body where the other robots are
(:meth:`SimulatedBase.set_other_robots`); it refuses to overlap them as it refuses to
overlap walls.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from navseq.geometry import Pose2D, compose, inverse
from navseq.sim.footprint import (
    TURTLEBOT3_BURGER,
    CollisionChecker,
    Footprint,
    footprints_overlap,
)
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.robot import DiffDriveLimits, DiffDriveRobot


class SimulatedBase:
    """A robot body on a map: commanded velocity in, pose (map and odom frames) out.

    ``step`` moves the robot by one time step unless that would make its footprint touch
    an obstacle, unknown space or the map edge, or overlap another robot, in which case
    the robot stops where it is and ``refused_steps`` counts the bump. Without a grid
    only other robots are refused.
    """

    def __init__(
        self,
        start: Pose2D,
        grid: OccupancyGrid | None,
        *,
        footprint: Footprint = TURTLEBOT3_BURGER,
        limits: DiffDriveLimits | None = None,
        cmd_vel_timeout: float = 0.5,
    ) -> None:
        self.footprint = footprint
        self.robot = DiffDriveRobot(start, limits)
        self.grid = grid
        self._others: list[tuple[Pose2D, Footprint]] = []
        # The odom frame is where the robot started: odometry reads (0, 0, 0) at start.
        self.map_to_odom = Pose2D(start.x, start.y, start.yaw)
        self.cmd_vel_timeout = cmd_vel_timeout
        self.time = 0.0
        self.refused_steps = 0
        self._cmd = (0.0, 0.0)
        self._cmd_time = -math.inf

    @property
    def grid(self) -> OccupancyGrid | None:
        """The map the body collides with; setting it (a map that arrived later) takes effect."""
        return self._grid

    @grid.setter
    def grid(self, grid: OccupancyGrid | None) -> None:
        self._grid = grid
        self._checker = CollisionChecker(grid, self.footprint) if grid is not None else None

    def set_other_robots(self, others: Iterable[tuple[Pose2D, Footprint]]) -> None:
        """Where the other robots are now (map frame) and their outlines; replaces the last."""
        self._others = list(others)

    @property
    def others(self) -> list[tuple[Pose2D, Footprint]]:
        """The other robots as last set (the simulated laser sees them too)."""
        return self._others

    def collides(self, pose: Pose2D) -> bool:
        """True when the footprint at ``pose`` overlaps an obstacle, unknown space, the edge,
        or another robot."""
        footprint = self.footprint
        return self._hits_map(pose) or any(
            footprints_overlap(footprint, pose, other, at) for at, other in self._others
        )

    def _hits_map(self, pose: Pose2D) -> bool:
        return self._checker is not None and self._checker.collides(pose)

    def command(self, v: float, w: float) -> None:
        """A new velocity command, valid for ``cmd_vel_timeout`` seconds of sim time."""
        self._cmd = (v, w)
        self._cmd_time = self.time

    def step(self, dt: float) -> bool:
        """Advance ``dt`` seconds; False when the move was refused (the robot bumped)."""
        self.time += dt
        fresh = self.time - self._cmd_time <= self.cmd_vel_timeout
        cmd_v, cmd_w = self._cmd if fresh else (0.0, 0.0)
        pose, v, w = self.robot.predict(cmd_v, cmd_w, dt)
        if self._hits_map(pose) or (self._others and self._bumps_other_robot(pose)):
            self.robot.stop()
            self.refused_steps += 1
            return False
        self.robot.pose, self.robot.v, self.robot.w = pose, v, w
        return True

    def _bumps_other_robot(self, pose: Pose2D) -> bool:
        """True if moving to ``pose`` runs into another robot.

        Two robots that already overlap (one was teleported onto the other from a stale
        pose, or they were started on top of each other) may still move apart, or both
        would be stuck for good.
        """
        footprint, here = self.footprint, self.robot.pose
        for at, other in self._others:
            if not footprints_overlap(footprint, pose, other, at):
                continue
            separating = math.hypot(pose.x - at.x, pose.y - at.y) > math.hypot(
                here.x - at.x, here.y - at.y
            )
            if not (separating and footprints_overlap(footprint, here, other, at)):
                return True
        return False

    def teleport(self, pose: Pose2D) -> bool:
        """Put the robot at ``pose`` (map frame), keeping odometry continuous.

        Returns False (and leaves the robot alone) when ``pose`` is in collision, also
        with another robot.
        """
        if self.collides(pose):
            return False
        odom_pose = self.odom_pose
        self.robot.teleport(pose)
        self.map_to_odom = compose(pose, inverse(odom_pose))
        self._cmd = (0.0, 0.0)
        return True

    @property
    def pose(self) -> Pose2D:
        """The robot's true pose in the map frame."""
        return self.robot.pose

    @property
    def odom_pose(self) -> Pose2D:
        """The robot's pose in the odom frame."""
        return compose(inverse(self.map_to_odom), self.robot.pose)
