"""Loading and validating huge missions: time and peak memory of each reading path.

Writes a generated navseq YAML mission of 10 000 and 100 000 waypoints (each
``{name, x, y, yaw}`` on one line, as a recorded patrol is) and loads it in a fresh
process per measurement (``navseq.mission.load_mission``: read, parse, check every
field), reporting CPU seconds, wall seconds and the process's peak resident memory.
Three paths, side by side, each the one before plus one shortcut:

- "composer": PyYAML's composer and the located walker, then the general waypoint
  reader (what documents with anchors, tags or problems still take), with Python's
  cyclic garbage collector running as it did before loading paused it;
- "events": libyaml's parse events straight to located values, the plain-waypoint
  reader, the collector paused while reading;
- "lines": navseq now: runs of one-line ``- {key: value, ...}`` items read by regex
  (``navseq.mission.yaml_flow_lines``), the rest of the document by events.

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
import contextlib, json, resource, sys, time
from navseq.mission import loader, navseq_format, yaml_doc
from navseq.mission import load_mission
mode = sys.argv[2]
if mode in ("composer", "events"):
    yaml_doc.find_runs = lambda text: (text, {})
if mode == "composer":
    def refuse(self, text):
        raise yaml_doc._SlowPath
    yaml_doc._EventBuilder.build = refuse
    navseq_format._plain_waypoint = lambda node: None
    loader._collector_paused = contextlib.nullcontext
cpu, wall = time.process_time(), time.perf_counter()
mission = load_mission(sys.argv[1])
print(json.dumps({
    "cpu": time.process_time() - cpu,
    "wall": time.perf_counter() - wall,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    "waypoints": len(mission.waypoints),
}))
"""


MODES = ("composer", "events", "lines")


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
    return dict(json.loads(output))


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
            rows = {mode: measure(path, mode) for mode in MODES}
            assert all(row["waypoints"] == count for row in rows.values())
            size = f"{path.stat().st_size / 1e6:.1f}"
            first = rows[MODES[0]]
            for mode, row in rows.items():
                ratio = f"{first['cpu'] / row['cpu']:.1f}x" if mode != MODES[0] else ""
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
