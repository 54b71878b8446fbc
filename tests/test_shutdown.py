"""However a run is ended, its report exists, parses and agrees with the exit status."""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

from cli_support import (
    NAVSEQ,
    assert_clean_error,
    journal_events,
    journal_records,
    kill_9_when,
    navseq,
    start_scripted_run,
    wait_for,
    write_mission,
)

SQUARE = """\
  - {name: a, x: 1.0, y: 0.0, yaw: 90}
  - {name: b, x: 1.0, y: 1.0, yaw: 180}
  - {name: c, x: 0.0, y: 1.0, yaw: -90}
  - {name: d, x: 0.0, y: 0.0, yaw: 0}
"""
EXIT = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}


def calls(log: Path, call: str) -> list[dict[str, Any]]:
    if not log.exists():
        return []
    return [r for r in map(json.loads, log.read_text().splitlines()) if r["call"] == call]


def start_run(tmp_path: Path, *extra: Any, **popen: Any) -> tuple[subprocess.Popen[str], Path]:
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    log = tmp_path / "nav.log"
    args = [
        NAVSEQ,
        "run",
        str(mission),
        "--navigator",
        "scripted",
        "--out",
        str(tmp_path / "out"),
        "--scripted-realtime",
        "1",
        "--scripted-log",
        str(log),
        *map(str, extra),
    ]
    process = subprocess.Popen(
        args, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen
    )
    wait_for(lambda: calls(log, "send_goal"), 30, "the first goal")
    return process, log


def assert_report_agrees(out: Path, returncode: int) -> dict[str, Any]:
    report = json.loads((out / "report.json").read_text())
    assert report["exit_code"] == returncode
    if "picture" in report["files"]:
        assert Path(report["files"]["picture"]).stat().st_size > 0
    assert not [p for p in out.iterdir() if p.stat().st_size == 0]  # never an empty file
    assert not list(out.glob(".*.tmp"))
    return report


@pytest.mark.parametrize(
    ("first", "second"),
    [("SIGINT", "SIGINT"), ("SIGTERM", "SIGTERM"), ("SIGINT", "SIGTERM"), ("SIGHUP", "SIGINT")],
)
def test_two_quick_signals_still_write_a_report_that_agrees_with_the_exit(
    tmp_path: Path, first: str, second: str
) -> None:
    process, log = start_run(tmp_path)
    process.send_signal(signal.Signals[first])
    time.sleep(0.005)
    process.send_signal(signal.Signals[second])
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == EXIT[first], stderr
    assert "Traceback" not in stderr
    report = assert_report_agrees(tmp_path / "out", process.returncode)
    assert report["interrupted"] == first
    assert calls(log, "cancel_goal")  # the robot was stopped


@pytest.mark.parametrize("delay", [0.0, 0.02, 0.1, 0.3])
def test_signals_at_the_end_of_a_run_never_lose_the_report(tmp_path: Path, delay: float) -> None:
    """Signals around the moment the mission finishes (while outputs are written)."""
    out = tmp_path / "out"
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    process = start_scripted_run(mission, out, realtime=8, cwd=tmp_path)
    journal = out / "journal.jsonl"
    wait_for(lambda: journal_events(journal, "MissionFinished"), 60, "the mission to finish")
    time.sleep(delay)
    for _ in range(2):
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert "Traceback" not in stderr
    # The mission was over: the run exits with the mission's own status, which the
    # report states.
    assert process.returncode == 0, stderr
    report = assert_report_agrees(out, 0)
    assert report["success"] is True


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM", "SIGHUP"])
def test_signals_after_the_outputs_are_written_leave_the_exit_status_alone(
    tmp_path: Path, name: str
) -> None:
    """Between the report and the process's exit (Python's own shutdown takes a while),
    a signal cannot make a run whose report says exit 0 die by that signal."""
    out = tmp_path / "out"
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    process = start_scripted_run(mission, out, realtime=8, cwd=tmp_path)
    wait_for(lambda: (out / "report.json").exists(), 60, "the report")
    sent = 0
    deadline = time.monotonic() + 30
    while process.poll() is None and time.monotonic() < deadline:
        process.send_signal(signal.Signals[name])
        sent += 1
        time.sleep(0.002)
    _, stderr = process.communicate(timeout=60)
    assert "Traceback" not in stderr
    assert process.returncode == 0, (sent, stderr)
    assert assert_report_agrees(out, 0)["success"] is True


def test_sighup_cancels_the_goal_like_sigterm(tmp_path: Path) -> None:
    process, log = start_run(tmp_path)
    process.send_signal(signal.SIGHUP)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 129, stderr
    assert calls(log, "cancel_goal")
    report = assert_report_agrees(tmp_path / "out", 129)
    assert report["reason"] == "interrupted: SIGHUP"


def test_sigint_cancels_the_goal_even_when_started_with_sigint_ignored(tmp_path: Path) -> None:
    """A background job of a shell script inherits SIGINT as ignored."""
    process, log = start_run(
        tmp_path, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)
    )
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert calls(log, "cancel_goal")
    assert_report_agrees(tmp_path / "out", 130)


def test_kill_9_after_the_last_journal_line_then_report_rebuilds_it(tmp_path: Path) -> None:
    out = tmp_path / "out"
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    first = navseq("run", mission, "--navigator", "scripted", "--out", out, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    original = json.loads((out / "report.json").read_text())
    # What a kill -9 between MissionFinished and the report leaves: no report, no picture.
    (out / "report.json").unlink()
    (out / "mission.png").write_bytes(b"")
    rebuilt = navseq("report", out, cwd=tmp_path)
    assert rebuilt.returncode == 0, rebuilt.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["rebuilt_from_journal"] is True
    assert report["exit_code"] == 0 and report["success"] is True
    assert [v["outcome"] for v in report["visits"]] == [v["outcome"] for v in original["visits"]]
    assert (out / "mission.png").read_bytes().startswith(b"\x89PNG")
    again = navseq("report", out, cwd=tmp_path)
    assert again.returncode == 0 and "complete" in again.stdout


def test_resume_of_a_finished_journal_rebuilds_a_missing_report(tmp_path: Path) -> None:
    out = tmp_path / "out"
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    assert (
        navseq("run", mission, "--navigator", "scripted", "--out", out, cwd=tmp_path).returncode
        == 0
    )
    (out / "report.json").unlink()
    result = navseq("run", "--resume", out / "journal.jsonl", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "rebuilt the report" in result.stderr
    assert json.loads((out / "report.json").read_text())["success"] is True
    # With the report complete, a resume of a finished run is refused as before.
    refused = navseq("run", "--resume", out / "journal.jsonl", cwd=tmp_path)
    assert_clean_error(refused)
    assert "nothing to resume" in refused.stderr


@pytest.mark.parametrize("cut", [3, 5, 8])
def test_kill_9_at_any_journal_line_then_resume_finishes_with_a_true_report(
    tmp_path: Path, cut: int
) -> None:
    out = tmp_path / "out"
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    process = start_scripted_run(mission, out, realtime=4, cwd=tmp_path)
    journal = out / "journal.jsonl"
    kill_9_when(
        process,
        lambda: len(journal_records(journal)) >= cut or process.poll() is not None,
        120,
        f"{cut} journal lines",
    )
    assert process.returncode == -signal.SIGKILL  # killed mid-run, not finished
    resumed = navseq("run", "--resume", journal, cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    report = assert_report_agrees(out, 0)
    assert report["totals"]["reached"] == 4


def test_a_full_disk_under_the_journal_stops_the_robot_and_exits_2(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import errno
    import os

    from navseq import cli
    from navseq.journal import writer as journal_module

    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    log = tmp_path / "nav.log"
    real_write = os.write
    writes = {"count": 0}

    def write_until_full(fd: int, data: Any) -> int:
        writes["count"] += 1
        if writes["count"] > 8:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(fd, data)

    monkeypatch.setattr(journal_module.os, "write", write_until_full)
    out = tmp_path / "out"
    code = cli.main(
        [
            "run",
            str(mission),
            "--navigator",
            "scripted",
            "--out",
            str(out),
            "--scripted-log",
            str(log),
        ]
    )
    stderr = capsys.readouterr().err
    assert code == 2
    assert f"{out / 'journal.jsonl'}: cannot write the journal: the disk is full" in stderr
    assert "Traceback" not in stderr
    assert calls(log, "cancel_goal")  # the robot was stopped first
    report = json.loads((out / "report.json").read_text())  # what could be written, was
    assert report["exit_code"] == 2 and report["reason"].startswith("stopped:")


def test_a_picture_that_cannot_be_written_exits_2_and_the_report_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import errno

    from navseq import cli, files

    real = files.write_atomically

    def no_room_for_pictures(path: Path, data: Any, **kwargs: Any) -> None:
        if path.suffix == ".png":
            raise OSError(errno.ENOSPC, "No space left on device")
        real(path, data, **kwargs)

    monkeypatch.setattr(files, "write_atomically", no_room_for_pictures)
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    code = cli.main(["run", str(mission), "--navigator", "scripted", "--out", str(out)])
    stderr = capsys.readouterr().err
    assert code == 2
    assert f"{out / 'mission.png'}: cannot write it: the disk is full" in stderr
    report = json.loads((out / "report.json").read_text())
    assert report["exit_code"] == 2 and report["success"] is True
    assert "picture" in report["files_not_written"]
    assert "picture" not in report["files"]  # it names no file that is not there
    assert not (out / "mission.png").exists()


def test_a_disk_that_fills_after_the_report_says_exactly_what_is_on_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The report is written, then the disk is full: no picture, and the report cannot
    be updated to say so. The run used to claim the report "could not be written"."""
    import errno

    from navseq import cli, files

    real = files.write_atomically
    room = {"files": 1}  # the first report fits, nothing after it

    def filling_up(path: Path, data: Any, **kwargs: Any) -> None:
        if room["files"] == 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        room["files"] -= 1
        real(path, data, **kwargs)

    monkeypatch.setattr(files, "write_atomically", filling_up)
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    code = cli.main(["run", str(mission), "--navigator", "scripted", "--out", str(out)])
    stderr = capsys.readouterr().err
    assert code == 2
    report_path = out / "report.json"
    report = json.loads(report_path.read_text())  # complete and valid, as said
    assert report["exit_code"] == 0 and report["files"]["picture"] == str(out / "mission.png")
    assert not (out / "mission.png").exists()
    assert "the report could not be written" not in stderr
    assert (
        f"the picture could not be written ({out / 'mission.png'}: cannot write it: the disk "
        f"is full); the report {report_path} is complete, but could not be updated after the "
        "picture failed (the disk is full): it still names the picture mission.png, which was "
        "not written, and states exit status 0, not 2" in stderr
    )
    assert f"`navseq report {out}` draws the picture" in stderr
    assert stderr.count("the disk is full") == 2  # one message: picture and report, once
    assert not list(out.glob(".*.tmp"))
    monkeypatch.undo()
    assert cli.main(["report", str(out)]) == 0  # once there is room: the picture only
    assert (out / "mission.png").exists() and json.loads(report_path.read_text()) == report


def test_a_report_that_cannot_be_written_at_all_says_so_and_how_to_rebuild_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import errno

    from navseq import cli, files

    def full(path: Path, data: Any, **kwargs: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files, "write_atomically", full)
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    code = cli.main(["run", str(mission), "--navigator", "scripted", "--out", str(out)])
    stderr = capsys.readouterr().err
    assert code == 2
    assert f"the report could not be written ({out / 'report.json'}: cannot write it" in stderr
    assert f", nor the picture ({out / 'mission.png'}: cannot write it" in stderr
    assert f"`navseq report {out}` rebuilds what is missing" in stderr
    assert stderr.count("the disk is full") == 2  # one message: report and picture, once
    assert sorted(p.name for p in out.iterdir()) == ["journal.jsonl"]


# A run killed with -9 in the middle of writing its report: the temporary stays behind.
KILLED_WHILE_WRITING = """
import os, signal, sys
from navseq import cli, files
def killed(temporary, target):
    os.kill(os.getpid(), signal.SIGKILL)
files._publish_without_replacing = killed
sys.exit(cli.main(sys.argv[1:]))
"""


def killed_while_writing_the_report(tmp_path: Path) -> Path:
    import sys

    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    args = ["run", str(mission), "--navigator", "scripted", "--out", str(out)]
    killed = subprocess.run(
        [sys.executable, "-c", KILLED_WHILE_WRITING, *args], cwd=tmp_path, capture_output=True
    )
    assert killed.returncode == -signal.SIGKILL
    assert [p.name.startswith(".report.json.") for p in out.glob(".*.tmp")] == [True]
    assert not (out / "report.json").exists()
    return out


@pytest.mark.parametrize("command", ["resume", "report", "new run"])
def test_a_temporary_a_killed_run_left_is_removed_by_the_next_command_in_its_folder(
    tmp_path: Path, command: str
) -> None:
    out = killed_while_writing_the_report(tmp_path)
    args = {
        "resume": ("run", "--resume", out / "journal.jsonl"),
        "report": ("report", out),
        "new run": ("run", tmp_path / "square.yaml", "--navigator", "scripted", "--out", out),
    }[command]
    result = navseq(*args, cwd=tmp_path)
    assert result.returncode in (0, 1), result.stderr
    assert not list(out.glob(".*.tmp"))
    assert json.loads((out / "report.json").read_text())["visits"]


def test_only_stale_temporaries_of_our_own_outputs_are_removed(tmp_path: Path) -> None:
    import fcntl
    import os

    from navseq.run.files import remove_stale_temporaries

    stale = [
        ".report.json.0123abcd.tmp",
        ".mission-2.png.deadbeef.tmp",
        ".report-3.json.00ff00ff.tmp",
    ]
    others = [
        ".notes.txt.deadbeef.tmp",  # our pattern, not our output
        ".report.json.tmp",
        "report.json.deadbeef.tmp",
        ".report.json.DEADBEEF.tmp",
        ".report.json.deadbeef.tmp.bak",
        "mission.png",
    ]
    for name in stale + others:
        (tmp_path / name).write_text("x")
    live = tmp_path / ".report.json.1111aaaa.tmp"  # another process is writing it
    live.write_text("being written")
    user_file = tmp_path / "mine.png"
    user_file.write_text("the user's")
    (tmp_path / ".mission.png.2222bbbb.tmp").symlink_to(user_file)
    (tmp_path / ".mission.png.3333cccc.tmp").mkdir()
    with open(live, "rb") as holder:
        fcntl.flock(holder.fileno(), fcntl.LOCK_EX)
        removed = remove_stale_temporaries(tmp_path)
    assert sorted(p.name for p in removed) == sorted(stale)
    left = set(os.listdir(tmp_path))
    assert left >= {*others, live.name, user_file.name, ".mission.png.2222bbbb.tmp"}
    assert user_file.read_text() == "the user's"


def test_a_temporary_being_written_is_locked_until_it_is_gone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import fcntl

    from navseq import files

    seen = []
    real_publish = files._publish_without_replacing

    def publish(temporary: Path, target: Path) -> None:
        with open(temporary, "rb") as other:  # what a cleaner in another process sees
            try:
                fcntl.flock(other.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
                seen.append("unlocked")
            except OSError:
                seen.append("locked")
        real_publish(temporary, target)

    monkeypatch.setattr(files, "_publish_without_replacing", publish)
    files.write_atomically(tmp_path / "report.json", "{}", replace=False)
    assert seen == ["locked"]
    assert (tmp_path / "report.json").read_text() == "{}"
    assert not list(tmp_path.glob(".*.tmp"))
