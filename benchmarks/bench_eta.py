"""The mission ETA against the actual end, on the embedded simulator.

Each mission runs on the simulator (simulated time, as fast as the CPU goes) through
the run service, as ``navseq run`` runs it, and its report's ``eta`` section is read:
the predicted end before the start (0 %) and the latest ones at 25, 50 and 75 % of
the actual duration, against the actual end; beside them the naive figure (every
planned leg at the robot's top speed, plus dwell), and in the summary the same live
estimate without the correction by achieved speed. Missions:

- the example missions that run on the simulator (``examples/*.yaml`` with a map; a
  patrol that loops forever is run for ``--patrol-loops`` loops);
- ``--seeds`` random missions on generated office maps (:func:`office_map`: rooms,
  corridor, doors; saved as map_server YAML + PGM in a temporary folder): 4 to 7
  waypoints at roomy free spots of the map's largest connected region, random yaw, a
  third of them passed through (0.3 m), one in five with a dwell of 1 to 3 s.

A mission in which some attempt failed (a retry, a skip) is listed but marked: its
actual end includes time the plan does not know of.

    .venv/bin/python benchmarks/bench_eta.py [--seeds 20] [--patrol-loops 2]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from navseq.commands.common import costmap_for_robot
from navseq.eta.live import EtaEstimator
from navseq.executor.events import AttemptFailed, MissionEvent
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.run import RunRequest, Session, prepare
from navseq.sim.mapgen import office_map, save_map
from navseq.sinks.summary import print_table

ROOT = Path(__file__).resolve().parents[1]
CHECKPOINTS = (0, 25, 50, 75)


@dataclass
class Measured:
    name: str
    actual_s: float
    predicted_s: dict[int, float]  # at percent -> predicted duration
    failed_attempts: int
    naive_s: float  # planned length / top speed + dwell: the figure navseq plan gave before
    uncorrected_s: dict[int, float]  # at percent -> predicted, not corrected by achieved speed

    @property
    def naive_error_percent(self) -> float:
        return 100.0 * (self.naive_s - self.actual_s) / self.actual_s

    def error_percent(self, at: int, corrected: bool = True) -> float:
        predicted = self.predicted_s if corrected else self.uncorrected_s
        return 100.0 * (predicted[at] - self.actual_s) / self.actual_s


def run_measured(name: str, mission: Path, loops: int | None = None) -> Measured:
    """Run ``mission`` on the simulator; its ETA's predictions against its actual end."""
    failures: list[AttemptFailed] = []

    def listen(event: MissionEvent) -> None:
        if isinstance(event, AttemptFailed):
            failures.append(event)

    request = RunRequest(mission=mission, outputs=None, loops=loops)
    session = prepare(request)
    estimator = session.eta()
    assert estimator is not None
    # The same prediction followed without the correction by achieved speed, side by side.
    plain = EtaEstimator(estimator.prediction, correct_by_achieved_speed=False)
    session.run([plain, listen])
    accuracy = estimator.accuracy() if estimator is not None else None
    if accuracy is None:
        raise SystemExit(f"{name}: no ETA accuracy (the mission did not end?)")
    predicted = {c["at_percent"]: c["predicted_s"] for c in accuracy["checkpoints"]}
    uncorrected = plain.accuracy()
    assert uncorrected is not None
    plain_predicted = {c["at_percent"]: c["predicted_s"] for c in uncorrected["checkpoints"]}
    return Measured(
        name, accuracy["actual_s"], predicted, len(failures), naive_s(session), plain_predicted
    )


def naive_s(session: Session) -> float:
    """Every visit's planned length at the robot's top speed, plus dwell: no turns, no
    acceleration, no slowing (what ``navseq plan`` printed before the ETA model)."""
    from navseq.route.legs import LegPlanner

    mission, robot = session.mission, session.robot
    assert session.grid is not None and session.start is not None and mission.loops is not None
    planner = LegPlanner(costmap_for_robot(session.grid, robot))
    seconds, where = 0.0, (session.start.x, session.start.y)
    for _ in range(mission.loops):
        for index, waypoint in enumerate(mission.waypoints):
            length = planner.leg(where, (waypoint.x, waypoint.y)).length_m or 0.0
            seconds += length / robot.max_linear_speed + mission.policy_for(index).dwell_s
            where = (waypoint.x, waypoint.y)
    return seconds


def roomy_spots(grid_yaml: Path, count: int, rng: np.random.Generator) -> list[tuple[float, float]]:
    """``count`` random spots where the robot turns freely, in the largest free region."""
    from scipy import ndimage

    from navseq.sim.occupancy import load_map

    costmap = costmap_for_robot(load_map(grid_yaml))
    free = costmap.free_mask()
    roomy = free & (costmap.clearance >= 0.35 + costmap.params.circumscribed_radius)
    labels, _ = ndimage.label(free, structure=np.ones((3, 3), bool))
    main = np.bincount(labels[labels > 0]).argmax()
    cells = np.argwhere(roomy & (labels == main))
    chosen = cells[rng.choice(len(cells), size=count, replace=False)]
    return [costmap.cell_to_world(int(row), int(col)) for row, col in chosen]


def office_mission(folder: Path, seed: int) -> Path:
    """A random mission on office map ``seed``, written beside its map; returns its path."""
    map_yaml = save_map(office_map(seed), folder / f"office-{seed}.yaml")
    rng = np.random.default_rng(1000 + seed)
    count = int(rng.integers(4, 8))
    spots = roomy_spots(map_yaml, count + 1, rng)
    (sx, sy), waypoints = spots[0], spots[1:]
    lines = [
        "navseq: 1",
        f"map: {map_yaml.name}",
        f"start: {{x: {sx:.2f}, y: {sy:.2f}, yaw: {int(rng.integers(-180, 180))}}}",
        "defaults: {goal_timeout: 300, stall_timeout: 60, retries: 1, on_failure: skip}",
        "waypoints:",
    ]
    for number, (x, y) in enumerate(waypoints, 1):
        extra = ""
        if rng.random() < 1 / 3:
            extra += ", pass_through: 0.3"
        if rng.random() < 0.2:
            extra += f", dwell: {int(rng.integers(1, 4))}"
        yaw = int(rng.integers(-180, 180))
        lines.append(f"  - {{name: p{number}, x: {x:.2f}, y: {y:.2f}, yaw: {yaw}{extra}}}")
    path = folder / f"office-{seed}-mission.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--patrol-loops", type=int, default=2)
    args = parser.parse_args()
    runs: list[Measured] = [
        run_measured("examples/turtlebot3_world.yaml", ROOT / "examples" / "turtlebot3_world.yaml"),
        run_measured(
            f"examples/patrol.yaml ({args.patrol_loops} loops)",
            ROOT / "examples" / "patrol.yaml",
            loops=args.patrol_loops,
        ),
    ]
    with tempfile.TemporaryDirectory(prefix="bench-eta-") as folder:
        for seed in range(args.seeds):
            path = office_mission(Path(folder), seed)
            runs.append(run_measured(f"office map {seed}", path))
    robot = DEFAULT_PROFILE.name
    table = Table(title=f"mission ETA vs actual end on the simulator ({robot})")
    headers = ("mission", "actual [s]", "naive [s]", *(f"at {c} %" for c in CHECKPOINTS), "note")
    for header in headers:
        table.add_column(escape(header), justify="left" if header == "mission" else "right")
    for run in runs:
        cells = [
            f"{run.predicted_s[c]:.1f} ({run.error_percent(c):+.1f} %)"
            if c in run.predicted_s
            else "-"
            for c in CHECKPOINTS
        ]
        note = f"{run.failed_attempts} failed attempts" if run.failed_attempts else ""
        naive = f"{run.naive_s:.1f} ({run.naive_error_percent:+.1f} %)"
        table.add_row(escape(run.name), f"{run.actual_s:.1f}", naive, *cells, note)
    print_table(table, Console())
    clean = [run for run in runs if not run.failed_attempts]
    for label, chosen in (("all", runs), ("no failed attempt", clean)):
        if not chosen:
            continue
        parts = []
        for c in CHECKPOINTS:
            errors = [abs(run.error_percent(c)) for run in chosen if c in run.predicted_s]
            within = sum(error <= 3.0 for error in errors)
            parts.append(
                f"at {c} %: mean |error| {statistics.fmean(errors):.1f} %, "
                f"max {max(errors):.1f} %, {within}/{len(errors)} within 3 %"
            )
        for c in CHECKPOINTS[1:]:
            plain = [abs(run.error_percent(c, False)) for run in chosen if c in run.uncorrected_s]
            parts.append(
                f"not corrected by achieved speed at {c} %: mean |error| "
                f"{statistics.fmean(plain):.1f} %, max {max(plain):.1f} %"
            )
        naive_errors = [abs(run.naive_error_percent) for run in chosen]
        parts.append(
            f"naive: mean |error| {statistics.fmean(naive_errors):.1f} %, "
            f"max {max(naive_errors):.1f} %"
        )
        print(f"{label} ({len(chosen)} missions): " + "; ".join(parts))


if __name__ == "__main__":
    main()
