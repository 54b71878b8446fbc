"""A 100 000-waypoint mission, run on the simulator and stopped by SIGTERM, ends with
the signal's exit status and a report that counts every waypoint."""

from __future__ import annotations

import json
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

WAYPOINTS = 100_000
NAVSEQ = [sys.executable, "-m", "navseq"]


def write_room_mission(folder: Path, count: int) -> Path:
    """A 4 m square room (80 x 80 cells, walled) and ``count`` waypoints inside it."""
    size = 80
    rows = [
        bytes(0 if r in (0, size - 1) or c in (0, size - 1) else 254 for c in range(size))
        for r in range(size)
    ]
    (folder / "room.pgm").write_bytes(b"P5\n%d %d\n255\n" % (size, size) + b"".join(rows))
    (folder / "room.yaml").write_text(
        "image: room.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    rng = random.Random(9)
    lines = [
        "navseq: 1",
        "map: room.yaml",
        "start: {x: 2.0, y: 2.0, yaw: 0}",
        "defaults: {on_failure: skip}",
        "waypoints:",
    ]
    lines += [
        f"  - {{name: wp{i}, x: {rng.uniform(1, 3):.2f}, y: {rng.uniform(1, 3):.2f}, "
        f"yaw: {rng.randint(-180, 180)}}}"
        for i in range(count)
    ]
    mission = folder / "big.yaml"
    mission.write_text("\n".join(lines) + "\n")
    return mission


@pytest.mark.slow
def test_a_sigtermed_100k_waypoint_run_exits_143_with_a_report(tmp_path: Path) -> None:
    mission = write_room_mission(tmp_path, WAYPOINTS)
    out = tmp_path / "out"
    process = subprocess.Popen(
        [*NAVSEQ, "run", str(mission), "--out", str(out)],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    journal = out / "journal.jsonl"
    deadline = time.monotonic() + 300  # loading and pre-flight under load, generously
    while not (journal.exists() and b'"WaypointFinished"' in journal.read_bytes()):
        assert process.poll() is None, process.communicate()[1]
        assert time.monotonic() < deadline, "no waypoint finished"
        time.sleep(0.2)
    process.send_signal(signal.SIGTERM)
    try:
        _, stderr = process.communicate(timeout=300)
    except subprocess.TimeoutExpired:
        process.kill()
        raise
    assert process.returncode == 143, stderr
    assert "Traceback" not in stderr
    report = json.loads((out / "report.json").read_text())
    assert report["exit_code"] == 143 and report["interrupted"] == "SIGTERM"
    totals = report["totals"]
    assert totals["visits"] == WAYPOINTS and totals["reached"] >= 1
    assert totals["not_run"] == WAYPOINTS - totals["reached"] - totals["failed"]
    assert len(report["waypoints"]) == WAYPOINTS
    assert report["visits_listed"]["listed"] == len(report["visits"]) <= 2000
    assert (out / "mission.png").stat().st_size > 0
