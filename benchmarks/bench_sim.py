"""Simulator benchmark: real-time factor and mission efficiency on the example mission.

Run:  .venv/bin/python benchmarks/bench_sim.py [MISSION] [--repeat N]

- Real-time factor: simulated seconds per wall second for the whole mission run
  (executor + sim navigator + navigation server + robot), median of the repeats.
- Mission efficiency: mission time divided by its lower bound, the sum over legs
  (start -> waypoint 1 -> waypoint 2 ...) of the shortest collision-free path length
  for the robot centre (8-connected over the costmap's free cells, scikit-image's
  ``MCP_Geometric`` with unit costs) divided by the top speed. Measured twice: stopping
  at every waypoint (pass_through off) and passing through every intermediate one
  (pass_through 0.3 m; the last waypoint always stops).

Targets (issue 3): real-time factor >= 200, efficiency <= 1.35 stopping, <= 1.15 passing.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import statistics
import time
from pathlib import Path
from types import MappingProxyType

import numpy as np
from rich.console import Console
from rich.table import Table
from skimage.graph import MCP_Geometric

from navseq.executor.runner import run_mission
from navseq.mission import Mission, load_mission
from navseq.navigators.sim import SimNavigator
from navseq.sim.costmap import Costmap
from navseq.sim.robot import DiffDriveLimits

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "turtlebot3_world.yaml"


def with_pass_through(mission: Mission, radius: float | None) -> Mission:
    """The mission with every waypoint's pass_through override set to ``radius``."""
    waypoints = tuple(
        dataclasses.replace(
            wp, overrides=MappingProxyType({**wp.overrides, "pass_through_m": radius})
        )
        for wp in mission.waypoints
    )
    return dataclasses.replace(mission, waypoints=waypoints)


def shortest_path_length(
    costmap: Costmap, start: tuple[float, float], goal: tuple[float, float]
) -> float:
    """Length (m) of the shortest 8-connected path over free cells between two points."""
    grid = costmap.grid
    costs = np.where(costmap.free_mask(), 1.0, np.inf)
    mcp = MCP_Geometric(costs, fully_connected=True)
    start_cell, goal_cell = grid.world_to_cell(*start), grid.world_to_cell(*goal)
    cumulative, _ = mcp.find_costs([start_cell], [goal_cell])
    return float(cumulative[goal_cell]) * grid.resolution


def lower_bound(mission: Mission, navigator: SimNavigator) -> float:
    """Seconds the mission needs at least: shortest leg lengths at top speed."""
    costmap = navigator.world.costmap
    pose = navigator.world.robot.pose
    points = [(pose.x, pose.y)] + [(wp.x, wp.y) for wp in mission.waypoints]
    length = sum(shortest_path_length(costmap, a, b) for a, b in itertools.pairwise(points))
    return length / DiffDriveLimits().max_v


def run_once(mission: Mission) -> tuple[float, float, bool, float]:
    """(simulated s, wall s, success, lower bound s) of one run on a fresh simulator."""
    assert mission.map is not None, "the benchmark mission needs a map"
    navigator = SimNavigator.from_map(mission.map, mission.start)
    bound = lower_bound(mission, navigator)
    started = time.perf_counter()
    result = run_mission(mission, navigator)
    wall = time.perf_counter() - started
    assert navigator.world.collisions == 0
    return navigator.now(), wall, result.success, bound


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mission", nargs="?", default=str(EXAMPLE))
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    mission = load_mission(args.mission)

    table = Table(title=f"Simulator on {Path(args.mission).name}")
    for column in (
        "variant",
        "reached all",
        "mission s",
        "lower bound s",
        "efficiency",
        "target",
        "wall s",
        "real-time factor",
    ):
        table.add_column(column, justify="right")
    variants = [
        ("as written", mission, None),
        ("stop at every waypoint", with_pass_through(mission, None), 1.35),
        ("pass through (0.3 m)", with_pass_through(mission, 0.3), 1.15),
    ]
    for name, variant, target in variants:
        runs = [run_once(variant) for _ in range(args.repeat)]
        simulated = statistics.median(r[0] for r in runs)
        wall = statistics.median(r[1] for r in runs)
        bound = runs[0][3]
        table.add_row(
            name,
            "yes" if all(r[2] for r in runs) else "NO",
            f"{simulated:.1f}",
            f"{bound:.1f}",
            f"{simulated / bound:.3f}",
            f"<= {target}" if target else "",
            f"{wall:.3f}",
            f"{simulated / wall:.0f}x",
        )
    Console(width=130).print(table)
    print("real-time factor target: >= 200x")


if __name__ == "__main__":
    main()
