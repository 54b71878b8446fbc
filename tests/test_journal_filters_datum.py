"""The costmap filters (``--keepout`` / ``--speed-mask``) and the GPS datum a run drove
with are in its journal and report: a ``--resume`` keeps driving round the same keepout
zone, ``navseq report`` rebuilds with the zones, and a resume refuses another datum."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from cli_support import EXAMPLES, REPO, TURTLEBOT3_MAP, journal_records, navseq, printed_events
from navseq.errors import NavseqError
from navseq.mission.geodesy import Datum, GeoPoint
from navseq.mission.loader import load_mission
from navseq.run.resume import refuse_another_datum

KEEPOUT = REPO / "maps" / "turtlebot3_world_keepout.yaml"
KEEPOUT_RECORD = {"mask": str(KEEPOUT.resolve()), "type": 0, "base": 0.0, "multiplier": 1.0}


def in_keepout_zone(x: float, y: float) -> bool:
    """The example keepout zone: x 0.15 .. 0.95, y below -1.35 (the south corridor)."""
    return 0.15 <= x <= 0.95 and y <= -1.35


def cut_after_first_arrival(journal: Path) -> None:
    """The journal as a kill -9 right after the first waypoint would have left it."""
    lines = journal.read_bytes().splitlines(keepends=True)
    for number, line in enumerate(lines):
        record = json.loads(line)
        if record.get("type") == "WaypointFinished":
            journal.write_bytes(b"".join(lines[: number + 1]))
            return
    raise AssertionError("no waypoint finished")


@pytest.fixture
def mission(tmp_path: Path) -> Path:
    """South gate, then east dock: the way between runs through the keepout zone."""
    path = tmp_path / "east.yaml"
    path.write_text(
        f"navseq: 1\nmap: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n"
        "waypoints:\n  - {name: south-gate, x: -0.55, y: -1.75, yaw: 0}\n"
        "  - {name: east-dock, x: 1.75, y: -0.55, yaw: 90}\n"
    )
    return path


def test_a_resume_drives_round_the_keepout_zone_of_the_first_run(
    tmp_path: Path, mission: Path
) -> None:
    out = tmp_path / "run"
    first = navseq("run", mission, "--keepout", KEEPOUT, "--out", out, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert json.loads((out / "report.json").read_text())["filters"] == [KEEPOUT_RECORD]
    header = journal_records(out / "journal.jsonl")[0]
    assert header["run"]["filters"] == [KEEPOUT_RECORD] and header["run"]["datum"] is None

    cut_after_first_arrival(out / "journal.jsonl")
    (out / "report.json").unlink()
    resumed = navseq("run", "--resume", out / "journal.jsonl", "--json", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    trail = printed_events(resumed.stdout, "WaypointProgress")
    assert trail and {record["index"] for record in trail} == {1}
    assert not [(r["x"], r["y"]) for r in trail if in_keepout_zone(r["x"], r["y"])]
    assert json.loads((out / "report.json").read_text())["filters"] == [KEEPOUT_RECORD]

    # Without the journaled filters the same leg goes straight through the zone.
    plain = navseq(
        "run", mission, "--from", "2", "--start", "-0.55,-1.75,0", "--json", "--out",
        tmp_path / "p", cwd=tmp_path,
    )  # fmt: skip
    assert plain.returncode == 0, plain.stderr
    straight = printed_events(plain.stdout, "WaypointProgress")
    assert [(r["x"], r["y"]) for r in straight if in_keepout_zone(r["x"], r["y"])]


def test_masks_given_again_on_resume_win_and_are_said(tmp_path: Path, mission: Path) -> None:
    out = tmp_path / "run"
    assert navseq("run", mission, "--keepout", KEEPOUT, "--out", out, cwd=tmp_path).returncode == 0
    cut_after_first_arrival(out / "journal.jsonl")
    (out / "report.json").unlink()
    speed = REPO / "maps" / "turtlebot3_world_speed.yaml"
    resumed = navseq("run", "--resume", out / "journal.jsonl", "--speed-mask", speed, cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert (
        "resuming with --keepout/--speed-mask turtlebot3_world_speed.yaml (speed) instead of "
        "the journal's turtlebot3_world_keepout.yaml (keepout)"
    ) in resumed.stderr + resumed.stdout
    assert [f["type"] for f in json.loads((out / "report.json").read_text())["filters"]] == [1]


def test_navseq_report_rebuilds_with_the_journaled_zones(tmp_path: Path, mission: Path) -> None:
    out = tmp_path / "run"
    assert navseq("run", mission, "--keepout", KEEPOUT, "--out", out, cwd=tmp_path).returncode == 0
    (out / "report.json").unlink()
    rebuilt = navseq("report", out, cwd=tmp_path)
    assert rebuilt.returncode == 0, rebuilt.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["rebuilt_from_journal"] is True
    assert report["filters"] == [KEEPOUT_RECORD]


def test_the_gps_datum_is_in_the_journal_and_report(tmp_path: Path) -> None:
    out = tmp_path / "run"
    done = navseq("run", EXAMPLES / "gps.yaml", "--out", out, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    datum = {"latitude": 52.0116, "longitude": 4.3571, "altitude": 0.0, "yaw_deg": 0.0}
    assert json.loads((out / "report.json").read_text())["datum"] == datum
    assert journal_records(out / "journal.jsonl")[0]["run"]["datum"] == datum


def test_a_resume_refuses_a_mission_whose_datum_is_not_the_journals() -> None:
    mission = load_mission(EXAMPLES / "gps.yaml")
    journaled = {"latitude": 52.0116, "longitude": 4.3571, "altitude": 0.0, "yaw_deg": 0.0}
    refuse_another_datum(mission, SimpleNamespace(run_options={"datum": journaled}))
    refuse_another_datum(mission, SimpleNamespace(run_options={}))  # an older journal
    moved = Datum(GeoPoint(52.0116, 4.3572, 0.0))
    import dataclasses

    with pytest.raises(NavseqError, match="GPS waypoints would land elsewhere"):
        refuse_another_datum(
            dataclasses.replace(mission, datum=moved),
            SimpleNamespace(run_options={"datum": journaled}),
        )
