"""The distance the robot drives, from the successive poses the executor is given."""

from __future__ import annotations

from navseq.geometry import Pose2D


class Odometer:
    """Adds up the steps between successive poses, odometry ones when there are any.

    Odometry poses are continuous and free of localisation jumps, so they are
    preferred; map poses count where the navigator gives no odometry.
    """

    def __init__(self) -> None:
        self._last_pose: Pose2D | None = None  # map frame
        self._last_odom_pose: Pose2D | None = None  # odometry frame

    def step(self, pose: Pose2D | None, odom_pose: Pose2D | None = None) -> float:
        """The distance driven since the previous poses (m), 0 for the first ones."""
        step = 0.0
        if odom_pose is not None:
            if self._last_odom_pose is not None:
                step = self._last_odom_pose.distance_to(odom_pose)
        elif pose is not None and self._last_pose is not None:
            step = self._last_pose.distance_to(pose)
        if pose is not None:
            self._last_pose = pose
        # Forgotten when missing, so that odometry coming back does not count the gap
        # a second time (the map poses counted it).
        self._last_odom_pose = odom_pose
        return step


__all__ = ["Odometer"]
