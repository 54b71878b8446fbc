"""Fleet benchmark: right of way on random missions, and the simulator's real-time factor.

Run:  .venv/bin/python benchmarks/bench_fleet.py [--missions N] [--quick]

- Random fleet missions (issue 21): mission ``k`` (seed ``k``) puts 2 to 8 TurtleBot3
  burgers at random roomy places of a generated map (``sim/mapgen.py``; even seeds an
  office, odd seeds a warehouse) and gives each 3 random waypoints, sent one after the
  other as soon as the last one ended. A waypoint is *reachable* when the bare map has a
  way to it from the robot's start (offices have doors narrower than the robot); only
  those are sent. Counted: robot pairs whose footprints overlap after a step
  (collisions), goals ABORTED "blocked by another robot" (deadlock aborts), other
  aborts, and reachable waypoints reached. Each mission has 900 simulated seconds.
  Run once with the right of way and once with the servers alone (they only wait).
- Real-time factor: simulated seconds per wall second of a fleet of 1, 10 and 20 robots
  on one 30 m x 20 m warehouse, each robot sent to a new random reachable waypoint as
  soon as it ends the last, for 120 simulated seconds; and of one robot in a plain
  ``SimWorld`` for comparison (the single-robot path).

Targets (issue 21): 0 collisions, 0 deadlock aborts, every reachable waypoint reached;
real-time factor >= 100 at 10 robots, >= 20 at 20.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from rich.console import Console
from rich.table import Table

from navseq.geometry import Pose2D
from navseq.sim.costmap import Costmap
from navseq.sim.fleet_world import FleetRobot, FleetWorld
from navseq.sim.footprint import TURTLEBOT3_BURGER
from navseq.sim.mapgen import office_map, warehouse_map
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.planner import reach_lengths
from navseq.sim.profile import SimSettings
from navseq.sim.world import SimWorld
from navseq.sinks.summary import print_table

WAYPOINTS_PER_ROBOT = 3
MISSION_LIMIT_S = 900.0
BLOCKED = "blocked by another robot"


@dataclass
class MissionResult:
    robots: int
    reachable: int = 0
    reached: int = 0
    collisions: int = 0
    deadlock_aborts: int = 0
    other_aborts: int = 0
    unfinished: int = 0  # robots still busy when the time ran out
    sim_s: float = 0.0
    wall_s: float = 0.0
    yields: int = 0


@dataclass
class Totals:
    missions: int = 0
    reachable: int = 0
    reached: int = 0
    collisions: int = 0
    deadlock_aborts: int = 0
    other_aborts: int = 0
    unfinished: int = 0
    yields: int = 0
    sim_s: float = 0.0
    wall_s: float = 0.0
    failed_seeds: list[int] = field(default_factory=list)

    def add(self, seed: int, result: MissionResult) -> None:
        self.missions += 1
        self.reachable += result.reachable
        self.reached += result.reached
        self.collisions += result.collisions
        self.deadlock_aborts += result.deadlock_aborts
        self.other_aborts += result.other_aborts
        self.unfinished += result.unfinished
        self.yields += result.yields
        self.sim_s += result.sim_s
        self.wall_s += result.wall_s
        if result.reached < result.reachable or result.collisions:
            self.failed_seeds.append(seed)


def roomy_spots(costmap: Costmap, count: int, rng: np.random.Generator) -> list[Pose2D]:
    """``count`` random poses where a burger can turn with room to spare, at least 0.6 m
    apart (so robots never start overlapping)."""
    grid = costmap.grid
    roomy = costmap.free_mask() & (
        costmap.clearance >= 2.0 * TURTLEBOT3_BURGER.circumscribed_radius
    )
    rows, cols = np.nonzero(roomy)
    spots: list[Pose2D] = []
    for index in rng.permutation(rows.size):
        x, y = grid.cell_to_world(int(rows[index]), int(cols[index]))
        if all(np.hypot(x - s.x, y - s.y) >= 0.6 for s in spots):
            spots.append(Pose2D(x, y, float(rng.uniform(-np.pi, np.pi))))
            if len(spots) == count:
                break
    return spots


def mission_map(seed: int) -> OccupancyGrid:
    return office_map(seed) if seed % 2 == 0 else warehouse_map(seed)


def run_mission(seed: int, *, right_of_way: bool) -> MissionResult:
    rng = np.random.default_rng(seed)
    grid = mission_map(seed)
    count = int(rng.integers(2, 9))
    costmap = Costmap.from_grid(grid, SimSettings.of().costmap_params)
    starts = roomy_spots(costmap, count, rng)
    names = [f"r{i}" for i in range(len(starts))]
    queues: dict[str, list[Pose2D]] = {}
    result = MissionResult(robots=len(starts))
    for name, start in zip(names, starts, strict=True):
        waypoints = roomy_spots(costmap, WAYPOINTS_PER_ROBOT, rng)
        lengths = reach_lengths(costmap, (start.x, start.y), [(w.x, w.y) for w in waypoints])
        queues[name] = [
            w for w, length in zip(waypoints, lengths, strict=True) if np.isfinite(length)
        ]
        result.reachable += len(queues[name])
    fleet = FleetWorld(
        grid,
        [FleetRobot(name, start) for name, start in zip(names, starts, strict=True)],
        right_of_way=right_of_way,
    )
    sent: dict[str, Pose2D | None] = dict.fromkeys(names)

    def dispatch() -> None:
        for name, server in zip(names, fleet.servers, strict=True):
            goal = sent[name]
            if goal is not None and server.state is NavState.ACTIVE:
                continue
            if goal is not None:
                if server.state is NavState.SUCCEEDED:
                    result.reached += 1
                elif BLOCKED in server.status_text:
                    result.deadlock_aborts += 1
                else:
                    result.other_aborts += 1
                sent[name] = None
            if queues[name]:
                goal = sent[name] = queues[name].pop(0)
                server.set_goal(goal)

    started = time.perf_counter()
    dispatch()
    end = round(MISSION_LIMIT_S / fleet.dt)
    while fleet.steps < end and (fleet.busy() or any(sent.values())):
        fleet.step()
        dispatch()
    result.wall_s = time.perf_counter() - started
    result.sim_s = fleet.now
    result.collisions = fleet.collisions
    result.unfinished = sum(1 for goal in sent.values() if goal is not None)
    result.yields = fleet.right_of_way.yields_started if fleet.right_of_way else 0
    return result


def realtime_factor(robots: int, seconds: float, seed: int = 7) -> float:
    """Simulated seconds per wall second of ``robots`` robots patrolling random waypoints
    on one warehouse (``robots`` 0: one robot in a plain SimWorld)."""
    rng = np.random.default_rng(seed)
    grid = warehouse_map(seed)
    costmap = Costmap.from_grid(grid, SimSettings.of().costmap_params)
    pool = roomy_spots(costmap, 400, rng)
    count = max(robots, 1)
    starts = pool[:count]
    goals = pool[count:]
    lengths = reach_lengths(costmap, (starts[0].x, starts[0].y), [(g.x, g.y) for g in goals])
    goals = [g for g, length in zip(goals, lengths, strict=True) if np.isfinite(length)]
    picks = iter(goals * 50)
    step: Callable[[], None]
    if robots == 0:
        world = SimWorld(grid, starts[0], costmap=costmap)
        servers = [world.server]
        step = world.step
        dt = world.dt
    else:
        fleet = FleetWorld(grid, [FleetRobot(f"r{i}", s) for i, s in enumerate(starts)])
        servers = list(fleet.servers)
        step = fleet.step
        dt = fleet.dt
    for server in servers:
        server.set_goal(next(picks))
    steps = round(seconds / dt)
    started = time.perf_counter()
    for _ in range(steps):
        step()
        for server in servers:
            if server.state is not NavState.ACTIVE:
                server.set_goal(next(picks))
    return steps * dt / (time.perf_counter() - started)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--missions", type=int, default=100, help="random missions (seeds 0..N-1)")
    parser.add_argument("--quick", action="store_true", help="10 missions, shorter real-time runs")
    parser.add_argument(
        "--no-baseline", action="store_true", help="skip the run without right of way"
    )
    parser.add_argument("--verbose", action="store_true", help="one line per mission as it ends")
    args = parser.parse_args()
    missions = 10 if args.quick else args.missions
    seconds = 30.0 if args.quick else 120.0
    console = Console()

    table = Table(title=f"{missions} random fleet missions (2-8 robots, office and warehouse maps)")
    for column in (
        "right of way",
        "robots",
        "collisions",
        "deadlock aborts",
        "other aborts",
        "unfinished",
        "reachable reached",
        "sent aside",
        "sim s",
        "wall s",
        "failed seeds",
    ):
        table.add_column(column, justify="right")
    for right_of_way in (True, False) if not args.no_baseline else (True,):
        totals = Totals()
        robots = 0
        for seed in range(missions):
            result = run_mission(seed, right_of_way=right_of_way)
            if args.verbose:
                console.print(
                    f"seed {seed}: {result.robots} robots, reached {result.reached}/"
                    f"{result.reachable}, collisions {result.collisions}, deadlock aborts "
                    f"{result.deadlock_aborts}, sent aside {result.yields}, "
                    f"{result.sim_s:.0f} sim s in {result.wall_s:.1f} s",
                    highlight=False,
                )
            robots += result.robots
            totals.add(seed, result)
        table.add_row(
            "on" if right_of_way else "off (servers only)",
            str(robots),
            str(totals.collisions),
            str(totals.deadlock_aborts),
            str(totals.other_aborts),
            str(totals.unfinished),
            f"{totals.reached} / {totals.reachable}",
            str(totals.yields),
            f"{totals.sim_s:.0f}",
            f"{totals.wall_s:.1f}",
            " ".join(str(seed) for seed in totals.failed_seeds[:12]) or "-",
        )
    print_table(table, console)

    speed = Table(title=f"Real-time factor, {seconds:.0f} simulated s on a 30 m x 20 m warehouse")
    speed.add_column("robots", justify="right")
    speed.add_column("real-time factor", justify="right")
    for robots in (0, 1, 10, 20):
        label = "1 (plain SimWorld)" if robots == 0 else str(robots)
        speed.add_row(label, f"{realtime_factor(robots, seconds):.0f}x")
    print_table(speed, console)


if __name__ == "__main__":
    main()
