"""Odometry that may drift and an amcl-like estimate of where the robot is, without ROS.

A real robot does not know its true pose: wheel odometry (the ``odom -> base_footprint``
transform) drifts, and a localiser (Nav2's ``amcl``) estimates ``map -> odom`` so that
``map -> base_footprint`` is where it believes the robot to be. Navigation plans and
steers from that belief. The ROS 2 stand-in plays both parts with this class:

- **odometry**: integrated from the body's true motion, step by step. With
  ``drift`` > 0 it errs as wheels do: every metre driven reads ``1 + drift`` metres and
  turns the heading by ``drift`` rad more (a fixed scale and heading error; no noise, so
  runs stay reproducible). With 0 it is exact, and the belief is the truth;
- **the estimate** (``map -> odom``): set by an initial pose (RViz's "2D Pose Estimate",
  ``/initialpose``), which moves the belief, never the robot. It is *not* a particle
  filter: whenever the robot has driven ``update_min_d`` or turned ``update_min_a``
  since the last update (nav2_bringup's amcl parameters), the estimate moves
  ``gain`` of the way toward the true ``map -> odom`` — what amcl's scan matching does
  when its guess is near the truth. A robot that stands still is not corrected, as
  with amcl.

:meth:`spread` is the estimate's uncertainty (what the covariance and the particle cloud
show): the distance between belief and truth, never below a converged amcl's few
centimetres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from navseq.geometry import Pose2D, compose, inverse, normalize_angle

UPDATE_MIN_D = 0.25  # m: nav2_bringup's amcl update_min_d
UPDATE_MIN_A = 0.2  # rad: nav2_bringup's amcl update_min_a
CORRECTION_GAIN = 0.5  # share of the error removed at each update
MIN_SPREAD_M = 0.05  # m: a converged amcl's standard deviation, about
MIN_SPREAD_RAD = 0.05  # rad


@dataclass(frozen=True)
class Spread:
    """Standard deviations of the estimate: metres along x and y, radians in yaw."""

    xy: float
    yaw: float


class Localization:
    """Odometry and the ``map -> odom`` estimate of one robot; see the module docstring.

    ``start`` is the true start pose: odometry reads zero there, and the estimate starts
    as the truth.
    """

    def __init__(
        self,
        start: Pose2D,
        *,
        drift: float = 0.0,
        update_min_d: float = UPDATE_MIN_D,
        update_min_a: float = UPDATE_MIN_A,
        gain: float = CORRECTION_GAIN,
    ) -> None:
        if not (math.isfinite(drift) and drift >= 0.0):
            raise ValueError(f"drift must be >= 0, got {drift}")
        self.drift = drift
        self.update_min_d = update_min_d
        self.update_min_a = update_min_a
        self.gain = gain
        self.odom_pose = Pose2D(0.0, 0.0, 0.0)
        self.estimate = Pose2D(start.x, start.y, start.yaw)  # map -> odom
        self.updates = 0  # corrections made (each is an amcl_pose / particle_cloud)
        self._true = Pose2D(start.x, start.y, start.yaw)
        self._moved_d = 0.0
        self._moved_a = 0.0

    # -- the belief ------------------------------------------------------------------

    @property
    def believed_pose(self) -> Pose2D:
        """Where the robot believes it is in the map: the estimate after odometry."""
        return compose(self.estimate, self.odom_pose)

    def true_map_to_odom(self) -> Pose2D:
        """The ``map -> odom`` that would put the belief on the truth."""
        return compose(self._true, inverse(self.odom_pose))

    def error(self) -> float:
        """Metres between the belief and the true pose."""
        return self.believed_pose.distance_to(self._true)

    def spread(self) -> Spread:
        believed, true = self.believed_pose, self._true
        return Spread(
            xy=max(MIN_SPREAD_M, believed.distance_to(true)),
            yaw=max(MIN_SPREAD_RAD, abs(normalize_angle(believed.yaw - true.yaw))),
        )

    # -- inputs ----------------------------------------------------------------------

    def moved(self, true_pose: Pose2D) -> bool:
        """The body is now at ``true_pose``: odometry integrates the motion (with its
        drift); True when that made an amcl update (the estimate was corrected)."""
        step = compose(inverse(self._true), true_pose)  # the motion in the robot's frame
        self._true = true_pose
        distance = math.hypot(step.x, step.y)
        if distance == 0.0 and step.yaw == 0.0:
            return False
        if self.drift > 0.0:
            scale = 1.0 + self.drift
            step = Pose2D(step.x * scale, step.y * scale, step.yaw + self.drift * distance)
        self.odom_pose = compose(self.odom_pose, step)
        self._moved_d += distance
        self._moved_a += abs(step.yaw)
        if self._moved_d < self.update_min_d and self._moved_a < self.update_min_a:
            return False
        self._moved_d = self._moved_a = 0.0
        self.estimate = _toward(self.estimate, self.true_map_to_odom(), self.gain)
        self.updates += 1
        return True

    def update_without_motion(self) -> None:
        """amcl's ``request_nomotion_update``: one correction now, as if the robot had
        driven far enough for an update."""
        self._moved_d = self._moved_a = 0.0
        self.estimate = _toward(self.estimate, self.true_map_to_odom(), self.gain)
        self.updates += 1

    def set_pose(self, believed: Pose2D) -> None:
        """An initial pose: the robot now believes it is at ``believed`` (it does not move)."""
        self.estimate = compose(believed, inverse(self.odom_pose))
        self._moved_d = self._moved_a = 0.0
        self.updates += 1

    def teleported(self, true_pose: Pose2D) -> None:
        """The body was put at ``true_pose`` (odometry stays continuous): the belief follows."""
        self._true = true_pose
        self.estimate = self.true_map_to_odom()
        self._moved_d = self._moved_a = 0.0
        self.updates += 1


def _toward(start: Pose2D, goal: Pose2D, share: float) -> Pose2D:
    """The pose ``share`` of the way from ``start`` to ``goal`` (yaw the short way round)."""
    turn = normalize_angle(goal.yaw - start.yaw)
    return Pose2D(
        start.x + share * (goal.x - start.x),
        start.y + share * (goal.y - start.y),
        normalize_angle(start.yaw + share * turn),
    )


__all__ = ["Localization", "Spread"]
