"""The stand-in's benchmark in a small run: two robots following one clock, three goal
round trips to each server. It shows the script still measures what it says (both
robots' clocks advance; every goal at the robot succeeds on both servers); its figures
are not checked (tests never time anything)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from bench_support import BENCHMARKS

pytestmark = pytest.mark.ros2

REPO = Path(__file__).resolve().parents[1]


def test_the_benchmark_measures_two_robots_and_both_servers() -> None:
    env = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join([str(REPO / "src"), os.environ.get("PYTHONPATH", "")]),
    )
    env["COLUMNS"] = "200"  # rich: one line per table row
    done = subprocess.run(
        [
            sys.executable,
            str(BENCHMARKS / "bench_standin.py"),
            "--robots",
            "2",
            "--speeds",
            "4",
            "--seconds",
            "2",
            "--rounds",
            "3",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=400,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    row = re.search(r"│\s+2 │\s+4x │\s+([\d.]+)x │\s+([\d.]+)x │", done.stdout)
    assert row, done.stdout
    assert float(row[1]) > 0 and float(row[2]) > 0  # the clock and both odometries ran
    assert done.stdout.count("3 SUCCEEDED") == 2, done.stdout
