"""A resume continues the run as journaled, alone, and refuses before it writes or moves."""

from __future__ import annotations

import json
import os
import signal
import subprocess
from pathlib import Path
from typing import Any

from cli_support import (
    assert_clean_error,
    journal_events,
    journal_records,
    kill_9_when,
    navseq,
    start_navseq,
    start_scripted_run,
    wait_for,
    write_mission,
)

PATROL = """\
  - {name: a, x: 1.0, y: 0.0, yaw: 90}
  - {name: b, x: 1.0, y: 1.0, yaw: 180}
  - {name: c, x: 0.0, y: 1.0, yaw: -90}
"""


def goals_sent(log: Path) -> list[dict[str, Any]]:
    if not log.exists():
        return []
    return [r for r in map(json.loads, log.read_text().splitlines()) if r["call"] == "send_goal"]


def killed_run(tmp_path: Path, *extra: Any, visits: int = 2) -> tuple[Path, Path, int]:
    """A patrol run killed with -9 after ``visits`` finished visits: (mission, journal, pid)."""
    mission = write_mission(tmp_path / "patrol.yaml", PATROL, header="loops: forever\n")
    out = tmp_path / "out"
    process = start_scripted_run(mission, out, *extra, realtime=4, cwd=tmp_path)
    journal = out / "journal.jsonl"
    kill_9_when(
        process,
        lambda: len(journal_events(journal, "WaypointFinished")) >= visits,
        60,
        f"{visits} visits finished",
    )
    return mission, journal, process.pid


def test_resume_keeps_the_journaled_loop_count_instead_of_patrolling_forever(tmp_path):
    _, journal, _ = killed_run(tmp_path, "--loops", "2", visits=4)
    result = navseq(
        "run",
        "--resume",
        journal,
        "--scripted-log",
        tmp_path / "nav.log",
        cwd=tmp_path,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    report = json.loads((journal.parent / "report.json").read_text())
    assert report["success"] is True
    assert report["totals"]["reached"] == 6  # 2 loops of 3 waypoints, not a patrol
    assert "instead of the journal's" not in result.stderr


def test_an_option_given_again_overrides_the_journal_and_says_so(tmp_path):
    _, journal, _ = killed_run(tmp_path, "--loops", "2", visits=1)
    result = navseq(
        "run",
        "--resume",
        journal,
        "--loops",
        "1",
        "--scripted-log",
        tmp_path / "nav.log",
        cwd=tmp_path,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert "resuming with --loops 1 instead of the journal's 2" in result.stderr
    report = json.loads((journal.parent / "report.json").read_text())
    assert report["totals"]["reached"] == 3


def test_a_second_resume_of_a_live_run_is_refused_and_moves_nothing(tmp_path):
    _, journal, _ = killed_run(tmp_path, "--loops", "3")
    first = start_navseq("run", "--resume", journal, "--scripted-realtime", "0.5", cwd=tmp_path)
    try:
        wait_for(
            lambda: any(r.get("kind") == "resumed" for r in journal_records(journal)),
            30,
            "the first resume to start",
        )
        before = journal.read_bytes()
        log = tmp_path / "second.log"
        second = navseq("run", "--resume", journal, "--scripted-log", log, cwd=tmp_path)
        assert_clean_error(second)
        assert f"another navseq run (process {first.pid})" in second.stderr
        assert goals_sent(log) == []
        # The live run may append meanwhile; the refused one added no 'resumed' record.
        records = journal_records(journal)
        assert sum(r.get("kind") == "resumed" for r in records) == 1
        assert journal.read_bytes().startswith(before)
    finally:
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=30)
    assert first.returncode == 143


def test_the_lock_of_a_killed_run_is_taken_over_and_said(tmp_path):
    _, journal, pid = killed_run(tmp_path, "--loops", "1")
    result = navseq("run", "--resume", journal, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert f"took over the lock of process {pid}" in result.stderr
    assert not (journal.parent / ".navseq.lock").exists()  # a clean end removes it


def test_a_refused_resume_writes_nothing_to_the_journal(tmp_path):
    _, journal, _ = killed_run(tmp_path, "--loops", "2", visits=4)  # in the second loop
    before = journal.read_bytes()
    log = tmp_path / "nav.log"
    result = navseq("run", "--resume", journal, "--loops", "1", "--scripted-log", log, cwd=tmp_path)
    assert_clean_error(result)
    assert "loop 2" in result.stderr
    assert journal.read_bytes() == before
    assert goals_sent(log) == []


def test_a_hand_edited_journal_is_refused_with_the_line(tmp_path):
    _, journal, _ = killed_run(tmp_path, "--loops", "2", visits=3)
    lines = journal.read_bytes().splitlines(keepends=True)
    finished = [n for n, line in enumerate(lines) if b'"WaypointFinished"' in line]
    del lines[finished[0]]  # "forget" that the first waypoint was reached
    journal.write_bytes(b"".join(lines))
    log = tmp_path / "nav.log"
    result = navseq("run", "--resume", journal, "--scripted-log", log, cwd=tmp_path)
    assert_clean_error(result)
    assert f"journal.jsonl:{finished[0] + 1}: the journal was altered" in result.stderr
    assert goals_sent(log) == []


def test_a_changed_outcome_in_a_journal_line_is_refused(tmp_path):
    _, journal, _ = killed_run(tmp_path, "--loops", "2", visits=3)
    text = journal.read_text()
    journal.write_text(text.replace('"outcome": "reached"', '"outcome": "skipped"', 1))
    result = navseq("run", "--resume", journal, cwd=tmp_path)
    assert_clean_error(result)
    assert "the journal was altered" in result.stderr


def test_lock_refusal_names_the_holder(tmp_path):
    from navseq.errors import NavseqError
    from navseq.run.runlock import RunLock

    holder = subprocess.Popen(
        [
            os.sys.executable,
            "-c",
            "import sys, time; from pathlib import Path; from navseq.run.runlock import RunLock; "
            "RunLock(Path(sys.argv[1])).acquire(); print('held', flush=True); time.sleep(30)",
            str(tmp_path),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        try:
            RunLock(tmp_path).acquire()
        except NavseqError as error:
            assert f"process {holder.pid}" in str(error)
        else:
            raise AssertionError("a held lock was acquired twice")
    finally:
        holder.kill()
        holder.communicate(timeout=10)
    lock = RunLock(tmp_path).acquire()  # the kernel dropped the dead holder's lock
    assert lock.took_over == holder.pid
    lock.release()


# --- a run stopped in its first moments ------------------------------------------------


def test_the_journal_has_its_header_before_the_slow_first_steps(tmp_path, monkeypatch):
    """A kill -9 while the picture's modules load (or the navigator connects) left a 0-byte
    journal that --resume and navseq report refused; now the header is there already."""
    import shutil

    from navseq import cli
    from navseq.commands import run as run_command
    from navseq.run import products

    mission = write_mission(tmp_path / "patrol.yaml", PATROL)
    out, killed, connecting = tmp_path / "out", tmp_path / "killed", tmp_path / "connecting"
    real_prepare = run_command.prepare

    def snapshot_as_if_killed_here() -> None:
        shutil.copytree(out, killed)  # what a kill -9 at this moment would leave

    def prepare(request: Any) -> Any:
        session = real_prepare(request)
        make = session.make_navigator
        session.make_navigator = lambda: (shutil.copytree(out, connecting), make())[1]
        return session

    monkeypatch.setattr(products, "import_picture_modules", snapshot_as_if_killed_here)
    monkeypatch.setattr(run_command, "prepare", prepare)
    assert cli.main(["run", str(mission), "--navigator", "scripted", "--out", str(out)]) == 0
    monkeypatch.undo()
    for folder in (killed, connecting):
        (folder / ".navseq.lock").unlink(missing_ok=True)
        assert journal_records(folder / "journal.jsonl")[0]["kind"] == "header"
        resumed = navseq(
            "run", "--resume", folder / "journal.jsonl", "--navigator", "scripted", cwd=tmp_path
        )
        assert resumed.returncode == 0, resumed.stderr
        assert len(journal_events(folder / "journal.jsonl", "WaypointFinished")) == 3


def test_a_signal_before_the_run_began_leaves_no_journal_behind(tmp_path, monkeypatch, capsys):
    from navseq import cli
    from navseq.run import products
    from navseq.signals import Terminated

    def terminated() -> None:
        raise Terminated("SIGTERM")

    monkeypatch.setattr(products, "import_picture_modules", terminated)
    mission = write_mission(tmp_path / "patrol.yaml", PATROL)
    out = tmp_path / "out"
    assert cli.main(["run", str(mission), "--navigator", "scripted", "--out", str(out)]) == 143
    assert "terminated (SIGTERM)" in capsys.readouterr().err
    assert not out.exists()  # the folder this run created, with nothing in it, is gone


def test_an_empty_journal_is_said_to_be_a_run_that_never_began(tmp_path):
    write_mission(tmp_path / "patrol.yaml", PATROL)
    journal = tmp_path / "out" / "journal.jsonl"
    journal.parent.mkdir()
    journal.write_bytes(b"")
    for args in (("run", "--resume", journal), ("report", journal.parent)):
        result = navseq(*args, cwd=tmp_path)
        assert_clean_error(result)
        assert f"{journal}:1: the journal is empty: its run was stopped before it began" in (
            result.stderr
        )
        assert "navseq run MISSION" in result.stderr
    assert journal.read_bytes() == b""  # left as it was
