"""The other robots of a simulated fleet, as the sim nodes see them: poses from TF.

Each sim node of a robot can be given the base frames of the other robots (private
param ``~other_robots``, e.g. ``[robot2/base_footprint]``). Their poses are looked up in
the global frame every step; a robot whose pose is not (yet) in TF, or too old, is left
out — with a throttled warning — rather than guessed. Every other robot is taken to
have the footprint the caller gives (the sim nodes give their own robot's, from
``~robot``: a fleet of one model); the burger's when none is given.

The checks of the list and the warning are ROS-free and shared with the ROS 2 sim node:
:mod:`navseq.sim.fleet`. This module only looks the poses up in TF.
"""

from __future__ import annotations

import rospy
import tf2_ros

from navseq.geometry import Pose2D
from navseq.ros1.conversions import pose2d_from_transform
from navseq.ros1.params import param_error, str_list_param
from navseq.sim.fleet import WARN_PERIOD, missing_warning, other_robots_problem
from navseq.sim.footprint import TURTLEBOT3_BURGER, Footprint


def other_robots_param(own_base_frame: str) -> tuple[str, ...]:
    """``~other_robots``: the other robots' base frames (leading ``/`` dropped, as tf2
    wants). This robot's own base frame among them is an error: it would bump into
    itself."""
    frames = tuple(frame.lstrip("/") for frame in str_list_param("other_robots", ()))
    problem = other_robots_problem(frames, own_base_frame.lstrip("/"), "base frame")
    if problem is not None:
        raise param_error("other_robots", problem)
    return frames


class OtherRobots:
    """Looks up the other robots' poses in TF (``global_frame`` -> each base frame)."""

    def __init__(
        self,
        buffer: tf2_ros.Buffer,
        global_frame: str,
        frames: tuple[str, ...],
        *,
        tolerance: float,
        footprint: Footprint = TURTLEBOT3_BURGER,
    ) -> None:
        self.buffer = buffer
        self.global_frame = global_frame
        self.frames = frames
        self.tolerance = tolerance
        self.footprint = footprint

    def poses(self) -> list[tuple[Pose2D, Footprint]]:
        """(pose, footprint) of every other robot with a recent pose in TF."""
        found: list[tuple[Pose2D, Footprint]] = []
        missing: list[str] = []
        now = rospy.Time.now()
        for frame in self.frames:
            try:
                transform = self.buffer.lookup_transform(self.global_frame, frame, rospy.Time(0))
            except (
                tf2_ros.LookupException,
                tf2_ros.ConnectivityException,
                tf2_ros.ExtrapolationException,
            ):
                missing.append(frame)
                continue
            if (now - transform.header.stamp).to_sec() > self.tolerance:
                missing.append(frame)  # its node is gone, most likely: so is the robot
                continue
            found.append((pose2d_from_transform(transform), self.footprint))
        if missing:
            rospy.logwarn_throttle(WARN_PERIOD, missing_warning(missing, self.global_frame))
        return found
