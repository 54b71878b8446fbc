"""How long ``navseq run`` takes to exit after SIGTERM, for long runs and huge missions.

The promise: a signal ends the run within about 2 s whatever the mission's size or
age: the goal is cancelled at once, then the report and the picture are written (the
picture thins what it draws) and the process exits 143. Measured here, each case in
a fresh ``navseq run`` subprocess on the embedded simulator, ``--repeat`` times:

- a patrol (``examples/patrol.yaml``, loops forever) signalled after ``--patrol-hours``
  of simulated time;
- a 100 000-waypoint mission (the room of ``tests/test_huge_mission.py``) signalled
  after its first visit finished.

For each: the time from SIGTERM to the process's exit (and the CPU time the process
used in it: on a shared, loaded machine the wall time is several times that), its exit
status, whether the report says SIGTERM, and the peak resident memory. (A patrol
resumed from a journal of 10⁶ simulated seconds is measured by
``benchmarks/bench_long_run.py``.)

    .venv/bin/python benchmarks/bench_shutdown.py --patrol-hours 4 --repeat 3
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from rich.console import Console
from rich.table import Table

ROOT = Path(__file__).resolve().parents[1]
PATROL = ROOT / "examples" / "patrol.yaml"
sys.path.insert(0, str(ROOT / "tests"))
from test_huge_mission import write_room_mission  # noqa: E402  (the tests' own mission)


@dataclass
class Stopped:
    signal_to_exit_s: float
    cpu_after_signal_s: float  # the process's CPU time from SIGTERM to exit
    wall_before_signal_s: float
    simulated_s: float
    exit_code: int
    report_says_sigterm: bool
    peak_mb: float


def cpu_seconds(pid: int) -> float:
    """User + system CPU time a live process has used so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def run_and_signal(mission: Path, out: Path, ready: str, after_s: float) -> Stopped:
    """``navseq run MISSION --json``; SIGTERM at the first ``ready`` event at or after
    ``after_s`` of simulated time; measure until the process has exited."""
    started = time.perf_counter()
    process = subprocess.Popen(
        [sys.executable, "-m", "navseq", "run", str(mission), "--json", "--out", str(out)],
        cwd=mission.parent,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None
    simulated = 0.0
    for line in process.stdout:
        record = json.loads(line)
        simulated = float(record.get("t_s", simulated))
        if record.get("event") == ready and simulated >= after_s:
            break
    else:
        raise RuntimeError(f"navseq run ended early: {process.communicate()[1]}")
    cpu_before = cpu_seconds(process.pid)
    signalled = time.perf_counter()
    process.send_signal(signal.SIGTERM)
    process.stdout.read()  # keep the pipe drained, as a terminal would
    _, status, usage = os.wait4(process.pid, 0)
    ended = time.perf_counter()
    process.returncode = code = os.waitstatus_to_exitcode(status)
    try:
        report = json.loads((out / "report.json").read_text())
    except (OSError, ValueError):
        report = {}
    return Stopped(
        signal_to_exit_s=ended - signalled,
        cpu_after_signal_s=usage.ru_utime + usage.ru_stime - cpu_before,
        wall_before_signal_s=signalled - started,
        simulated_s=simulated,
        exit_code=code,
        report_says_sigterm=report.get("interrupted") == "SIGTERM"
        and report.get("exit_code") == code,
        peak_mb=usage.ru_maxrss / 1024.0,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--patrol-hours", type=float, default=4.0, help="simulated hours")
    parser.add_argument("--waypoints", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    table = Table(title="SIGTERM to exit, navseq run on the embedded simulator")
    for header in (
        "run",
        "signalled after (simulated)",
        "wall before the signal",
        "SIGTERM to exit: median",
        "max",
        "CPU after the signal: median",
        "exit",
        "report says SIGTERM",
        "peak MB",
    ):
        table.add_column(header, justify="right")
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        huge = write_room_mission(folder, args.waypoints)
        cases = [
            ("patrol.yaml, loops forever", PATROL, "WaypointProgress", args.patrol_hours * 3600),
            (f"{args.waypoints:,} waypoints", huge, "WaypointFinished", 0.0),
        ]
        for name, mission, ready, after in cases:
            runs = [
                run_and_signal(mission, folder / f"out-{len(name)}-{n}", ready, after)
                for n in range(args.repeat)
            ]
            times = [r.signal_to_exit_s for r in runs]
            table.add_row(
                name,
                f"{statistics.median(r.simulated_s for r in runs):,.0f} s",
                f"{statistics.median(r.wall_before_signal_s for r in runs):.0f} s",
                f"{statistics.median(times):.2f} s",
                f"{max(times):.2f} s",
                f"{statistics.median(r.cpu_after_signal_s for r in runs):.2f} s",
                ", ".join(sorted({str(r.exit_code) for r in runs})),
                f"{sum(r.report_says_sigterm for r in runs)} of {len(runs)}",
                f"{max(r.peak_mb for r in runs):.0f}",
            )
    Console(width=160).print(table)
    print(f"load average at the end: {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
