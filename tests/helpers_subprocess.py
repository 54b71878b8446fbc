"""Helpers for tests that run a mission in a real subprocess (helpers_mission_script.py)."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

SCRIPT = Path(__file__).with_name("helpers_mission_script.py")


def read_calls(path: Path) -> list[dict[str, Any]]:
    """The navigator calls the subprocess logged (complete lines only)."""
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.endswith("}")]


def wait_for(condition: Callable[[], bool], timeout: float = 20.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError("timed out waiting for the mission subprocess")
        time.sleep(0.02)


def start_mission(
    tmp_path: Path, count: int, realtime: float | None, *extra: str
) -> tuple[subprocess.Popen[str], Path]:
    """Start the mission script on ``count`` waypoints; returns it and its call log path.

    The mission file ``tmp_path/mission.json`` is written only if it does not exist yet,
    so a resumed run sees the same file (and digest) as the first one.
    """
    mission = tmp_path / "mission.json"
    if not mission.exists():
        mission.write_text(json.dumps({"count": count, "speed": 1.0}))
    calls = tmp_path / "calls.jsonl"
    command = [sys.executable, str(SCRIPT), str(mission), str(calls), *extra]
    if realtime is not None:
        command += ["--realtime", str(realtime)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return process, calls


def journal_records(path: Path) -> list[dict[str, Any]]:
    """The journal's records as raw JSON, skipping a line that a crash cut short."""
    if not path.exists():
        return []
    records = []
    for line in path.read_text().splitlines():
        try:
            records.append(json.loads(line))
        except ValueError:
            continue
    return records
