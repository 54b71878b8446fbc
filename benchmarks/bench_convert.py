"""Writing a huge mission as navseq YAML (``navseq convert``): PyYAML's emitter against
the line writer, time and peak memory of each.

Writes a generated navseq YAML mission of 10 000 and 100 000 waypoints (each
``{name, x, y, yaw}`` on one line, as a recorded patrol is), loads it, then writes it
back in a fresh process per measurement, reporting the writing's CPU and wall seconds
and the process's peak resident memory (loading included: ``navseq convert`` does
both). Two paths, side by side, on the same mission:

- "pyyaml": every line written by PyYAML's emitter (``dump_mission_yaml_slowly``, what
  ``navseq convert`` did);
- "lines": navseq now: the settings by PyYAML, the waypoints' lines by
  ``navseq.mission.writer`` itself, the same text (checked here).

    .venv/bin/python benchmarks/bench_convert.py [--sizes 10000 100000]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_load import write_mission
from rich.console import Console
from rich.table import Table

# Runs in the child process: load, then write once; CPU, wall, peak memory and digest.
CHILD = """
import hashlib, json, resource, sys, time
from navseq.mission import load_mission
from navseq.mission import writer
mission = load_mission(sys.argv[1])
dump = writer.dump_mission_yaml_slowly if sys.argv[2] == "pyyaml" else writer.dump_mission_yaml
cpu, wall = time.process_time(), time.perf_counter()
text = dump(mission)
print(json.dumps({
    "cpu": time.process_time() - cpu,
    "wall": time.perf_counter() - wall,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    "sha256": hashlib.sha256(text.encode()).hexdigest(),
}))
"""

MODES = ("pyyaml", "lines")


def measure(path: Path, mode: str) -> dict[str, object]:
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
    table = Table(title="writing a loaded mission as navseq YAML (navseq convert)")
    for header in ("waypoints", "path", "write CPU s", "write wall s", "peak RSS MB", "speed-up"):
        table.add_column(header, justify="right")
    with tempfile.TemporaryDirectory() as folder:
        for count in args.sizes:
            path = Path(folder) / f"m{count}.yaml"
            write_mission(path, count)
            rows = {mode: measure(path, mode) for mode in MODES}
            digests = {row["sha256"] for row in rows.values()}
            assert len(digests) == 1, "the two paths wrote different text"
            first = rows[MODES[0]]
            for mode, row in rows.items():
                speed_up = float(first["cpu"]) / float(row["cpu"])  # type: ignore[arg-type]
                ratio = f"{speed_up:.0f}x" if mode != MODES[0] else ""
                table.add_row(
                    f"{count:,}",
                    mode,
                    f"{row['cpu']:.2f}",
                    f"{row['wall']:.2f}",
                    f"{row['peak_mb']:.0f}",
                    ratio,
                )
    Console().print(table)


if __name__ == "__main__":
    main()
