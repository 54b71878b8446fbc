"""kill -9 a mission subprocess mid-mission, then resume it from its journal."""

from __future__ import annotations

import json
import signal
from pathlib import Path

from helpers_subprocess import journal_records, read_calls, start_mission, wait_for


def reached(path: Path) -> list[int]:
    return [
        r["index"]
        for r in journal_records(path)
        if r.get("type") == "WaypointFinished" and r["outcome"] == "reached"
    ]


def test_resume_after_kill_9_skips_reached_waypoints_and_reruns_the_active_one(
    tmp_path: Path,
) -> None:
    journal = tmp_path / "run.journal"
    first, first_calls = start_mission(tmp_path, 6, 4.0, "--journal", str(journal))
    try:
        wait_for(lambda: len(reached(journal)) >= 2)
        first.send_signal(signal.SIGKILL)
        first.wait(timeout=20)
    finally:
        first.kill()
    assert first.returncode == -signal.SIGKILL
    done_before = reached(journal)
    started = [r for r in journal_records(journal) if r.get("type") == "WaypointStarted"]
    active = started[-1]["index"]
    assert active not in done_before and done_before == list(range(active))
    assert not [c for c in read_calls(first_calls) if c["call"] == "cancel_goal"]

    first_calls.rename(tmp_path / "first_calls.jsonl")
    second, calls = start_mission(tmp_path, 6, None, "--journal", str(journal), "--resume")
    stdout, stderr = second.communicate(timeout=30)
    assert second.returncode == 0, stderr
    sent = [c["x"] for c in read_calls(calls) if c["call"] == "send_goal"]
    assert sent == [float(i + 1) for i in range(active, 6)]  # the active one first, again
    result = json.loads(stdout)
    assert result["success"] and [v["outcome"] for v in result["visits"]] == ["reached"] * 6
    assert [v["attempts"] for v in result["visits"]] == [1] * 6
    kinds = [r["kind"] for r in journal_records(journal)]
    assert kinds.count("header") == 1 and kinds.count("resumed") == 1


def test_resume_with_a_changed_mission_file_exits_2(tmp_path: Path) -> None:
    journal = tmp_path / "run.journal"
    first, first_calls = start_mission(tmp_path, 4, 4.0, "--journal", str(journal))
    try:
        wait_for(lambda: len(reached(journal)) >= 1)
        first.send_signal(signal.SIGKILL)
        first.wait(timeout=20)
    finally:
        first.kill()
    before = journal.read_bytes()
    first_calls.rename(tmp_path / "first_calls.jsonl")
    (tmp_path / "mission.json").write_text(json.dumps({"count": 5, "speed": 1.0}))
    second, calls = start_mission(tmp_path, 5, None, "--journal", str(journal), "--resume")
    _, stderr = second.communicate(timeout=30)
    assert second.returncode == 2
    assert "mission file changed" in stderr and "Traceback" not in stderr
    assert journal.read_bytes() == before
    assert read_calls(calls) == []  # the robot was not sent anywhere
