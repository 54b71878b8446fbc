"""Fleet split: the makespan of 2-5 robots against one robot's tour of the same waypoints.

For each seeded warehouse map (navseq.sim.mapgen, 30 m x 20 m) and waypoint count, the
waypoints are split among N robots starting side by side at the warehouse's door
(navseq.fleet.split, the same code as ``navseq plan --fleet``) and the makespan (the
time the last robot finishes, planned distance / top speed) is set beside one robot's
tour of all of them (N = 1, same solver, same time limit). Prints a table; the ratio
is makespan / one robot's time; distances and split are the wall seconds of each step.

    python benchmarks/bench_fleet_split.py [--seeds 3] [--waypoints 60] [--time-limit 2]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from navseq.fleet.checks import fleet_distances
from navseq.fleet.model import Fleet, FleetRobot
from navseq.fleet.split import split_waypoints
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.route.legs import LegPlanner
from navseq.sim.costmap import Costmap
from navseq.sim.footprint import clearance_map
from navseq.sim.mapgen import warehouse_map
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.profile import costmap_params_of

#: Robots start side by side along the warehouse's south wall, 0.6 m apart.
DOOR = (1.2, 1.0)


def warehouse_fleet(seed: int, waypoints: int, robots: int) -> tuple[Fleet, Costmap]:
    """``robots`` robots at the door of warehouse ``seed`` and ``waypoints`` random
    waypoints they can all reach (seeded)."""
    grid = warehouse_map(seed)
    costmap = Costmap.from_grid(grid, costmap_params_of(DEFAULT_PROFILE))
    starts = [Pose2D(DOOR[0] + 0.6 * k, DOOR[1], 0.0) for k in range(robots)]
    places = _reachable_places(grid, costmap, (starts[0].x, starts[0].y), waypoints, seed)
    mission = Mission(
        waypoints=tuple(Waypoint(x, y, name=f"p{k + 1}") for k, (x, y) in enumerate(places))
    )
    fleet = Fleet(
        robots=tuple(
            FleetRobot(f"r{k + 1}", f"r{k + 1}", start, DEFAULT_PROFILE)
            for k, start in enumerate(starts)
        ),
        mission=mission,
    )
    return fleet, costmap


def _reachable_places(
    grid: OccupancyGrid,
    costmap: Costmap,
    start: tuple[float, float],
    count: int,
    seed: int,
) -> list[tuple[float, float]]:
    from navseq.sim.planner import reach_lengths

    rng = np.random.default_rng(seed + 1000)
    roomy = clearance_map(grid) >= 0.35
    rows, cols = np.nonzero(roomy)
    picked: list[tuple[float, float]] = []
    while len(picked) < count:
        k = rng.integers(len(rows), size=4 * count)
        centres = grid.cells_to_world(rows[k], cols[k])
        candidates = [(float(x), float(y)) for x, y in centres]
        lengths = reach_lengths(costmap, start, candidates)
        picked += [c for c, m in zip(candidates, lengths, strict=True) if np.isfinite(m)]
    return picked[:count]


def makespan(fleet: Fleet, costmap: Costmap, time_limit_s: float) -> float:
    distances = fleet_distances(fleet, {DEFAULT_PROFILE: LegPlanner(costmap)})
    return split_waypoints(fleet, distances, time_limit_s).makespan_s


def one_robot(fleet: Fleet) -> Fleet:
    import dataclasses

    return dataclasses.replace(fleet, robots=fleet.robots[:1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--waypoints", type=int, default=60)
    parser.add_argument("--robots", default="2,3,5")
    parser.add_argument("--time-limit", type=float, default=2.0)
    args = parser.parse_args()
    counts = [int(n) for n in args.robots.split(",")]
    print(
        "| map | waypoints | robots | one robot [s] | makespan [s] | ratio | distances [s] "
        "| split [s] |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for seed in range(args.seeds):
        for robots in counts:
            fleet, costmap = warehouse_fleet(seed, args.waypoints, robots)
            alone = makespan(one_robot(fleet), costmap, args.time_limit)
            began = time.perf_counter()
            distances = fleet_distances(fleet, {DEFAULT_PROFILE: LegPlanner(costmap)})
            measured = time.perf_counter()
            span = split_waypoints(fleet, distances, args.time_limit).makespan_s
            solved = time.perf_counter()
            print(
                f"| warehouse-{seed} | {args.waypoints} | {robots} | {alone:.0f} | "
                f"{span:.0f} | {span / alone:.2f} | {measured - began:.1f} | "
                f"{solved - measured:.1f} |"
            )


if __name__ == "__main__":
    main()
