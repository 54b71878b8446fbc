"""``navseq plan --order shortest`` on a long mission: progress on a terminal, Ctrl-C ends it."""

from __future__ import annotations

import json
import os
import pty
import select
import signal
import subprocess
import time
from pathlib import Path

import numpy as np

from cli_support import NAVSEQ, TURTLEBOT3_MAP, write_mission


def arena_mission(path: Path, count: int) -> Path:
    """``count`` waypoints at roomy free spots of the TurtleBot3 arena, in a random order."""
    from navseq.commands.common import costmap_for_map

    costmap = costmap_for_map(TURTLEBOT3_MAP)
    roomy = costmap.free_mask() & (costmap.clearance >= costmap.params.circumscribed_radius + 0.2)
    cells = np.argwhere(roomy)
    chosen = cells[np.random.default_rng(3).choice(len(cells), size=count, replace=False)]
    lines = []
    for row, col in chosen:
        x, y = costmap.cell_to_world(int(row), int(col))
        lines.append(f"  - {{x: {x:.3f}, y: {y:.3f}, yaw: 0}}\n")
    return write_mission(path, "".join(lines), header=f"map: {TURTLEBOT3_MAP}\n")


def start_on_terminal(*args: object, cwd: Path) -> tuple[subprocess.Popen[bytes], int]:
    """``navseq ARGS`` with stderr on a pseudo-terminal (stdout piped); the pty's reader."""
    reader, writer = pty.openpty()
    process = subprocess.Popen(
        [NAVSEQ, *map(str, args)], cwd=cwd, stdout=subprocess.PIPE, stderr=writer
    )
    os.close(writer)
    return process, reader


def read_until(reader: int, wanted: str, timeout: float) -> str:
    """What the terminal showed until ``wanted`` (or the time ran out, or it closed)."""
    seen = b""
    deadline = time.monotonic() + timeout
    while wanted.encode() not in seen and time.monotonic() < deadline:
        ready, _, _ = select.select([reader], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(reader, 65536)
            except OSError:  # the other end closed
                break
            if not chunk:
                break
            seen += chunk
    return seen.decode(errors="replace")


def drain(reader: int) -> str:
    return read_until(reader, "\0never\0", timeout=2.0)


def test_progress_shows_on_a_terminal_and_json_stays_clean(tmp_path: Path) -> None:
    mission = arena_mission(tmp_path / "many.yaml", 60)
    process, reader = start_on_terminal(
        "plan", mission, "--order", "shortest", "--time-limit", "1", "--json", cwd=tmp_path
    )
    try:
        shown = read_until(reader, "solving", timeout=90)
        stdout, _ = process.communicate(timeout=90)
        shown += drain(reader)
    finally:
        os.close(reader)
    assert process.returncode == 0
    assert "distances" in shown and "solving" in shown
    route = json.loads(stdout)  # nothing but the JSON on stdout
    assert sorted(route["order"]) == list(range(1, 61))


def test_ctrl_c_while_solving_ends_with_130_and_writes_nothing(tmp_path: Path) -> None:
    mission = arena_mission(tmp_path / "many.yaml", 60)
    out = tmp_path / "ordered.yaml"
    process, reader = start_on_terminal(
        "plan", mission, "--order", "shortest", "--time-limit", "120", "--out", out,
        cwd=tmp_path,
    )  # fmt: skip
    try:
        shown = read_until(reader, "solving", timeout=90)
        assert "solving" in shown, shown
        process.send_signal(signal.SIGINT)
        stdout, _ = process.communicate(timeout=60)  # not the solver's 120 s
        shown += drain(reader)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        os.close(reader)
    assert process.returncode == 130, shown
    assert "interrupted" in shown and "Traceback" not in shown
    assert not out.exists() and stdout == b""
