"""Loading and validating huge missions: time and peak memory, fast path against slow.

Writes a generated navseq YAML mission of 10 000 and 100 000 waypoints (each
``{name, x, y, yaw}``, as a recorded patrol would be) and loads it in a fresh process
per measurement (``navseq.mission.load_mission``: read, parse, check every field),
reporting CPU seconds, wall seconds and the process's peak resident memory. "slow"
forces the paths every document took before the fast ones (PyYAML's composer and
the located walker; the general waypoint reader), which remain for documents the
fast path does not take (aliases, tags, problems); "fast" is what navseq does now.

    .venv/bin/python benchmarks/bench_load.py [--sizes 10000 100000]
"""

from __future__ import annotations

import argparse
import json
import random
import subprocess
import sys
import tempfile
from pathlib import Path

from rich.console import Console
from rich.table import Table

# Runs in the child process: load once, print CPU, wall and peak memory as JSON.
CHILD = """
import json, resource, sys, time
from navseq.mission import yaml_doc, navseq_format
from navseq.mission import load_mission
if sys.argv[2] == "slow":
    def refuse(self, text):
        raise yaml_doc._SlowPath
    yaml_doc._EventBuilder.build = refuse
    navseq_format._plain_waypoint = lambda node: None
cpu, wall = time.process_time(), time.perf_counter()
mission = load_mission(sys.argv[1])
print(json.dumps({
    "cpu": time.process_time() - cpu,
    "wall": time.perf_counter() - wall,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    "waypoints": len(mission.waypoints),
}))
"""


def write_mission(path: Path, count: int) -> None:
    rng = random.Random(count)
    lines = ["navseq: 1", "frame: map", "loops: 1", "waypoints:"]
    lines += [
        f"  - {{name: wp{i}, x: {rng.uniform(-50, 50):.3f}, y: {rng.uniform(-50, 50):.3f}, "
        f"yaw: {rng.randint(-180, 180)}}}"
        for i in range(count)
    ]
    path.write_text("\n".join(lines) + "\n")


def measure(path: Path, mode: str) -> dict[str, float]:
    output = subprocess.run(
        [sys.executable, "-c", CHILD, str(path), mode],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(output)  # type: ignore[no-any-return]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    args = parser.parse_args()
    table = Table(title="load_mission of a generated navseq YAML mission")
    for header in ("waypoints", "MB", "path", "CPU s", "wall s", "peak RSS MB", "speed-up"):
        table.add_column(header, justify="right")
    with tempfile.TemporaryDirectory() as folder:
        for count in args.sizes:
            path = Path(folder) / f"m{count}.yaml"
            write_mission(path, count)
            slow, fast = measure(path, "slow"), measure(path, "fast")
            assert slow["waypoints"] == fast["waypoints"] == count
            size = f"{path.stat().st_size / 1e6:.1f}"
            for mode, row in (("slow", slow), ("fast", fast)):
                ratio = f"{slow['cpu'] / row['cpu']:.1f}x" if mode == "fast" else ""
                table.add_row(
                    f"{count:,}",
                    size,
                    mode,
                    f"{row['cpu']:.2f}",
                    f"{row['wall']:.2f}",
                    f"{row['peak_mb']:.0f}",
                    ratio,
                )
    Console().print(table)


if __name__ == "__main__":
    main()
