"""A :class:`~navseq.mission.robot.RobotProfile` turned into the simulator's settings.

The profile is plain data; the simulator's parts each take their own settings: the
outline (:class:`Footprint`), the costmap's inflation and radii (:class:`CostmapParams`),
the body's speed and acceleration limits (:class:`DiffDriveLimits`) and the navigation
server's goal tolerances (:class:`NavParams`). One function per part, so that a caller
with its own tuning (the ROS node's parameters) can take only what it needs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.sim.costmap import CostmapParams
from navseq.sim.footprint import Footprint
from navseq.sim.navserver import NavParams
from navseq.sim.robot import DiffDriveLimits


def footprint_of(profile: RobotProfile) -> Footprint:
    return Footprint(np.array(profile.footprint, dtype=float))


def costmap_params_of(profile: RobotProfile) -> CostmapParams:
    footprint = footprint_of(profile)
    return CostmapParams(
        inflation_radius=profile.inflation_radius,
        cost_scaling_factor=profile.cost_scaling_factor,
        inscribed_radius=footprint.inscribed_radius,
        circumscribed_radius=footprint.circumscribed_radius,
    )


def limits_of(profile: RobotProfile) -> DiffDriveLimits:
    return DiffDriveLimits(
        max_v=profile.max_linear_speed,
        max_w=profile.max_angular_speed,
        acc_v=profile.max_linear_accel,
        acc_w=profile.max_angular_accel,
    )


def nav_params_of(profile: RobotProfile, base: NavParams | None = None) -> NavParams:
    """``base`` (the defaults) with the profile's limits and goal tolerances."""
    base = base if base is not None else NavParams()
    limits = limits_of(profile)
    return dataclasses.replace(
        base,
        limits=limits,
        xy_tolerance=profile.goal_tolerance.xy_m,
        yaw_tolerance=profile.goal_tolerance.yaw_rad,
        # Turning in place no faster than the robot can; the body would clamp it anyway,
        # but the braking profile must be planned with the real rate.
        rotate_speed=min(base.rotate_speed, limits.max_w),
        rotate_decel=min(base.rotate_decel, limits.acc_w),
        approach_decel=min(base.approach_decel, limits.acc_v),
    )


@dataclass(frozen=True)
class SimSettings:
    """Everything the simulator takes from one robot profile."""

    profile: RobotProfile
    footprint: Footprint
    costmap_params: CostmapParams
    nav_params: NavParams

    @classmethod
    def of(cls, profile: RobotProfile = DEFAULT_PROFILE) -> SimSettings:
        return cls(
            profile, footprint_of(profile), costmap_params_of(profile), nav_params_of(profile)
        )


__all__ = ["SimSettings", "costmap_params_of", "footprint_of", "limits_of", "nav_params_of"]
