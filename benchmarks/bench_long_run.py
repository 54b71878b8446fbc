"""A patrol that runs for days: memory and journal size against simulated time.

Runs ``examples/patrol.yaml`` (loops forever) in process on the embedded simulator with
the journal and the recorder listening, as ``navseq run`` does, for ``--seconds`` of
simulated time, and prints at every tenth of it: the process's resident memory, the
journal's size, and what the recorder and the simulated trajectory hold. At the end it
draws the picture and reports how long that took (what a signal waits for).

    .venv/bin/python benchmarks/bench_long_run.py --seconds 1000000
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import tempfile
import time
from collections import Counter
from pathlib import Path

from rich.console import Console
from rich.table import Table

from navseq.executor.events import MissionEvent
from navseq.executor.runner import MissionInterrupted, run_mission
from navseq.mission import load_mission
from navseq.navigators.sim import SimNavigator
from navseq.sinks.journal import JournalWriter, mission_digest
from navseq.sinks.picture import mission_picture_png
from navseq.sinks.recorder import RunRecorder

ROOT = Path(__file__).resolve().parents[1]
PATROL = ROOT / "examples" / "patrol.yaml"


def resident_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def peak_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=100_000.0, help="simulated seconds")
    args = parser.parse_args()

    mission = dataclasses.replace(load_mission(PATROL), loops=None)
    assert mission.map is not None and mission.start is not None
    navigator = SimNavigator.from_map(mission.map, mission.start)
    recorder = RunRecorder()
    rows: list[tuple[str, ...]] = []
    checkpoints = [args.seconds * k / 10 for k in range(1, 11)]
    wall_start = time.perf_counter()

    with tempfile.TemporaryDirectory() as folder:
        journal_path = Path(folder) / "journal.jsonl"
        journal = JournalWriter(journal_path, str(PATROL), mission_digest(PATROL))

        def watch(event: MissionEvent) -> None:
            if checkpoints and event.t >= checkpoints[0]:
                checkpoints.pop(0)
                rows.append(
                    (
                        f"{event.t:,.0f}",
                        f"{resident_mb():.0f}",
                        f"{journal_path.stat().st_size / 1e6:.1f}",
                        f"{len(recorder.track):,}",
                        f"{len(navigator.trajectory):,}",
                        f"{time.perf_counter() - wall_start:.0f}",
                    )
                )
                if not checkpoints:
                    raise KeyboardInterrupt  # as Ctrl-C would end a patrol

        try:
            with journal:
                run_mission(mission, navigator, [journal, recorder, watch])
        except MissionInterrupted as stop:
            result = stop.result
        drawing = time.perf_counter()
        png = mission_picture_png(
            mission,
            result,
            plans=recorder.leg_plans(),
            trajectory=[(recorder.mission_time(t), x, y) for t, x, y in navigator.trajectory],
        )
        drawn = time.perf_counter() - drawing
        # What the journal holds, by record type: does it grow by events or by time?
        by_type: Counter[str] = Counter()
        with journal_path.open("rb") as lines:
            for line in lines:
                by_type[str(json.loads(line).get("type", "header/resumed"))] += len(line)
        journal_total = sum(by_type.values())

    table = Table(title=f"patrol.yaml for {args.seconds:,.0f} simulated seconds")
    for header in (
        "simulated s",
        "resident MB",
        "journal MB",
        "recorder points",
        "trajectory points",
        "wall s",
    ):
        table.add_column(header, justify="right")
    for row in rows:
        table.add_row(*row)
    console = Console()
    console.print(table)
    console.print(
        f"visits: {result.total_visits:,} ({len(result.visits):,} listed in full); "
        f"picture: {len(png) / 1e3:.0f} kB drawn in {drawn:.1f} s; "
        f"peak resident {peak_mb():.0f} MB"
    )
    shares = Table(title="journal by record type")
    for header in ("type", "MB", "share"):
        shares.add_column(header, justify="right")
    for kind, size in by_type.most_common():
        shares.add_row(kind, f"{size / 1e6:.1f}", f"{100 * size / journal_total:.0f} %")
    console.print(shares)


if __name__ == "__main__":
    main()
