"""Missions at scale: random missions on generated office and warehouse maps, pre-flighted
and then run on the embedded simulator (issue 8's "Done when").

Run:  .venv/bin/python benchmarks/bench_missions.py [--missions 100] [--seed 1] [--robot NAME]

Maps (:mod:`navseq.sim.mapgen`, seeded): offices (rooms off a corridor; doors and
passages 0.2 .. 1.0 m wide, some narrower than the robot's turning circle, furniture)
and warehouses (long shelf rows, aisles 0.9 .. 1.6 m, some blocked halfway: long
detours). Six in ten missions are on offices. Each mission has 4 .. 6 waypoints: most
drawn from open floor, one in four from any free cell (next to walls, in doorways), so
pre-flight has something to refuse; a roomy start pose.

Policies: the defaults (no goal timeout, no retry) with ``on_failure: skip``, so that
every waypoint is tried, run twice on the same missions: with ``stall_timeout`` 30 s
(the executor gives up on a robot making no progress) and without a stall limit (what
the robot and its navigation server achieve on their own). Only the waypoints pre-flight
accepts are run (what a user does after reading its messages).

Columns:
- accepted / reached: waypoints pre-flight accepted, and those the robot reached;
- false stalls: accepted waypoints given up for "stalled" (the goal was reachable);
  "of which on plan": the robot was getting closer along its plan all the while — the
  executor's stall measure compared a straight-line distance with one along the plan;
- trapped: missions after which the robot, sent back to its start, cannot get there;
- collisions: moves the simulated body refused (should be 0: the server stops first);
- efficiency: time to reach a waypoint / (length of the plan from where the leg began
  / top speed), as in bench_sim.py (1 = driving the plan at top speed all the way;
  median and max over reached waypoints with a plan over 0.5 m).

Targets: no false stall, no trapped robot, every accepted waypoint reached.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np
from rich.console import Console
from rich.table import Table

from navseq.executor.events import (
    AttemptFailed,
    MissionEvent,
    WaypointOutcome,
    WaypointProgress,
    WaypointStarted,
)
from navseq.executor.runner import run_mission
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction, Mission, Policy, Waypoint
from navseq.mission.robot import BUILTIN_PROFILES, DEFAULT_PROFILE, RobotProfile
from navseq.navigators.sim import SimNavigator
from navseq.preflight import check_mission
from navseq.sim.costmap import Costmap
from navseq.sim.mapgen import office_map, warehouse_map
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.planner import plan_path
from navseq.sim.profile import SimSettings
from navseq.sim.world import SimWorld

POLICIES = {
    "stall 30 s": Policy(stall_timeout_s=30.0, on_failure=FailureAction.SKIP),
    # The same without the executor's stall measure: what the robot itself achieves.
    "no stall limit": Policy(on_failure=FailureAction.SKIP),
}
MISSIONS_PER_MAP = 10
GO_HOME_SECONDS = 600.0


@dataclass
class KindStats:
    """What the missions on one kind of map came to."""

    kind: str
    policy: str
    maps: int = 0
    missions: int = 0
    waypoints: int = 0
    accepted: int = 0
    reached: int = 0
    false_stalls: int = 0
    stalls_on_plan: int = 0  # ... while the robot was getting closer along its plan
    other_failures: int = 0
    trapped: int = 0
    collisions: int = 0
    efficiency: list[float] = field(default_factory=list)
    wall_time: float = 0.0
    failures: list[str] = field(default_factory=list)


def random_mission(
    costmap: Costmap, rng: np.random.Generator, name: str, waypoints: tuple[int, int] = (4, 6)
) -> Mission:
    # The policy is set per run (POLICIES).
    """A mission with a roomy start and ``waypoints`` (min, max) random waypoints."""
    grid = costmap.grid
    known_free = (grid.data == 0) & (costmap.clearance > 0.0)
    open_floor = known_free & (costmap.clearance >= 0.3)
    roomy = known_free & (costmap.clearance >= 0.5)

    def pick(mask: np.ndarray) -> tuple[float, float]:
        rows, cols = np.nonzero(mask)
        index = int(rng.integers(rows.size))
        x, y = grid.cell_to_world(int(rows[index]), int(cols[index]))
        # Anywhere in the cell, not only its centre.
        jitter = rng.uniform(-0.5, 0.5, size=2) * grid.resolution
        return float(x + jitter[0]), float(y + jitter[1])

    start_x, start_y = pick(roomy)
    start = Pose2D(start_x, start_y, math.radians(45.0 * int(rng.integers(8))))
    count = int(rng.integers(waypoints[0], waypoints[1] + 1))
    points = []
    for number in range(count):
        x, y = pick(known_free if rng.random() < 0.25 else open_floor)
        yaw = math.radians(45.0 * int(rng.integers(8)))
        points.append(
            Waypoint(x, y, yaw_rad=yaw, name=f"p{number + 1}", where=f"{name}:{number + 1}")
        )
    return Mission(waypoints=tuple(points), start=start, source=name)


def accepted_part(mission: Mission, costmap: Costmap, robot: RobotProfile) -> Mission:
    """The mission without the waypoints pre-flight refuses.

    Again until pre-flight has nothing to say: dropping a waypoint the robot cannot get
    to from the start makes the next one's predecessor the start pose.
    """
    while mission.waypoints:
        problems = check_mission(mission, costmap, robot=robot)
        if not problems:
            break
        refused = {problem.subject for problem in problems}
        kept = tuple(
            waypoint
            for index, waypoint in enumerate(mission.waypoints)
            if waypoint.label(index) not in refused
        )
        mission = dataclasses.replace(mission, waypoints=kept)
    return mission


def run_one(
    mission: Mission, grid: OccupancyGrid, costmap: Costmap, sim: SimSettings, stats: KindStats
) -> None:
    """Pre-flight, run the accepted waypoints, and add what happened to ``stats``."""
    stats.missions += 1
    stats.waypoints += len(mission.waypoints)
    runnable = accepted_part(mission, costmap, sim.profile)
    stats.accepted += len(runnable.waypoints)
    if not runnable.waypoints:
        return
    assert mission.start is not None
    world = SimWorld(
        grid, mission.start, costmap=costmap, nav_params=sim.nav_params, footprint=sim.footprint
    )
    watch = _StallWatch(runnable.defaults.stall_timeout_s or 0.0)
    result = run_mission(runnable, SimNavigator(world), [watch])
    stats.stalls_on_plan += watch.stalls_on_plan
    leg_start: Pose2D | None = mission.start  # None: where the robot gave up, unknown
    failed = False
    for visit in result.visits:
        goal = Pose2D(visit.x, visit.y, visit.yaw_rad)
        if visit.outcome is WaypointOutcome.REACHED:
            stats.reached += 1
            if leg_start is not None:
                plan = plan_path(costmap, (leg_start.x, leg_start.y), (goal.x, goal.y))
                if plan is not None and plan.length > 0.5:
                    bound = plan.length / sim.profile.max_linear_speed
                    stats.efficiency.append(visit.duration / bound)
            leg_start = goal
        else:
            failed = True
            if "stalled" in visit.reason:
                stats.false_stalls += 1
            else:
                stats.other_failures += 1
            stats.failures.append(f"{stats.policy}: {mission.source} {visit.name}: {visit.reason}")
            leg_start = None
    stats.collisions += world.collisions
    if failed and not _goes_home(world, mission.start):
        stats.trapped += 1
        stats.failures.append(f"{stats.policy}: {mission.source}: trapped at {world.robot.pose}")


class _StallWatch:
    """Tells stalls of a robot that was getting closer along its plan from real ones.

    The executor's stall measure is being fixed (it compared a straight-line distance
    with a distance along the plan); a stall where the plan's remaining length fell by
    0.2 m or more within the stall timeout is that measure's, not the robot's.
    """

    def __init__(self, stall_timeout: float) -> None:
        self.stall_timeout = stall_timeout
        self.remaining: list[tuple[float, float]] = []  # (t, along-the-plan distance)
        self.stalls_on_plan = 0

    def __call__(self, event: MissionEvent) -> None:
        if isinstance(event, WaypointStarted):
            self.remaining = []
        elif isinstance(event, WaypointProgress) and event.distance_remaining is not None:
            self.remaining.append((event.t, event.distance_remaining))
        elif isinstance(event, AttemptFailed) and event.reason == "stalled":
            recent = [d for t, d in self.remaining if t >= event.t - self.stall_timeout]
            # The first reports may be straight-line distances (before a plan): measure
            # from the largest.
            if recent and max(recent) - recent[-1] >= 0.2:
                self.stalls_on_plan += 1


def _goes_home(world: SimWorld, home: Pose2D) -> bool:
    """True if the robot, after the mission, can still drive back to its start."""
    world.server.set_goal(home)
    for _ in range(round(GO_HOME_SECONDS / world.dt)):
        world.step()
        if world.server.state is not NavState.ACTIVE:
            break
    return world.server.state is NavState.SUCCEEDED


MAP_KINDS: dict[str, Callable[[int], OccupancyGrid]] = {
    "office": office_map,
    "warehouse": warehouse_map,
}


def mission_plan(total: int, seed: int) -> Iterator[tuple[str, int, int]]:
    """(kind, map seed, missions on it): six in ten missions on offices."""
    shares = {"office": round(total * 0.6), "warehouse": total - round(total * 0.6)}
    for offset, (kind, count) in enumerate(shares.items()):
        map_number = 0
        while count > 0:
            on_this = min(MISSIONS_PER_MAP, count)
            yield kind, seed * 1000 + offset * 100 + map_number, on_this
            count -= on_this
            map_number += 1


def run_benchmark(
    total: int,
    seed: int,
    robot: RobotProfile = DEFAULT_PROFILE,
    waypoints: tuple[int, int] = (4, 6),
    policies: dict[str, Policy] = POLICIES,
) -> list[KindStats]:
    """One row per map kind and policy; the same missions under every policy."""
    sim = SimSettings.of(robot)
    table = {(kind, policy): KindStats(kind, policy) for kind in MAP_KINDS for policy in policies}
    for kind, map_seed, count in mission_plan(total, seed):
        began = time.perf_counter()
        grid = MAP_KINDS[kind](map_seed)
        costmap = Costmap.from_grid(grid, sim.costmap_params)
        built = time.perf_counter() - began
        rng = np.random.default_rng(map_seed)
        missions = [
            random_mission(costmap, rng, f"{grid.source}#{number + 1}", waypoints)
            for number in range(count)
        ]
        for name, policy in policies.items():
            stats = table[(kind, name)]
            began = time.perf_counter()
            stats.maps += 1
            for mission in missions:
                mission = dataclasses.replace(mission, defaults=policy)
                run_one(mission, grid, costmap, sim, stats)
            stats.wall_time += built + time.perf_counter() - began
    return [stats for stats in table.values() if stats.missions]


def print_table(rows: list[KindStats], robot: RobotProfile) -> None:
    table = Table(title=f"navseq missions on generated maps — robot {robot.name}")
    for column in (
        "map kind", "policy", "maps", "missions", "waypoints", "accepted by pre-flight", "reached",
        "false stalls", "of which on plan", "other failures", "trapped robots", "collisions",
        "efficiency median", "efficiency max", "wall time [s]",
    ):  # fmt: skip
        table.add_column(column, justify="right" if column != "map kind" else "left")
    for stats in rows:
        ratios = stats.efficiency
        table.add_row(
            stats.kind, stats.policy, str(stats.maps), str(stats.missions), str(stats.waypoints),
            str(stats.accepted), str(stats.reached), str(stats.false_stalls),
            str(stats.stalls_on_plan),
            str(stats.other_failures), str(stats.trapped), str(stats.collisions),
            f"{statistics.median(ratios):.2f}" if ratios else "-",
            f"{max(ratios):.2f}" if ratios else "-",
            f"{stats.wall_time:.1f}",
        )  # fmt: skip
    console = Console(width=220)
    console.print(table)
    for stats in rows:
        for failure in stats.failures:
            console.print(f"  {failure}", highlight=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--missions", type=int, default=100, help="missions in total")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--robot", choices=sorted(BUILTIN_PROFILES), default=DEFAULT_PROFILE.name)
    args = parser.parse_args()
    robot = BUILTIN_PROFILES[args.robot]
    print_table(run_benchmark(args.missions, args.seed, robot), robot)


if __name__ == "__main__":
    main()
