"""A fleet file made into a checked plan: the one path ``navseq plan --fleet`` and
``navseq run --fleet`` share, so both refuse the same things before anything moves."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.fleet.checks import (
    FleetDistances,
    fleet_distances,
    raise_all,
    start_problems,
    untakeable_problems,
)
from navseq.fleet.fleet_format import inspect_fleet
from navseq.fleet.model import Fleet
from navseq.fleet.split import Split, split_waypoints

if TYPE_CHECKING:
    from navseq.mission.robot import RobotProfile
    from navseq.route.legs import Legs
    from navseq.sim.occupancy import OccupancyGrid


@dataclass(frozen=True)
class FleetPlan:
    fleet: Fleet
    grid: OccupancyGrid | None
    distances: FleetDistances | None  # None: a resumed run's, whose split is kept
    split: Split


def plan_fleet(
    fleet_path: Path,
    mission_path: Path | None = None,
    *,
    map_path: Path | None = None,
    time_limit_s: float = 2.0,
    need_map: bool = False,
) -> FleetPlan:
    """Read, check and split a fleet file (``mission_path`` / ``map_path`` replace its
    ``mission:`` / ``map:``). Raises NavseqError / MissionErrors, every problem at once."""
    import dataclasses

    from navseq.errors import NavseqError
    from navseq.files import require_file

    require_file(fleet_path, "FLEET")
    if mission_path is not None:
        require_file(mission_path, "MISSION")
    if map_path is not None:
        require_file(map_path, "--map")
    fleet, file_problems = inspect_fleet(fleet_path, mission_path)
    if fleet is None:
        file_problems.raise_if_any()
    assert fleet is not None
    if map_path is not None:
        fleet = dataclasses.replace(fleet, map=map_path)
    if fleet.map is None and need_map:
        raise NavseqError(
            "the simulator needs a map: give map: in the fleet file (or the mission), "
            "or --map MAP.yaml",
            source=str(fleet_path),
        )
    grid = None
    if fleet.map is not None:
        from navseq.sim.occupancy import load_map

        grid = load_map(fleet.map)
    problems = [*file_problems.errors, *start_problems(fleet, grid)]
    if problems:  # the split needs a whole fleet: a robot left out would change it
        raise_all(problems)
    distances = fleet_distances(fleet, _legs(fleet, grid))
    raise_all(untakeable_problems(fleet, distances))
    split = split_waypoints(fleet, distances, time_limit_s)
    return FleetPlan(fleet, grid, distances, split)


def _legs(fleet: Fleet, grid: OccupancyGrid | None) -> dict[RobotProfile, Legs]:
    """A leg planner per robot model (straight lines without a map)."""
    from navseq.route.legs import LegPlanner, StraightLegs
    from navseq.sim.costmap import Costmap
    from navseq.sim.profile import costmap_params_of

    legs: dict[RobotProfile, Legs] = {}
    for robot in fleet.robots:
        if robot.profile not in legs:
            legs[robot.profile] = (
                StraightLegs()
                if grid is None
                else LegPlanner(Costmap.from_grid(grid, costmap_params_of(robot.profile)))
            )
    return legs


__all__ = ["FleetPlan", "plan_fleet"]
