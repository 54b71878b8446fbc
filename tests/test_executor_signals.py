"""A real subprocess running a mission is sent SIGINT / SIGTERM: the goal is cancelled."""

from __future__ import annotations

import json
import signal
import subprocess
from pathlib import Path

import pytest

from cli_support import NAVSEQ, write_mission
from helpers_subprocess import read_calls, start_mission, wait_for


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_cancels_the_active_goal_and_sets_the_exit_status(
    tmp_path: Path, sig: signal.Signals, status: int
) -> None:
    process, calls = start_mission(tmp_path, count=5, realtime=2.0)
    try:
        # Let the robot get going on its second goal.
        wait_for(lambda: sum(c["call"] == "send_goal" for c in read_calls(calls)) >= 2)
        process.send_signal(sig)
        stdout, stderr = process.communicate(timeout=20)
    finally:
        process.kill()
    assert process.returncode == status, stderr
    log = read_calls(calls)
    sends = [c for c in log if c["call"] == "send_goal"]
    cancels = [c for c in log if c["call"] == "cancel_goal"]
    assert cancels, "the active goal was not cancelled"
    assert cancels[0]["goal_id"] == sends[-1]["goal_id"]
    after_cancel = log[log.index(cancels[0]) :]
    assert not [c for c in after_cancel if c["call"] == "send_goal"]  # the robot stays stopped
    result = json.loads(stdout)
    assert result["reason"] == f"interrupted: {sig.name}"
    assert result["success"] is False
    assert [v["outcome"] for v in result["visits"]][:2] == ["reached", "failed"]


def test_sigint_stops_a_run_started_with_sigint_ignored(tmp_path: Path) -> None:
    """A background job of a shell script inherits SIGINT ignored; kill -INT must still work."""
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {x: 3.0, y: 0.0, yaw: 0}\n  - {x: 3.0, y: 3.0, yaw: 90}\n",
    )
    log = tmp_path / "nav.log"
    process = subprocess.Popen(
        [NAVSEQ, "run", str(mission), "--navigator", "scripted", "--out", str(tmp_path / "out"),
         "--scripted-realtime", "1", "--scripted-log", str(log)],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )  # fmt: skip
    try:
        wait_for(lambda: any(c["call"] == "send_goal" for c in read_calls(log)))
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    calls = read_calls(log)
    sends = [c for c in calls if c["call"] == "send_goal"]
    cancels = [c for c in calls if c["call"] == "cancel_goal"]
    assert cancels and cancels[0]["goal_id"] == sends[-1]["goal_id"]
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["interrupted"] == "SIGINT" and report["reason"] == "interrupted: SIGINT"
    assert report["exit_code"] == 130
