"""A fleet against its map, before anything moves: every problem at once.

- a robot whose start pose is off the map or whose footprint there overlaps an
  obstacle or unknown space (the exact test the simulated body uses);
- two robots whose footprints overlap at their start poses;
- a waypoint no robot may take: the fleet file allows it to no robot that can reach
  it from its start pose on the costmap of its own footprint (mixed models: a narrow
  aisle may be for the small robot only).

Reachability comes from the distances the split is made of (:class:`FleetDistances`:
one search per place and robot model), so checking costs nothing extra.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from navseq.errors import NavseqError
from navseq.fleet.model import Fleet

if TYPE_CHECKING:
    from navseq.mission.robot import RobotProfile
    from navseq.route.legs import Legs
    from navseq.sim.occupancy import OccupancyGrid


def start_problems(fleet: Fleet, grid: OccupancyGrid | None) -> list[NavseqError]:
    """Start poses off the map, in obstacles, or on another robot."""
    from navseq.sim.footprint import footprint_collides, footprints_overlap
    from navseq.sim.profile import footprint_of

    problems: list[NavseqError] = []
    footprints = [footprint_of(robot.profile) for robot in fleet.robots]
    for robot, footprint in zip(fleet.robots, footprints, strict=True):
        if grid is not None and footprint_collides(grid, footprint, robot.start):
            problems.append(
                NavseqError(
                    f"the start pose ({robot.start.x:.2f}, {robot.start.y:.2f}) puts the "
                    f"robot's footprint ({robot.profile.name}) over an obstacle, unknown "
                    "space or the map's edge",
                    source=robot.where,
                    subject=f"robot '{robot.name}', field start",
                )
            )
    for i, a in enumerate(fleet.robots):
        for j in range(i + 1, len(fleet.robots)):
            b = fleet.robots[j]
            if footprints_overlap(footprints[i], a.start, footprints[j], b.start):
                problems.append(
                    NavseqError(
                        f"starts on robot '{a.name}' ({a.where}): their footprints overlap "
                        f"at ({b.start.x:.2f}, {b.start.y:.2f}); move one of them",
                        source=b.where,
                        subject=f"robot '{b.name}', field start",
                    )
                )
    return problems


@dataclass(frozen=True)
class FleetDistances:
    """Metres between places for each robot model, over ``places``: every robot's start
    (in fleet order) and then every waypoint. ``by_robot[k]`` is robot k's matrix
    (``inf``: no path for its footprint)."""

    places: tuple[tuple[float, float], ...]
    by_robot: tuple[np.ndarray, ...]
    robots: int

    def waypoint_node(self, index: int) -> int:
        return self.robots + index

    def reachable(self, robot: int, index: int) -> bool:
        """Whether robot ``robot`` can drive from its start to waypoint ``index``."""
        return math.isfinite(self.by_robot[robot][robot, self.waypoint_node(index)])


def fleet_distances(fleet: Fleet, legs_for: dict[RobotProfile, Legs]) -> FleetDistances:
    """The distances for every robot model of ``fleet`` (one matrix per model)."""
    places = tuple(
        [(robot.start.x, robot.start.y) for robot in fleet.robots]
        + [(w.x, w.y) for w in fleet.mission.waypoints]
    )
    matrices: dict[RobotProfile, np.ndarray] = {}
    for robot in fleet.robots:
        if robot.profile not in matrices:
            measured = np.asarray(legs_for[robot.profile].distances(places), dtype=float)
            np.fill_diagonal(measured, 0.0)
            matrices[robot.profile] = measured
    return FleetDistances(
        places, tuple(matrices[robot.profile] for robot in fleet.robots), len(fleet.robots)
    )


def untakeable_problems(fleet: Fleet, distances: FleetDistances) -> list[NavseqError]:
    """Waypoints that no robot both may take and can reach."""
    problems = []
    mission = fleet.mission
    for index, waypoint in enumerate(mission.waypoints):
        allowed = [k for k, robot in enumerate(fleet.robots) if fleet.may_take(robot.name, index)]
        if any(distances.reachable(k, index) for k in allowed):
            continue
        names = ", ".join(fleet.robots[k].name for k in allowed)
        why = (
            f"none of the robots allowed to take it ({names}) can reach it from its start "
            "with its footprint (navseq validate MISSION --map MAP --robot ... says why)"
            if allowed
            else "the fleet file allows it to no robot"
        )
        problems.append(
            NavseqError(
                f"no robot may take this waypoint: {why}",
                source=waypoint.where or mission.source,
                subject=mission.waypoint_label(index),
            )
        )
    return problems


def raise_all(problems: Sequence[NavseqError]) -> None:
    """Raise the problems together (nothing moves, nothing is written)."""
    from navseq.errors import MissionErrors
    from navseq.fleet.fleet_format import line_order

    problems = sorted(problems, key=line_order)
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise MissionErrors(list(problems))


__all__ = [
    "FleetDistances",
    "fleet_distances",
    "raise_all",
    "start_problems",
    "untakeable_problems",
]
