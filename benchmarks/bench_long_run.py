"""A patrol that runs for days: memory, journal size, and resuming a long journal.

1. Runs ``examples/patrol.yaml`` (loops forever) in process on the embedded simulator
   for ``--seconds`` of simulated time, with the recorder and two journals listening
   to the same events side by side: navseq's journal now, and the journal as it was
   written before (:class:`OneHertzJournal`: progress once a second of mission time,
   every plan, full float precision). Prints at every tenth of the run the process's
   resident memory, both journals' sizes and what the recorder and the simulated
   trajectory hold; then each journal's growth per 1000 simulated seconds, by record
   type. At the end it draws the picture and says how long that took.

2. With ``--resume-seconds`` (default 10⁶), builds a journal of a patrol that long from
   each writer's lines: the lines of the run's last whole loops are repeated with their
   times, loops and goal ids moved on and the chain digests recomputed (a synthetic
   journal: simulating 10⁶ s takes half an hour; the lines are the writers' own). Then
   measures, each in a fresh process: ``navseq report`` rebuilding the report and
   picture, and ``navseq run --resume`` up to its first goal, then SIGTERM to exit
   (report and picture written): wall and CPU times, peak resident memory. With
   ``--before-src DIR`` (the ``src`` folder of an earlier navseq, e.g. from ``git
   archive``) the same commands run with that navseq too, side by side.

    .venv/bin/python benchmarks/bench_long_run.py --seconds 20000
    .venv/bin/python benchmarks/bench_long_run.py --seconds 1000000 --resume-seconds 0
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from navseq.executor import events as ev
from navseq.executor.runner import MissionInterrupted, run_mission
from navseq.journal.format import json_default, sealed
from navseq.journal.writer import JournalWriter, mission_digest
from navseq.mission import load_mission
from navseq.navigators.sim import SimNavigator
from navseq.sinks.picture.draw import mission_picture_png
from navseq.sinks.recorder import RunRecorder

ROOT = Path(__file__).resolve().parents[1]
PATROL = ROOT / "examples" / "patrol.yaml"


class OneHertzJournal(JournalWriter):
    """The journal as navseq wrote it before (for comparison): every event in full
    precision, every plan, and progress thinned only to one per second of mission time."""

    _last_progress_t: float | None = None

    def __call__(self, event: ev.MissionEvent) -> None:
        if isinstance(event, ev.WaypointProgress):
            last = self._last_progress_t
            if last is not None and 0.0 <= event.t - last < 1.0:
                return
            self._last_progress_t = event.t
        self._write({"kind": "event", "type": type(event).__name__, **dataclasses.asdict(event)})


def resident_mb() -> float:
    return _status_mb("VmRSS:")


def peak_mb() -> float:
    return _status_mb("VmHWM:")


def _status_mb(key: str) -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def by_type(path: Path) -> Counter[str]:
    """Bytes of the journal per record type."""
    sizes: Counter[str] = Counter()
    with path.open("rb") as lines:
        for line in lines:
            sizes[str(json.loads(line).get("type", "header/resumed"))] += len(line)
    return sizes


def live_run(seconds: float, folder: Path, console: Console) -> tuple[Path, Path, float]:
    """Part 1; returns the two journals and the simulated time they cover."""
    mission = dataclasses.replace(load_mission(PATROL), loops=None)
    assert mission.map is not None and mission.start is not None
    navigator = SimNavigator.from_map(mission.map, mission.start)
    recorder = RunRecorder()
    rows: list[tuple[str, ...]] = []
    checkpoints = [seconds * k / 10 for k in range(1, 11)]
    wall_start = time.perf_counter()
    digest = mission_digest(PATROL)
    now_path, before_path = folder / "now.jsonl", folder / "before.jsonl"
    now = JournalWriter(now_path, str(PATROL), digest)
    before = OneHertzJournal(before_path, str(PATROL), digest)
    last_t = 0.0

    def watch(event: ev.MissionEvent) -> None:
        nonlocal last_t
        last_t = event.t
        if checkpoints and event.t >= checkpoints[0]:
            checkpoints.pop(0)
            rows.append(
                (
                    f"{event.t:,.0f}",
                    f"{resident_mb():.0f}",
                    f"{before_path.stat().st_size / 1e6:.2f}",
                    f"{now_path.stat().st_size / 1e6:.2f}",
                    f"{len(recorder.track):,}",
                    f"{len(navigator.trajectory):,}",
                    f"{time.perf_counter() - wall_start:.0f}",
                )
            )
            if not checkpoints:
                raise KeyboardInterrupt  # as Ctrl-C would end a patrol

    try:
        with now, before:
            run_mission(mission, navigator, [now, before, recorder, watch])
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

    table = Table(title=f"patrol.yaml for {seconds:,.0f} simulated seconds")
    for header in (
        "simulated s",
        "resident MB",
        "journal MB before",
        "journal MB now",
        "recorder points",
        "trajectory points",
        "wall s",
    ):
        table.add_column(header, justify="right")
    for row in rows:
        table.add_row(*row)
    console.print(table)
    console.print(
        f"visits: {result.total_visits:,} ({len(result.visits):,} listed in full); "
        f"picture: {len(png) / 1e3:.0f} kB drawn in {drawn:.1f} s; "
        f"peak resident {peak_mb():.0f} MB"
    )
    shares = Table(title="journal growth per 1000 simulated seconds, by record type")
    for header in ("type", "before kB", "share", "now kB", "share", "now / before"):
        shares.add_column(header, justify="right")
    sizes = {"before": by_type(before_path), "now": by_type(now_path)}
    totals = {name: sum(counts.values()) for name, counts in sizes.items()}
    per_1000 = 1000.0 / last_t / 1e3
    for kind, size in sizes["before"].most_common():
        mine = sizes["now"].get(kind, 0)
        shares.add_row(
            kind,
            f"{size * per_1000:.1f}",
            f"{100 * size / totals['before']:.0f} %",
            f"{mine * per_1000:.1f}",
            f"{100 * mine / totals['now']:.0f} %",
            f"{mine / size:.2f}" if size else "",
        )
    shares.add_row(
        "all",
        f"{totals['before'] * per_1000:.1f}",
        "",
        f"{totals['now'] * per_1000:.1f}",
        "",
        f"{totals['now'] / totals['before']:.3f}",
    )
    console.print(shares)
    return now_path, before_path, last_t


def synthetic_journal(source: Path, target: Path, seconds: float) -> tuple[float, int]:
    """A journal of a patrol ``seconds`` long from ``source``'s lines (see module doc).

    The lines up to the second-to-last LoopStarted are kept as they are; the whole
    loops between the first LoopStarted after a tenth of the run and that one are
    repeated. Returns the simulated time covered and the number of lines.
    """
    lines = source.read_bytes().splitlines()
    records = [json.loads(line) for line in lines]
    for record in records:
        record.pop("chain", None)
    loop_starts = [i for i, r in enumerate(records) if r.get("type") == "LoopStarted"]
    last_t = max(float(r.get("t", 0.0)) for r in records)
    first = next(i for i in loop_starts if records[i]["t"] >= last_t / 10)
    end = loop_starts[-1]
    cycle = records[first:end]
    shift_t = records[end]["t"] - records[first]["t"]
    shift_loop = records[end]["loop"] - records[first]["loop"]
    goal_ids = [r["goal_id"] for r in cycle if "goal_id" in r]
    shift_goal = max(goal_ids) - min(goal_ids) + 1
    chain = ""
    count = 0
    covered = 0.0
    with target.open("wb") as out:

        def put(record: dict[str, Any]) -> None:
            nonlocal chain, count
            line = sealed(json.dumps(record, default=json_default).encode(), chain)
            chain = line[-19:-3].decode()
            out.write(line)
            count += 1

        for record in records[:end]:
            put(record)
        repeat = 1
        while True:
            for record in cycle:
                moved = dict(record)
                if "t" in moved:
                    moved["t"] = round(moved["t"] + repeat * shift_t, 6)
                    covered = moved["t"]
                if "loop" in moved and moved.get("kind") == "event":
                    moved["loop"] += repeat * shift_loop
                if "goal_id" in moved:
                    moved["goal_id"] += repeat * shift_goal
                put(moved)
            if covered >= seconds:
                break
            repeat += 1
    return covered, count


@dataclasses.dataclass
class Measured:
    wall_s: float
    cpu_s: float  # user + system, of the whole process
    peak_mb: float
    exit_code: int
    first_goal_s: float | None = None  # --resume: from start to its first goal
    exit_after_signal_s: float | None = None  # --resume: from SIGTERM to exit


def navseq_command(src: Path | None, journal: Path) -> tuple[list[str], dict[str, str]]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = str(src)
        # An earlier navseq refused journals over 64 MiB unless told (and reads that
        # many bytes at once: the limit must not be far above the journal's size).
        env["NAVSEQ_MAX_JOURNAL_BYTES"] = str(journal.stat().st_size + (1 << 20))
    return [sys.executable, "-m", "navseq"], env


def wait_measured(process: subprocess.Popen[Any]) -> tuple[int, float, float]:
    """Wait for a child; its exit status, CPU seconds and peak resident memory (MB)."""
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    return process.returncode, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def measure_report(journal: Path, src: Path | None) -> Measured:
    command, env = navseq_command(src, journal)
    for name in ("report.json", "mission.png"):
        (journal.parent / name).unlink(missing_ok=True)
    start = time.perf_counter()
    process = subprocess.Popen(
        [*command, "report", str(journal.parent)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    code, cpu, peak = wait_measured(process)
    wall = time.perf_counter() - start
    if code != 0:
        print(process.stderr.read().decode() if process.stderr else "", file=sys.stderr)
    return Measured(wall, cpu, peak, code)


def measure_resume(journal: Path, src: Path | None) -> Measured:
    """``navseq run --resume`` to its first goal, then SIGTERM; on a copy of the journal."""
    command, env = navseq_command(src, journal)
    start = time.perf_counter()
    process = subprocess.Popen(
        [*command, "run", "--resume", str(journal), "--json"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None
    first_goal = None
    for line in process.stdout:
        if '"WaypointStarted"' in line:
            first_goal = time.perf_counter() - start
            break
    signalled = time.perf_counter()
    process.send_signal(signal.SIGTERM)
    process.stdout.read()
    code, cpu, peak = wait_measured(process)
    ended = time.perf_counter()
    if code != 143:
        print(process.stderr.read() if process.stderr else "", file=sys.stderr)
    return Measured(ended - start, cpu, peak, code, first_goal, ended - signalled)


def resume_table(
    journals: dict[str, Path], seconds: float, before_src: Path | None, folder: Path
) -> Table:
    table = Table(title=f"a {seconds:,.0f} s patrol journal: rebuild and resume, fresh processes")
    for header in (
        "journal written by",
        "journal MB",
        "navseq",
        "command",
        "wall s",
        "CPU s",
        "peak MB",
        "exit",
        "first goal after s",
        "SIGTERM to exit s",
    ):
        table.add_column(header, justify="right")
    codes = {"now": None, "before": before_src}
    for writer, journal in journals.items():
        size = f"{journal.stat().st_size / 1e6:.0f}"
        for code_name, src in codes.items():
            if code_name == "before" and src is None:
                continue
            for command in ("report", "run --resume"):
                copy = folder / f"{writer}-{code_name}-{command.split()[0]}" / "journal.jsonl"
                copy.parent.mkdir()
                shutil.copyfile(journal, copy)
                if command == "report":
                    measured = measure_report(copy, src)
                else:
                    measured = measure_resume(copy, src)
                table.add_row(
                    writer,
                    size,
                    code_name,
                    f"navseq {command}",
                    f"{measured.wall_s:.1f}",
                    f"{measured.cpu_s:.1f}",
                    f"{measured.peak_mb:.0f}",
                    str(measured.exit_code),
                    "" if measured.first_goal_s is None else f"{measured.first_goal_s:.1f}",
                    ""
                    if measured.exit_after_signal_s is None
                    else f"{measured.exit_after_signal_s:.2f}",
                )
                shutil.rmtree(copy.parent)
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20_000.0, help="simulated seconds")
    parser.add_argument(
        "--resume-seconds",
        type=float,
        default=1_000_000.0,
        help="simulated seconds of the synthetic journals to rebuild and resume (0: none)",
    )
    parser.add_argument(
        "--before-src",
        type=Path,
        help="the src folder of an earlier navseq, to run the same commands with it",
    )
    args = parser.parse_args()
    console = Console(width=160)
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        now_path, before_path, _ = live_run(args.seconds, folder, console)
        if args.resume_seconds <= 0:
            return
        journals: dict[str, Path] = {}
        for name, source in (("before", before_path), ("now", now_path)):
            target = folder / f"long-{name}.jsonl"
            started = time.perf_counter()
            covered, lines = synthetic_journal(source, target, args.resume_seconds)
            console.print(
                f"synthetic journal ({name}'s writer): {covered:,.0f} s, {lines:,} lines, "
                f"{target.stat().st_size / 1e6:.0f} MB, made in "
                f"{time.perf_counter() - started:.0f} s"
            )
            journals[name] = target
        console.print(resume_table(journals, args.resume_seconds, args.before_src, folder))


if __name__ == "__main__":
    main()
