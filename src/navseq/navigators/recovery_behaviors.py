"""A mission's recovery as the behaviour Nav2's behaviour server runs for it.

One place for what both the simulator (:mod:`navseq.sim.behaviors` on the simulated
robot) and ``--navigator nav2`` (the behaviour server's ``spin``, ``backup`` and ``wait``
actions) send for a recovery: the action, its target, speed and time allowance, the
values of Nav2's default behaviour tree where the mission says nothing. No ROS here.
``clear_costmaps`` is no behaviour: each navigator clears its costmaps its own way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from navseq.mission.recovery import BACKUP_SPEED_MPS, Recovery
from navseq.sim.behaviors import Behavior, BehaviorGoal, BehaviorServer

#: m/s backwards: Nav2's default trees (``<BackUp backup_dist="0.30" backup_speed="0.15"/>``).
BACKUP_SPEED = BACKUP_SPEED_MPS


@dataclass(frozen=True)
class BehaviorRequest:
    """The behaviour goal for a recovery: ``target`` is radians (spin), metres (backup,
    a positive distance backwards) or seconds (wait); ``time_allowance`` in seconds."""

    behavior: Behavior
    target: float
    speed: float = 0.0
    time_allowance: float = 0.0


def behavior_request(recovery: Recovery) -> BehaviorRequest | None:
    """The behaviour that carries ``recovery`` out; None for ``clear_costmaps``."""
    amount = recovery.amount or 0.0
    allowance = recovery.timeout_s
    if recovery.kind == "spin":
        return BehaviorRequest(Behavior.SPIN, math.radians(amount), time_allowance=allowance)
    if recovery.kind == "backup":
        return BehaviorRequest(Behavior.BACKUP, amount, BACKUP_SPEED, allowance)
    if recovery.kind == "wait":
        return BehaviorRequest(Behavior.WAIT, amount)
    return None


def start_on(server: BehaviorServer, request: BehaviorRequest, now: float) -> BehaviorGoal:
    """Start ``request`` on the simulator's behaviour server."""
    if request.behavior is Behavior.SPIN:
        return server.spin(now, request.target, request.time_allowance)
    if request.behavior is Behavior.WAIT:
        return server.wait(now, request.target)
    return server.drive(
        request.behavior, now, (request.target, 0.0, 0.0), request.speed, request.time_allowance
    )


__all__ = ["BACKUP_SPEED", "BehaviorRequest", "behavior_request", "start_on"]
