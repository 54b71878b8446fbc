"""Nav2's assisted teleop filter: a teleop command slowed down before it collides.

``nav2_behaviors::AssistedTeleop`` (Jazzy) takes the operator's twist from
``cmd_vel_teleop`` and, every cycle, projects the robot along it in steps of
``simulation_time_step`` (0.1 s) for less than ``projection_time`` (1 s). At the first
projected pose whose footprint collides it scales the whole twist by ``t /
projection_time`` (``t`` being how far ahead that pose is), so the robot slows down as it
nears an obstacle; a collision already at the first step stops it. Without a collision
the twist passes unchanged. This module is that filter, without ROS; the behaviour
server (:mod:`navseq.sim.behaviors`) runs it every cycle.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from navseq.geometry import Pose2D


@dataclass(frozen=True)
class TeleopParams:
    """The behaviour server's assisted teleop parameters (Nav2's defaults; nav2_bringup
    sets none)."""

    projection_time: float = 1.0  # s
    simulation_time_step: float = 0.1  # s


def assisted_command(
    pose: Pose2D,
    twist: tuple[float, float],
    collides: Callable[[Pose2D], bool],
    params: TeleopParams = TeleopParams(),
) -> tuple[float, float]:
    """The (v, w) Nav2's assisted teleop sends for the operator's ``twist`` at ``pose``."""
    v, w = twist
    step = params.simulation_time_step
    projected = pose
    # Accumulated as Nav2 does (its loop counter is a double): ten steps for 1 s.
    ahead = step
    while ahead < params.projection_time:
        projected = Pose2D(
            projected.x + step * v * math.cos(projected.yaw),
            projected.y + step * v * math.sin(projected.yaw),
            projected.yaw + step * w,
        )
        if collides(projected):
            if ahead == step:
                return (0.0, 0.0)
            scale = ahead / params.projection_time
            return (v * scale, w * scale)
        ahead += step
    return (v, w)


__all__ = ["TeleopParams", "assisted_command"]
