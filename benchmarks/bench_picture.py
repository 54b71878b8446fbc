"""How long the mission picture takes to draw, from 10 to 100 000 waypoints.

A run that gets a signal waits for its picture before it exits, so the picture must
be drawn in bounded time whatever the mission. Each size is a seeded mission on a
30 x 20 m warehouse map: waypoints on free cells, a driven trajectory through them
(``--points-per-leg`` positions per leg, up to a million rows), the last 1000 legs'
plans, 70 % of the waypoints run (every 37th skipped, then one failed, the rest not
run). With ``--before REF`` the same inputs are drawn by the picture module of git
``REF`` too (sizes up to ``--before-max``), side by side: 46a4aae is the last commit
before the picture learnt to thin.

    .venv/bin/python benchmarks/bench_picture.py
    .venv/bin/python benchmarks/bench_picture.py --before 46a4aae --out /tmp/pictures
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
from rich.console import Console
from rich.table import Table

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult, WaypointResult
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.sim.mapgen import warehouse_map
from navseq.sim.occupancy import OccupancyGrid
from navseq.sinks.picture import draw as picture

ROOT = Path(__file__).resolve().parents[1]


def scenario(size: int, points_per_leg: int, seed: int = 7) -> dict[str, Any]:
    """The arguments of ``mission_picture_png`` for a seeded ``size``-waypoint run."""
    rng = np.random.default_rng(seed)
    grid: OccupancyGrid = warehouse_map(seed)
    rows, cols = np.nonzero(grid.data == 0)
    chosen = rng.choice(len(rows), size=size, replace=size > len(rows))
    xy = grid.cells_to_world(rows[chosen], cols[chosen])
    yaws = rng.uniform(-np.pi, np.pi, size)
    waypoints = tuple(
        Waypoint(float(x), float(y), yaw_rad=float(yaw), name=f"p{i + 1}" if i % 10 == 0 else None)
        for i, ((x, y), yaw) in enumerate(zip(xy, yaws, strict=True))
    )
    mission = Mission(waypoints, source=f"warehouse-{size}.yaml")
    ran = max(1, int(0.7 * size))
    visits = []
    for i in range(size):
        if i < ran - 1:
            outcome = WaypointOutcome.SKIPPED if i % 37 == 36 else WaypointOutcome.REACHED
        elif i == ran - 1 and size > 1:
            outcome = WaypointOutcome.FAILED
        else:
            outcome = WaypointOutcome.NOT_RUN
        visits.append(WaypointResult(i, 0, None, xy[i, 0], xy[i, 1], yaws[i], outcome=outcome))
    result = MissionResult(False, "stopped: a waypoint failed", visits, 3600.0, 1234.5)
    start = Pose2D(float(xy[0, 0]) - 0.5, float(xy[0, 1]), 0.0)
    # Driven: straight legs through the waypoints that ran, ``points_per_leg`` rows each.
    path = np.vstack([[start.x, start.y], xy[:ran]])
    legs = min(len(path) - 1, max(1, 1_000_000 // points_per_leg))
    fractions = np.linspace(0.0, 1.0, points_per_leg, endpoint=False)
    heads, tails = path[-legs - 1 : -1], path[-legs:]
    rows_xy = (heads[:, None, :] + fractions[None, :, None] * (tails - heads)[:, None, :]).reshape(
        -1, 2
    )
    times = np.linspace(0.0, 3600.0, len(rows_xy))
    trajectory = np.column_stack((times, rows_xy))
    plans = [
        ((float(a[0]), float(a[1])), (float(a[0]), float(b[1])), (float(b[0]), float(b[1])))
        for a, b in zip(heads[-1000:], tails[-1000:], strict=True)
    ]
    return {
        "mission": mission,
        "result": result,
        "grid": grid,
        "start": start,
        "plans": plans,
        "trajectory": [tuple(row) for row in trajectory],
    }


def module_at(ref: str) -> ModuleType:
    """``navseq.sinks.picture.draw`` as it is at git ``ref`` (for a before/after table)."""
    # The module moved into a package (sinks/picture.py -> sinks/picture/draw.py).
    for path_at_ref in ("src/navseq/sinks/picture/draw.py", "src/navseq/sinks/picture.py"):
        shown = subprocess.run(
            ["git", "-C", str(ROOT), "show", f"{ref}:{path_at_ref}"],
            capture_output=True,
            text=True,
        )
        if shown.returncode == 0:
            break
    shown.check_returncode()
    source = shown.stdout
    folder = Path(tempfile.mkdtemp())
    path = folder / "picture_before.py"
    path.write_text(source, encoding="utf-8")
    spec = importlib.util.spec_from_file_location("picture_before", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["picture_before"] = module
    spec.loader.exec_module(module)
    return module


def timed(module: ModuleType, arguments: dict[str, Any], repeat: int) -> tuple[float, bytes]:
    best, png = float("inf"), b""
    for _ in range(repeat):
        began = time.perf_counter()
        png = module.mission_picture_png(**arguments)
        best = min(best, time.perf_counter() - began)
    return best, png


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,1000,100000", help="waypoint counts")
    parser.add_argument("--points-per-leg", type=int, default=10)
    parser.add_argument("--repeat", type=int, default=3, help="best of N")
    parser.add_argument("--before", metavar="REF", help="also time the picture at git REF")
    parser.add_argument("--before-max", type=int, default=1000, help="largest size for --before")
    parser.add_argument("--out", type=Path, help="write the PNGs into this folder")
    args = parser.parse_args()

    before = module_at(args.before) if args.before else None
    table = Table(title=f"mission picture: draw time (best of {args.repeat})")
    for header in ("waypoints", "trajectory rows", "plans", "now s", "PNG kB"):
        table.add_column(header, justify="right")
    if before is not None:
        table.add_column(f"{args.before} s", justify="right")
        table.add_column("speed-up", justify="right")
    for size in (int(s) for s in args.sizes.split(",")):
        arguments = scenario(size, args.points_per_leg)
        seconds, png = timed(picture, arguments, args.repeat)
        row = [
            f"{size:,}",
            f"{len(arguments['trajectory']):,}",
            f"{len(arguments['plans']):,}",
            f"{seconds:.2f}",
            f"{len(png) / 1e3:.0f}",
        ]
        if before is not None:
            if size <= args.before_max:
                old, old_png = timed(before, arguments, 1)
                row += [f"{old:.2f}", f"{old / seconds:.1f}x"]
                if args.out:
                    (args.out / f"bench-{size}-{args.before}.png").write_bytes(old_png)
            else:
                row += ["-", "-"]
        if args.out:
            args.out.mkdir(parents=True, exist_ok=True)
            (args.out / f"bench-{size}.png").write_bytes(png)
        table.add_row(*row)
    Console().print(table)


if __name__ == "__main__":
    main()
