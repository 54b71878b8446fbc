"""Ordering again on the same map: the distances kept per map and robot (route/distances.py).

The studio's Order… after an edit, or a second ``navseq plan --order`` in one process,
asks for the distances between nearly the same waypoints again. Side by side, on one
mission of ``--size`` random roomy spots per map (one thread per core):

- **first**: every distance measured (one search per waypoint, nothing kept yet);
- **same places, new order**: the mission as the first Order… left it (every pair known);
- **one moved**: then one waypoint dragged elsewhere (one search, from it);
- **another robot**: a robot 0.2 m wider on the same map (its own costmap:
  nothing kept applies, every distance measured again).

    .venv/bin/python benchmarks/bench_order_again.py [--size 400]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

from rich.console import Console
from rich.markup import escape
from rich.table import Table

from navseq.commands.common import costmap_for_map, costmap_for_robot
from navseq.route.distances import known_distances
from navseq.route.legs import LegPlanner
from navseq.sim.costmap import Costmap
from navseq.sim.mapgen import warehouse_map

ROOT = Path(__file__).resolve().parents[1]


def timed(costmap: Costmap, places: list[tuple[float, float]]) -> tuple[float, int]:
    """Seconds to measure the distances, and the searches it took."""
    known = known_distances(costmap)
    searched = known.searched
    began = time.perf_counter()
    LegPlanner(costmap).distances(places)
    return time.perf_counter() - began, known.searched - searched


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=400, help="waypoints")
    args = parser.parse_args()
    from bench_route import free_spots

    maps = {
        "TurtleBot3 arena": costmap_for_map(ROOT / "maps/turtlebot3_world.yaml"),
        "warehouse 400 x 600": costmap_for_robot(warehouse_map(0)),
    }
    # escape: "[s]" would otherwise be taken as rich markup and vanish.
    table = Table(title=escape(f"ordering distances of {args.size} waypoints [s] (searches)"))
    table.add_column("map")
    for name in ("first", "same places, new order", "one moved", "another robot"):
        table.add_column(name, justify="right")
    for name, costmap in maps.items():
        places = free_spots(costmap, args.size + 1, seed=7)
        mission, spare = places[:-1], places[-1]
        figures = [timed(costmap, mission), timed(costmap, mission[::-1])]
        figures.append(timed(costmap, [*mission[:-1], spare]))
        params = costmap.params
        wider = replace(
            params,
            inscribed_radius=params.inscribed_radius + 0.1,
            circumscribed_radius=params.circumscribed_radius + 0.1,
        )
        figures.append(timed(Costmap.from_grid(costmap.grid, wider), mission))
        table.add_row(name, *(f"{seconds:.2f} ({searches})" for seconds, searches in figures))
    Console(width=160).print(table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
