"""Planar poses and the yaw <-> quaternion conversions every source needs.

Also the readers of ROS pose-like messages (:func:`yaw_of`, :func:`pose2d_from_pose`,
:func:`pose2d_from_transform`): they only read fields, which ROS 1 and ROS 2 messages
name alike, so they import no ROS and serve both (``navseq.ros1``, later ``navseq.ros2``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Pose2D:
    """A pose on the plane: metres and radians, in the mission's frame."""

    x: float
    y: float
    yaw: float = 0.0

    def distance_to(self, other: Pose2D) -> float:
        return math.hypot(other.x - self.x, other.y - self.y)


def normalize_angle(angle: float) -> float:
    """Wrap an angle in radians to [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def yaw_to_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """Quaternion (x, y, z, w) of a rotation by ``yaw`` radians about +z."""
    half = 0.5 * yaw
    return (0.0, 0.0, math.sin(half), math.cos(half))


def quaternion_to_yaw(x: float, y: float, z: float, w: float) -> float:
    """Yaw (radians, in [-pi, pi]) of a quaternion; roll and pitch are ignored."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def yaw_of(orientation: Any) -> float:
    """Yaw (radians) of a geometry_msgs/Quaternion-like object; roll and pitch ignored."""
    return quaternion_to_yaw(orientation.x, orientation.y, orientation.z, orientation.w)


def pose2d_from_pose(pose: Any) -> Pose2D:
    """A planar pose from a ``geometry_msgs/Pose``-like object (z, roll, pitch ignored)."""
    return Pose2D(float(pose.position.x), float(pose.position.y), yaw_of(pose.orientation))


def pose2d_from_transform(transform: Any) -> Pose2D:
    """Where a planar ``TransformStamped``-like object puts its child in its parent frame."""
    t = transform.transform
    return Pose2D(float(t.translation.x), float(t.translation.y), yaw_of(t.rotation))


def yaw_degrees_to_quaternion(degrees: float) -> tuple[float, float, float, float]:
    """The tutorial's conversion: yaw in degrees to quaternion (x, y, z, w)."""
    return yaw_to_quaternion(math.radians(degrees))


def compose(a: Pose2D, b: Pose2D) -> Pose2D:
    """The pose ``b`` (expressed in frame ``a``) expressed in ``a``'s parent frame.

    This is how TF chains planar transforms: ``compose(map_to_odom, odom_to_base)`` is
    the robot's pose in the map.
    """
    cos_a, sin_a = math.cos(a.yaw), math.sin(a.yaw)
    return Pose2D(
        a.x + cos_a * b.x - sin_a * b.y,
        a.y + sin_a * b.x + cos_a * b.y,
        normalize_angle(a.yaw + b.yaw),
    )


def inverse(a: Pose2D) -> Pose2D:
    """The pose ``p`` with ``compose(a, p)`` = identity (the parent frame seen from ``a``)."""
    cos_a, sin_a = math.cos(a.yaw), math.sin(a.yaw)
    return Pose2D(
        -cos_a * a.x - sin_a * a.y,
        sin_a * a.x - cos_a * a.y,
        normalize_angle(-a.yaw),
    )


def remaining_along_path(path: Sequence[tuple[float, float]], x: float, y: float) -> float:
    """Distance (m) left along ``path`` from the point (x, y) to the path's end.

    The point is projected onto the nearest segment of the polyline (the earliest one
    on a tie); the result is the rest of that segment plus every later segment. A
    point whose nearest path point is the path's very start (it is behind it: a plan
    made from a pose a little newer than the point) first has to get there, so that
    gap counts too. An empty path leaves nothing to go (0.0); a single point is the
    straight-line distance to it.
    """
    if not path:
        return 0.0
    if len(path) == 1:
        return math.hypot(path[0][0] - x, path[0][1] - y)
    best_gap = math.inf
    best_segment = 0
    best_fraction = 0.0
    for segment, ((ax, ay), (bx, by)) in enumerate(itertools.pairwise(path)):
        ex, ey = bx - ax, by - ay
        length_squared = ex * ex + ey * ey
        fraction = (
            0.0
            if length_squared == 0.0
            else max(0.0, min(1.0, ((x - ax) * ex + (y - ay) * ey) / length_squared))
        )
        gap = math.hypot(ax + fraction * ex - x, ay + fraction * ey - y)
        if gap < best_gap:
            best_gap, best_segment, best_fraction = gap, segment, fraction
    (ax, ay), (bx, by) = path[best_segment], path[best_segment + 1]
    remaining = (1.0 - best_fraction) * math.hypot(bx - ax, by - ay)
    if best_segment == 0 and best_fraction == 0.0:
        remaining += best_gap
    for (px, py), (qx, qy) in zip(path[best_segment + 1 :], path[best_segment + 2 :], strict=False):
        remaining += math.hypot(qx - px, qy - py)
    return remaining


class FrameTree:
    """The latest planar transform of every frame to its parent, as TF publishes them.

    For a ROS face without tf2's Python libraries (the minimal ROS 2 has none): it
    keeps only the newest transform per child frame (no history, no interpolation),
    which is what "where is the robot now" needs. Frame names are taken without a
    leading ``/`` (ROS 1 style), so ``/map`` and ``map`` are the same frame.
    """

    #: Longest parent chain followed; TF trees of mobile robots are a handful deep, and
    #: a loop published by mistake must not hang a lookup.
    MAX_DEPTH = 32

    def __init__(self) -> None:
        self._parents: dict[str, tuple[str, Pose2D]] = {}

    def set(self, parent: str, child: str, pose: Pose2D) -> None:
        """Record that ``child`` is at ``pose`` in ``parent`` (a TransformStamped)."""
        self._parents[child.lstrip("/")] = (parent.lstrip("/"), pose)

    def lookup(self, target: str, source: str) -> Pose2D | None:
        """The pose of frame ``source`` in frame ``target``; None when not connected.

        Walks from ``source`` up its parents until ``target``, composing on the way
        (``map -> odom -> base_footprint`` gives the robot's pose in the map). Only
        ``target`` being an ancestor of ``source`` (or the same frame) is supported:
        the case of a robot's pose in its map or odometry frame.
        """
        target, frame = target.lstrip("/"), source.lstrip("/")
        pose = Pose2D(0.0, 0.0, 0.0)
        for _ in range(self.MAX_DEPTH):
            if frame == target:
                return pose
            link = self._parents.get(frame)
            if link is None:
                return None
            frame, above = link
            pose = compose(above, pose)
        return None

    def __contains__(self, frame: str) -> bool:
        return frame.lstrip("/") in self._parents
