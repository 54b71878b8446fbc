"""Global planner benchmark: navseq's A* against scikit-image and pyastar2d.

Prints one table: per map and start/goal pair, the median planning time of each
planner and the cost of its path measured with navseq's objective (step length x mean
traversal cost of the two cells, metres), as a ratio to scikit-image
``MCP_Geometric``'s optimum for that same objective. Targets (issue 3): cost ratio
<= 1.01 and time <= 0.5 s on the 2000 x 2000 map.

- ``navseq C``: the compiled search (``navseq.sim._astar``); ``navseq py``: the
  pure-Python fallback (TurtleBot3 map only: minutes on 2000 x 2000).
- ``MCP_Geometric``: ``find_costs`` from the start, stopping at the goal, plus
  ``traceback``; the reference optimum.
- ``pyastar2d``: C++ A* with a different cost model (a step costs the weight of the
  cell it enters, diagonals not scaled by sqrt 2), given the same traversal costs; its
  paths are optimal for its model, so their ratio on ours shows what that model costs.

Run: ``.venv/bin/python benchmarks/bench_planner.py`` (about a minute).
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyastar2d
from rich.console import Console
from rich.table import Table
from skimage.graph import MCP_Geometric

from navseq.geometry import Pose2D
from navseq.sim.costmap import INSCRIBED, Costmap
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.planner import compiled_search_available, search_cells, traversal_costs

REPO = Path(__file__).resolve().parents[1]
REPEATS = 3
Cell = tuple[int, int]


def random_obstacle_costmap(size: int = 2000, seed: int = 1) -> Costmap:
    """A size x size, 5 cm map of random rectangular blocks and speckle, inflated."""
    rng = np.random.default_rng(seed)
    data = np.zeros((size, size), np.int8)
    for _ in range(size * 3 // 10):
        row, col = rng.integers(0, size, 2)
        height, width = rng.integers(5, 60, 2)
        data[row : row + height, col : col + width] = 100
    data[rng.random(data.shape) < 0.0005] = 100
    return Costmap.from_grid(OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0), "random"))


def pick_pairs(costmap: Costmap, count: int, min_separation: float, seed: int) -> list:
    """Start/goal cell pairs, both free and at least ``min_separation`` cells apart."""
    rng = np.random.default_rng(seed)
    free = np.argwhere(costmap.cost < INSCRIBED)
    pairs: list[tuple[Cell, Cell]] = []
    while len(pairs) < count:
        start, goal = free[rng.choice(len(free), 2)]
        if np.linalg.norm(start - goal) >= min_separation:
            pairs.append(((int(start[0]), int(start[1])), (int(goal[0]), int(goal[1]))))
    return pairs


def path_cost(weights: np.ndarray, cells: np.ndarray, resolution: float) -> float:
    """navseq's objective for any 8-connected cell path, in metres."""
    steps = np.linalg.norm(np.diff(cells, axis=0), axis=1)
    along = weights[cells[:, 0], cells[:, 1]]
    return float(np.sum(steps * 0.5 * (along[:-1] + along[1:])) * resolution)


def timed(run: Callable[[], np.ndarray | None], repeats: int) -> tuple[float, np.ndarray | None]:
    times, result = [], None
    for _ in range(repeats):
        began = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - began)
    return statistics.median(times), result


def planners(costmap: Costmap, start: Cell, goal: Cell, with_python: bool) -> dict:
    weights = traversal_costs()[costmap.cost]
    weights32 = weights.astype(np.float32)

    def navseq(compiled: bool) -> Callable[[], np.ndarray | None]:
        def run() -> np.ndarray | None:
            found = search_cells(costmap.cost, start, goal, use_compiled=compiled)
            return None if found is None else found[0]

        return run

    def mcp() -> np.ndarray | None:
        graph = MCP_Geometric(weights, fully_connected=True)
        costs, _ = graph.find_costs([start], [goal])
        return None if np.isinf(costs[goal]) else np.array(graph.traceback(goal))

    def astar2d() -> np.ndarray | None:
        return pyastar2d.astar_path(weights32, start, goal, allow_diagonal=True)

    runs = {"MCP_Geometric": mcp, "pyastar2d": astar2d}
    if compiled_search_available():
        runs["navseq C"] = navseq(True)
    if with_python:
        runs["navseq py"] = navseq(False)
    return {name: timed(run, REPEATS) for name, run in runs.items()}


def main() -> int:
    console = Console()
    if not compiled_search_available():
        console.print("[yellow]navseq.sim._astar is not built: only the Python search runs")
    began = time.perf_counter()
    turtlebot3 = Costmap.from_grid(load_map(REPO / "maps" / "turtlebot3_world.yaml"))
    big = random_obstacle_costmap()
    cases = [
        ("turtlebot3_world 384x384", turtlebot3, pick_pairs(turtlebot3, 4, 60, seed=2), True),
        ("random 2000x2000", big, pick_pairs(big, 4, 1500, seed=3), False),
    ]
    names = ["navseq C", "navseq py", "MCP_Geometric", "pyastar2d"]
    table = Table(title="Global planner: median time (s) and path cost / MCP_Geometric optimum")
    table.add_column("map")
    table.add_column("start -> goal (cells)")
    table.add_column("optimum (m)", justify="right")
    for name in names:
        table.add_column(f"{name}\ntime", justify="right")
        table.add_column(f"{name}\ncost ratio", justify="right")
    worst = {name: (0.0, 0.0) for name in names}  # (max time, max ratio)
    for label, costmap, pairs, with_python in cases:
        weights = traversal_costs()[costmap.cost]
        for start, goal in pairs:
            results = planners(costmap, start, goal, with_python)
            optimum_path = results["MCP_Geometric"][1]
            if optimum_path is None:
                table.add_row(label, f"{start} -> {goal}", "no path")
                continue
            optimum = path_cost(weights, optimum_path, costmap.resolution)
            row = [label, f"{start} -> {goal}", f"{optimum:.2f}"]
            for name in names:
                if name not in results:
                    row += ["n/a", "n/a"]
                    continue
                seconds, path = results[name]
                ratio = path_cost(weights, path, costmap.resolution) / optimum
                row += [f"{seconds:.3f}", f"{ratio:.4f}"]
                if label.startswith("random"):
                    max_time, max_ratio = worst[name]
                    worst[name] = (max(max_time, seconds), max(max_ratio, ratio))
            table.add_row(*row)
    console.print(table)
    time_c, ratio_c = worst["navseq C"]
    console.print(
        f"2000x2000 worst case, navseq C: {time_c:.3f} s (target <= 0.5 s), "
        f"cost ratio {ratio_c:.4f} (target <= 1.01). pyastar2d's cost model: a step "
        "costs the entered cell's weight, diagonals not sqrt 2."
    )
    console.print(f"benchmark took {time.perf_counter() - began:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
