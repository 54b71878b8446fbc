"""Helpers for tests that run the ``navseq`` command as a subprocess, as a user runs it.

Shared by the CLI test modules so that none imports another test module.
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
NAVSEQ = str(Path(sys.executable).with_name("navseq"))
EXAMPLES = REPO / "examples"
TURTLEBOT3_MAP = REPO / "maps" / "turtlebot3_world.yaml"


def navseq(*args: Any, cwd: Path, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
    """Run ``navseq ARGS``; output is captured, so stdout is not a terminal."""
    return subprocess.run(
        [NAVSEQ, *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=timeout
    )


def start_navseq(*args: Any, cwd: Path) -> subprocess.Popen[str]:
    """Start ``navseq ARGS`` in the background, stdout and stderr piped."""
    return subprocess.Popen(
        [NAVSEQ, *map(str, args)],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for(predicate: Callable[[], Any], timeout: float, what: str) -> None:
    """Poll ``predicate`` until it is truthy; fail naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


def journal_records(path: Path) -> list[dict[str, Any]]:
    """The records of a run's ``journal.jsonl`` so far (none before it exists)."""
    records = []
    for line in path.read_text().splitlines() if path.exists() else []:
        with contextlib.suppress(json.JSONDecodeError):  # a last line cut short by kill -9
            records.append(json.loads(line))
    return records


def journal_events(path: Path, kind: str) -> list[dict[str, Any]]:
    """The journal records of one event type (``MissionFinished`` ...)."""
    return [r for r in journal_records(path) if r.get("type") == kind]


def printed_events(text: str, kind: str) -> list[dict[str, Any]]:
    """The ``navseq run --json`` records of one event type in ``text`` (its stdout so far).

    Wait on these, not on the journal, for "the robot is driving": ``--json`` prints
    every progress event, the journal only the corners of the driven path (a straight
    leg shows there when it ends).
    """
    records = []
    for line in text.splitlines():
        with contextlib.suppress(json.JSONDecodeError):  # the line being written
            record = json.loads(line) if line.startswith("{") else None
            if isinstance(record, dict) and record.get("event") == kind:
                records.append(record)
    return records


def driven_towards(text: str, index: int, metres: float = 0.05) -> bool:
    """Whether ``--json`` output ``text`` shows the robot ``metres`` along waypoint ``index``."""
    return any(
        record["index"] == index and record["distance_m"] > metres
        for record in printed_events(text, "WaypointProgress")
    )


def assert_clean_error(result: subprocess.CompletedProcess[str]) -> None:
    """Bad input: exit 2, a message on stderr, never a traceback."""
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stdout + result.stderr
    assert result.stderr.strip()


def write_mission(path: Path, waypoints: str, header: str = "") -> Path:
    """A navseq YAML mission at ``path``: ``header`` lines, then the ``waypoints`` list."""
    path.write_text(f"navseq: 1\n{header}waypoints:\n{waypoints}")
    return path


def start_scripted_run(
    mission: Path, out: Path, *extra: Any, realtime: float, cwd: Path
) -> subprocess.Popen[str]:
    """``navseq run MISSION --navigator scripted`` in the background, paced at ``realtime``."""
    return start_navseq(
        "run", mission, "--navigator", "scripted", "--out", out,
        "--scripted-realtime", realtime, *extra, cwd=cwd,
    )  # fmt: skip


def kill_9_when(
    process: subprocess.Popen[str], predicate: Callable[[], Any], timeout: float, what: str
) -> None:
    """``kill -9`` the run once ``predicate`` holds (no chance to clean up); reap it."""
    try:
        wait_for(predicate, timeout, what)
    finally:
        process.kill()
        process.communicate(timeout=30)
