"""``navseq run --fleet FLEET --resume RUN_DIR``: a fleet run continued where it stopped."""

from __future__ import annotations

import json
import signal
from collections import Counter
from pathlib import Path

import pytest

from cli_support import (
    TURTLEBOT3_MAP,
    assert_clean_error,
    journal_events,
    navseq,
    start_navseq,
    wait_for,
)

# Robot a has one short leg; b three long ones: a is done well before b.
MISSION = (
    "navseq: 1\nwaypoints:\n"
    "  - {name: near, x: -1.6, y: -0.5, yaw: 0}\n"
    "  - {name: east-dock, x: 1.75, y: -0.55, yaw: 90}\n"
    "  - {name: inner-east, x: 0.55, y: 0.55, yaw: 180}\n"
    "  - {name: north-dock, x: 0.0, y: 1.75, yaw: 180}\n"
)
FLEET = (
    f"navseq_fleet: 1\nmission: mission.yaml\nmap: {TURTLEBOT3_MAP}\nrobots:\n"
    "  - {name: a, start: {x: -2.0, y: -0.5, yaw: 0}}\n"
    "  - {name: b, start: {x: 2.0, y: 0.5, yaw: 180}}\n"
    "waypoints:\n  near: {robots: [a]}\n  east-dock: {robots: [b]}\n"
    "  inner-east: {robots: [b]}\n  north-dock: {robots: [b]}\n"
)


def fleet_files(folder: Path) -> Path:
    (folder / "mission.yaml").write_text(MISSION)
    fleet = folder / "fleet.yaml"
    fleet.write_text(FLEET)
    return fleet


def fleet_report(folder: Path) -> dict:
    return json.loads((folder / "fleet-report.json").read_text())


def reached_indices(journal: Path) -> Counter[int]:
    """How often each waypoint of a robot's share was reached, over every run segment."""
    return Counter(
        event["index"]
        for event in journal_events(journal, "WaypointFinished")
        if event["outcome"] == "reached"
    )


def test_an_interrupted_fleet_run_resumes_and_reaches_every_waypoint_once(
    tmp_path: Path,
) -> None:
    fleet = fleet_files(tmp_path)
    run = tmp_path / "run"
    process = start_navseq("run", "--fleet", fleet, "--out", run, "--realtime", "2", cwd=tmp_path)
    try:
        # a is done and b has reached its first waypoint (of three): stop the fleet.
        wait_for(
            lambda: (
                journal_events(run / "a" / "journal.jsonl", "MissionFinished")
                and reached_indices(run / "b" / "journal.jsonl")
            ),
            60,
            "robot a done and robot b's first arrival",
        )
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 130, stderr
    first = fleet_report(run)
    assert first["interrupted"] == "SIGINT" and first["reached"] < 4
    done_journal = (run / "a" / "journal.jsonl").read_bytes()

    resumed = navseq("run", "--fleet", fleet, "--resume", run, cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    report = fleet_report(run)
    assert (report["reached"], report["skipped"], report["failed"]) == (4, 0, 0)
    assert report["interrupted"] is None and report["robot_overlaps"] == 0
    rows = {row["name"]: row for row in report["robots"]}
    assert rows["a"]["reached"] == rows["a"]["waypoints"] == 1
    assert rows["b"]["reached"] == rows["b"]["waypoints"] == 3
    # The robot that was done stays done: its journal is not touched, nor is it driven.
    assert (run / "a" / "journal.jsonl").read_bytes() == done_journal
    # b went on from its journal: each of its waypoints reached exactly once in all.
    assert reached_indices(run / "b" / "journal.jsonl") == Counter({0: 1, 1: 1, 2: 1})
    # Its newest report (beside the first, as a one-robot resume's) covers both parts.
    assert rows["b"]["report"] == str(run / "b" / "report-2.json")
    robot_report = json.loads(Path(rows["b"]["report"]).read_text())
    assert robot_report["totals"]["reached"] == 3
    assert "fleet: 4 reached, 0 skipped, 0 failed" in resumed.stdout


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A complete fleet run (as fast as the CPU allows); tests copy it before harming it."""
    folder = tmp_path_factory.mktemp("fleet")
    fleet = fleet_files(folder)
    done = navseq("run", "--fleet", fleet, "--out", folder / "run", cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder


def copy_of(finished_run: Path, tmp_path: Path) -> tuple[Path, Path]:
    import shutil

    shutil.copytree(finished_run, tmp_path / "copy")
    return tmp_path / "copy" / "fleet.yaml", tmp_path / "copy" / "run"


def test_resuming_a_complete_fleet_run_moves_nothing_and_says_all_reached(
    finished_run: Path, tmp_path: Path
) -> None:
    fleet, run = copy_of(finished_run, tmp_path)
    journals = {name: (run / name / "journal.jsonl").read_bytes() for name in ("a", "b")}
    done = navseq("run", "--fleet", fleet, "--resume", run, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert fleet_report(run)["reached"] == 4
    for name, text in journals.items():
        assert (run / name / "journal.jsonl").read_bytes() == text


def _break_journal(run: Path) -> None:
    journal = run / "b" / "journal.jsonl"
    lines = journal.read_text().splitlines(keepends=True)
    lines[3] = lines[3].replace('"t": ', '"t": 1')  # an edited line: the chain breaks
    journal.write_text("".join(lines))


def _drop_robot(run: Path) -> None:
    (run / "b" / "journal.jsonl").unlink()


@pytest.mark.parametrize(
    ("harm", "said"),
    [
        (lambda fleet, run: fleet.write_text(FLEET + "# edited\n"), "is not the fleet file"),
        (lambda fleet, run: _drop_robot(run), "robot 'b'"),
        (lambda fleet, run: _break_journal(run), "journal.jsonl:4"),
        (lambda fleet, run: (run / "fleet-run.json").unlink(), "is not a fleet run folder"),
    ],
    ids=["another-fleet-file", "robot-missing", "journal-torn", "not-a-fleet-run"],
)
def test_a_resume_that_cannot_continue_the_run_is_refused_and_changes_nothing(
    finished_run: Path, tmp_path: Path, harm, said: str
) -> None:
    fleet, run = copy_of(finished_run, tmp_path)
    harm(fleet, run)
    report = (run / "fleet-report.json").read_bytes()
    done = navseq("run", "--fleet", fleet, "--resume", run, cwd=tmp_path)
    assert_clean_error(done)
    assert said in done.stderr
    assert (run / "fleet-report.json").read_bytes() == report


def test_a_second_resume_of_a_fleet_run_in_use_is_refused(
    finished_run: Path, tmp_path: Path
) -> None:
    from navseq.run.runlock import RunLock

    fleet, run = copy_of(finished_run, tmp_path)
    lock = RunLock(run).acquire()  # as a resume running now holds it
    try:
        done = navseq("run", "--fleet", fleet, "--resume", run, cwd=tmp_path)
    finally:
        lock.release()
    assert_clean_error(done)
    assert "another navseq run" in done.stderr
