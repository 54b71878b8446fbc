"""A real subprocess running a mission is sent SIGINT / SIGTERM: the goal is cancelled."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest

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
