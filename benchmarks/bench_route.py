"""``navseq plan --order shortest``: how much quicker, and how long it takes to find.

Waypoints are put at random free spots of a map (where the robot fits with 0.3 m to
spare, in the map's largest connected region), each with a random yaw, in the order they
were drawn — as a user clicking a map, or a list copied from somewhere, has them. The
routes are compared by their travel time (:mod:`navseq.route.travel`: planned length at
the robot's top speed plus the turns in place at each waypoint), the cost navseq orders
by, side by side over the same matrix:

- **file order**: the route as drawn;
- **nearest neighbour**: from waypoint 1 always to the nearest waypoint not yet
  visited — what a hand-written reordering usually does;
- **navseq**: :func:`navseq.route.order.shortest_tour` (nearest neighbour, then the
  iterated local search of :mod:`navseq.route.search` for ``--time-limit`` seconds;
  OR-tools' guided local search where its C extension is not built);
- **reference**: the same solver given ``--reference`` seconds (0: not run), the
  long solve navseq's tour is measured against.

Every route starts at waypoint 1 and ends anywhere (an open route, as ``navseq plan
--order shortest`` finds it for a mission without a start pose). The table gives the
mean over ``--seeds`` random missions. The distances are measured two ways, side by side
on the same places, both on one thread per core: what navseq does
(``LegPlanner.routes``: on a big map the coarse routes of :mod:`navseq.route.coarse`,
otherwise one exact search per waypoint), and one exact search per waypoint that stops
once it reached the waypoints after it (what navseq did before; only up to
``--exact-up-to`` waypoints), whose lengths are the planner's (one A* plan per pair,
checked by ``tests/test_route_distances.py``). Reachable and unreachable pairs must be
the same both ways; the table gives the median and largest difference in length.
The maps (``--maps``): the TurtleBot3 arena, a generated warehouse (400 x 600 cells),
Nav2's warehouse map (nav2_bringup's, 1006 x 1674 cells at 3 cm, where
``scripts/install-nav2.sh`` put it) and 2000 x 2000 cells of generated warehouses side by
side (benchmarks/bench_studio.py's).

    .venv/bin/python benchmarks/bench_route.py [--sizes 100 200] [--seeds 1] \\
        [--time-limit 1] [--reference 30] [--maps arena warehouse nav2-warehouse big] \\
        [--exact-up-to 200]
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
from navseq.eta.drive import DriveModel
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.route.legs import LegPlanner
from navseq.route.order import NO_PATH_M, shortest_tour, tour_length
from navseq.route.travel import travel_seconds
from navseq.sim.costmap import Costmap
from navseq.sim.mapgen import warehouse_map
from navseq.sim.occupancy import OccupancyGrid
from navseq.sinks.summary import print_table

ROOT = Path(__file__).resolve().parents[1]
NAV2_WAREHOUSE = Path("/opt/nav2/share/nav2_bringup/maps/warehouse.yaml")


@dataclass
class Row:
    map_name: str
    size: int
    file_s: list[float]
    nearest_s: list[float]
    navseq_s: list[float]
    reference_s: list[float]
    exact_s: list[float]
    searches_s: list[float]
    searches_cpu_s: list[float]
    errors: list[np.ndarray]
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
    name: str,
    costmap: Costmap,
    size: int,
    seeds: int,
    time_limit_s: float,
    reference_s: float,
    exact_up_to: int,
) -> Row:
    row = Row(name, size, [], [], [], [], [], [], [], [], [])
    model = DriveModel.of(DEFAULT_PROFILE)
    for seed in range(seeds):
        places = free_spots(costmap, size, seed)
        yaws = np.random.default_rng(seed).uniform(-np.pi, np.pi, size).tolist()
        # Each measured on a costmap of its own: the distances kept per map and robot
        # (route/distances.py) would answer the second from the first.
        fresh = Costmap.from_grid(costmap.grid, costmap.params)
        began, began_cpu = time.perf_counter(), time.process_time()
        table = LegPlanner(fresh, size * size).routes(places, model.lookahead)
        row.searches_s.append(time.perf_counter() - began)
        row.searches_cpu_s.append(time.process_time() - began_cpu)
        if size <= exact_up_to:
            began = time.perf_counter()
            exact = exact_metres(costmap, places, model.lookahead)
            row.exact_s.append(time.perf_counter() - began)
            reached = np.isfinite(exact)
            assert (np.isfinite(table.metres) == reached).all(), "reachability differs"
            off = np.abs(table.metres - exact)[reached] / np.maximum(exact[reached], 1e-9)
            row.errors.append(off)
        seconds = travel_seconds(table, yaws, model)
        matrix = np.where(np.isfinite(seconds), seconds, NO_PATH_M)
        began = time.perf_counter()
        tour = shortest_tour(matrix, closed=False, time_limit_s=time_limit_s)
        row.solver_s.append(time.perf_counter() - began)
        row.file_s.append(tour_length(matrix, list(range(size)), closed=False))
        row.nearest_s.append(tour_length(matrix, nearest_neighbour(matrix), closed=False))
        row.navseq_s.append(tour_length(matrix, tour, closed=False))
        if reference_s > 0:
            reference = shortest_tour(matrix, closed=False, time_limit_s=reference_s)
            row.reference_s.append(tour_length(matrix, reference, closed=False))
    return row


def exact_metres(
    costmap: Costmap, places: list[tuple[float, float]], anchor_m: float
) -> np.ndarray:
    """One exact search per place to the places after it, on one thread per core."""
    import os
    from concurrent.futures import ThreadPoolExecutor

    from navseq.sim.planner import reach_routes

    count = len(places)
    metres = np.zeros((count, count))
    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        rows = pool.map(
            lambda i: reach_routes(costmap, places[i], places[i + 1 :], anchor_m)[:, 0],
            range(count - 1),
        )
        for i, found in enumerate(rows):
            metres[i, i + 1 :] = metres[i + 1 :, i] = found
    return metres


def the_maps(names: list[str]) -> dict[str, Costmap]:
    makers = {
        "arena": ("TurtleBot3 arena (384 x 384)", lambda: costmap_for_map(
            ROOT / "maps" / "turtlebot3_world.yaml")),
        "warehouse": ("generated warehouse (400 x 600)", lambda: costmap_for_robot(
            warehouse_map(1))),
        "nav2-warehouse": ("Nav2 warehouse (1006 x 1674)", lambda: costmap_for_map(
            NAV2_WAREHOUSE)),
        "big": ("warehouses (2000 x 2000)", lambda: costmap_for_robot(_big_map())),
    }  # fmt: skip
    maps = {}
    for name in names:
        if name == "nav2-warehouse" and not NAV2_WAREHOUSE.is_file():
            print(f"skipped: {NAV2_WAREHOUSE} is not installed (scripts/install-nav2.sh)")
            continue
        title, make = makers[name]
        maps[title] = make()
    return maps


def _big_map() -> OccupancyGrid:
    from bench_studio import big_map

    return big_map()


def error_text(errors: list[np.ndarray]) -> str:
    """The median and largest relative difference in length, in per cent ("-": none)."""
    if not errors:
        return "-"
    every = np.concatenate(errors)
    return f"{100 * np.median(every):.2f} % / {100 * every.max():.1f} %"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 30, 100])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--time-limit", type=float, default=2.0)
    parser.add_argument("--reference", type=float, default=0.0, metavar="S")
    parser.add_argument("--exact-up-to", type=int, default=200)
    parser.add_argument(
        "--maps",
        nargs="+",
        default=["arena", "warehouse"],
        choices=["arena", "warehouse", "nav2-warehouse", "big"],
    )
    args = parser.parse_args()
    maps = the_maps(args.maps)
    table = Table(title=f"quickest visiting order, mean of {args.seeds} random missions")
    for header in (
        "map",
        "waypoints",
        "file order [s]",
        "nearest neighbour [s]",
        f"navseq ({args.time_limit:g} s) [s]",
        "navseq / nearest",
        f"navseq / reference ({args.reference:g} s)",
        "exact search per waypoint [s]",
        "navseq's distances [s] (CPU)",
        "length off: median / max",
        "solver [s]",
    ):
        table.add_column(escape(header), justify="left" if header == "map" else "right")
    mean = statistics.fmean
    for name, costmap in maps.items():
        for size in args.sizes:
            row = measure(
                name, costmap, size, args.seeds, args.time_limit, args.reference, args.exact_up_to
            )
            ratio = (
                f"{mean(n / r for n, r in zip(row.navseq_s, row.reference_s, strict=True)):.4f}"
                if row.reference_s
                else "-"
            )
            table.add_row(
                name,
                str(size),
                f"{mean(row.file_s):.1f}",
                f"{mean(row.nearest_s):.1f}",
                f"{mean(row.navseq_s):.1f}",
                f"{mean(n / f for n, f in zip(row.navseq_s, row.nearest_s, strict=True)):.2f}",
                ratio,
                f"{mean(row.exact_s):.2f}" if row.exact_s else "-",
                f"{mean(row.searches_s):.2f} ({mean(row.searches_cpu_s):.2f})",
                error_text(row.errors),
                f"{mean(row.solver_s):.2f}",
            )
    print_table(table, Console())


if __name__ == "__main__":
    main()
