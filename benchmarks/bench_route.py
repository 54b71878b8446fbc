"""``navseq plan --order shortest``: how much shorter, and how long it takes to find.

Waypoints are put at random free spots of a map (where the robot fits with 0.3 m to
spare, in the map's largest connected region), in the order they were drawn — as a
user clicking a map, or a list copied from somewhere, has them. Side by side, over the
same planned lengths (the planner on the robot's costmap):

- **file order**: the route as drawn;
- **nearest neighbour**: from waypoint 1 always to the nearest waypoint not yet
  visited — what a hand-written reordering usually does;
- **navseq**: :func:`navseq.route.order.shortest_tour` (OR-tools: cheapest arc, then
  guided local search for ``--time-limit`` seconds).

Every route starts at waypoint 1 and ends anywhere (an open route, as ``navseq plan
--order shortest`` finds it for a mission without a start pose). The table gives the
mean over ``--seeds`` random missions of the route lengths, navseq's length as a
fraction of the other two, the time to measure every distance and the solver's time.
The distances are measured two ways, side by side on the same places: one A* plan per
pair (what navseq did before: n²/2 plans) and one search per waypoint that stops once
it reached the waypoints after it (what navseq does: ``LegPlanner.distances``), both on
one thread per core (the compiled search lets go of the GIL); per-pair plans only up to
``--pairs-up-to`` waypoints, and the two matrices must agree within 2 %. The maps: the
TurtleBot3 arena, a warehouse (400 x 600 cells) and, with ``--big``, 2000 x 2000 cells
of warehouses side by side (benchmarks/bench_studio.py's).

    .venv/bin/python benchmarks/bench_route.py [--sizes 10 30 100 200] [--seeds 3] \\
        [--time-limit 2] [--big]
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from navseq.commands.common import costmap_for_map, costmap_for_robot
from navseq.route.legs import LegPlanner, lengths
from navseq.route.order import distance_matrix, distances_between, shortest_tour, tour_length
from navseq.sim.costmap import Costmap
from navseq.sim.mapgen import warehouse_map
from navseq.sinks.summary import print_table

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class Row:
    map_name: str
    size: int
    file_m: list[float]
    nearest_m: list[float]
    navseq_m: list[float]
    pairs_s: list[float]
    searches_s: list[float]
    solver_s: list[float]


def free_spots(costmap: Costmap, count: int, seed: int) -> list[tuple[float, float]]:
    """``count`` random spots where the robot fits with room to spare, in drawn order."""
    from scipy import ndimage

    roomy = costmap.free_mask() & (costmap.clearance >= 0.3 + costmap.params.circumscribed_radius)
    labels, _ = ndimage.label(costmap.free_mask(), structure=np.ones((3, 3), bool))
    main = np.bincount(labels[labels > 0]).argmax()
    cells = np.argwhere(roomy & (labels == main))
    rng = np.random.default_rng(seed)
    chosen = cells[rng.choice(len(cells), size=count, replace=False)]
    return [costmap.cell_to_world(int(row), int(col)) for row, col in chosen]


def nearest_neighbour(matrix: np.ndarray) -> list[int]:
    tour, left = [0], set(range(1, len(matrix)))
    while left:
        here = tour[-1]
        nearest = min(left, key=lambda there: matrix[here, there])
        tour.append(nearest)
        left.remove(nearest)
    return tour


def measure(
    name: str, costmap: Costmap, size: int, seeds: int, time_limit_s: float, pairs_up_to: int
) -> Row:
    row = Row(name, size, [], [], [], [], [], [])
    for seed in range(seeds):
        places = free_spots(costmap, size, seed)
        # Each measured on a planner of its own (its cache would answer the second).
        began = time.perf_counter()
        matrix = distances_between(places, LegPlanner(costmap, size * size))
        row.searches_s.append(time.perf_counter() - began)
        if size <= pairs_up_to:
            began = time.perf_counter()
            pairs = distance_matrix(places, lengths(LegPlanner(costmap, size * size)))
            row.pairs_s.append(time.perf_counter() - began)
            # Equal-cost routes may differ in cells, hardly in length.
            assert np.allclose(matrix, pairs, rtol=0.02), "the two ways disagree"
        began = time.perf_counter()
        tour = shortest_tour(matrix, closed=False, time_limit_s=time_limit_s)
        row.solver_s.append(time.perf_counter() - began)
        row.file_m.append(tour_length(matrix, list(range(size)), closed=False))
        row.nearest_m.append(tour_length(matrix, nearest_neighbour(matrix), closed=False))
        row.navseq_m.append(tour_length(matrix, tour, closed=False))
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 30, 100])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--time-limit", type=float, default=2.0)
    parser.add_argument("--pairs-up-to", type=int, default=100)
    parser.add_argument("--big", action="store_true", help="also the 2000 x 2000 map")
    args = parser.parse_args()
    maps = {
        "turtlebot3_world (384 x 384)": costmap_for_map(ROOT / "maps" / "turtlebot3_world.yaml"),
        "warehouse (400 x 600)": costmap_for_robot(warehouse_map(1)),
    }
    if args.big:
        from bench_studio import big_map

        maps["warehouses (2000 x 2000)"] = costmap_for_robot(big_map())
    table = Table(title=f"shortest visiting order, mean of {args.seeds} random missions")
    for header in (
        "map",
        "waypoints",
        "file order [m]",
        "nearest neighbour [m]",
        "navseq [m]",
        "navseq / file",
        "navseq / nearest",
        "plan per pair [s]",
        "search per waypoint [s]",
        "solver [s]",
    ):
        table.add_column(escape(header), justify="left" if header == "map" else "right")
    for name, costmap in maps.items():
        for size in args.sizes:
            row = measure(name, costmap, size, args.seeds, args.time_limit, args.pairs_up_to)
            mean = statistics.fmean
            table.add_row(
                name,
                str(size),
                f"{mean(row.file_m):.1f}",
                f"{mean(row.nearest_m):.1f}",
                f"{mean(row.navseq_m):.1f}",
                f"{mean(n / f for n, f in zip(row.navseq_m, row.file_m, strict=True)):.2f}",
                f"{mean(n / f for n, f in zip(row.navseq_m, row.nearest_m, strict=True)):.2f}",
                f"{mean(row.pairs_s):.2f}" if row.pairs_s else "-",
                f"{mean(row.searches_s):.2f}",
                f"{mean(row.solver_s):.2f}",
            )
    print_table(table, Console())


if __name__ == "__main__":
    main()
