"""The goal-turnaround benchmarks run end to end, small: over real actionlib (ROS 1) and
real rclpy actions (ROS 2), navseq and the plain client loop both complete every goal.

They are scripts nothing else imports: without this, a renamed API breaks them silently
until someone reruns the figures of docs/performance.md.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


def run_bench(name: str) -> list[str]:
    """The table rows (one per client) that ``benchmarks/NAME --goals 5`` printed."""
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / name), "--goals", "5", "--skip-mission"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "COLUMNS": "250"},  # one line per row: rich wraps to the width
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return [line for line in done.stdout.splitlines() if line.startswith("│")]


def cells(row: str) -> list[str]:
    return [cell.strip() for cell in row.strip("│").split("│")]


@pytest.mark.ros
def test_ros1_turnaround_benchmark_completes_every_goal_with_each_client() -> None:
    rows = [cells(row) for row in run_bench("bench_ros1.py")]
    clients = {row[1] for row in rows}
    assert "SimpleActionClient loop" in clients and any(c.startswith("navseq") for c in clients)
    assert all(row[2] == "5" and row[3] == "yes" for row in rows), rows


@pytest.mark.ros2
def test_nav2_turnaround_benchmark_completes_every_goal_with_each_client() -> None:
    rows = [cells(row) for row in run_bench("bench_nav2.py")]
    clients = {row[0] for row in rows}
    assert "ActionClient loop" in clients and any(c.startswith("navseq") for c in clients)
    assert all(row[1] == "5" and row[2] == "yes" for row in rows), rows
