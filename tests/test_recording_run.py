"""Recording as part of a run: asked for by the mission, after a crash, on resume, refused.

The file's content is tests/test_recording.py's business; here: which files a run
leaves, what survives ``kill -9``, and what the user is told.
"""

from __future__ import annotations

import io
import json
import signal
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import jsonschema
import pytest
from mcap.exceptions import EndOfFile
from mcap.reader import NonSeekingReader, make_reader
from mcap_ros2.decoder import DecoderFactory

from cli_support import EXAMPLES, journal_events, navseq, start_navseq, wait_for
from navseq import cli

MISSION = EXAMPLES / "turtlebot3_world.yaml"
DOCS = EXAMPLES.parent / "docs"


def survivor_topics(path: Path) -> list[str]:
    """The topics of the messages a streaming reader gets from a file, in file order,
    up to where it ends (a file whose writer died has no summary)."""
    reader = NonSeekingReader(io.BytesIO(path.read_bytes()))
    topics = []
    try:
        for _, channel, _ in reader.iter_messages(log_time_order=False):
            topics.append(channel.topic)
    except (EndOfFile, struct.error):
        pass
    return topics


def test_record_true_in_the_mission_records_without_the_option(tmp_path: Path) -> None:
    mission = tmp_path / "recorded.yaml"
    text = MISSION.read_text().replace("loops: 1", "loops: 1\nrecord: true")
    mission.write_text(text.replace("../maps/", str(EXAMPLES.parent / "maps") + "/"))
    out = tmp_path / "out"
    assert cli.main(["run", str(mission), "--out", str(out), "--to", "2"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["files"]["recording"] == str(out / "run.mcap")
    with (out / "run.mcap").open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    assert summary.statistics.message_count > 100


def test_record_must_be_true_or_false_in_a_mission(tmp_path: Path) -> None:
    mission = tmp_path / "wrong.yaml"
    mission.write_text("navseq: 1\nrecord: always\nwaypoints:\n  - {x: 0, y: 0, yaw: 0}\n")
    done = navseq("validate", mission, cwd=tmp_path)
    assert done.returncode == 2
    assert "record" in done.stderr and "must be true or false" in done.stderr


def test_an_unknown_record_format_is_exit_2_naming_the_choices(tmp_path: Path) -> None:
    done = navseq("run", MISSION, "--record", "--record-format", "ros3", cwd=tmp_path)
    assert done.returncode == 2
    assert "--record-format" in done.stderr and "'ros2', 'ros1'" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "navseq-out").exists()


def test_a_killed_run_leaves_a_readable_recording_and_resume_records_beside_it(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    first = start_navseq(
        "run", MISSION, "--record", "--realtime", "8", "--json", "--out", out, cwd=tmp_path
    )
    journal = out / "journal.jsonl"
    try:
        wait_for(lambda: len(journal_events(journal, "WaypointFinished")) >= 2, 60, "2 waypoints")
        first.send_signal(signal.SIGKILL)
        first.wait(timeout=20)
    finally:
        first.kill()
        first.communicate()
    # Flushed at every waypoint's end: what the journal says is done is in the recording.
    topics = survivor_topics(out / "run.mcap")
    assert topics.count("/map") == 1 and topics.count("/navseq/goal") >= 2
    assert topics.count("/navseq/pose") > 50

    done = navseq("run", "--resume", journal, "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    last = json.loads(done.stdout.splitlines()[-1])
    assert last["event"] == "RunFinished"
    assert last["files"]["recording"] == str(out / "run-2.mcap")
    jsonschema.validate(last, json.loads((DOCS / "schemas" / "events.schema.json").read_text()))
    report = json.loads((out / "report.json").read_text())
    assert report["files"]["recording"] == str(out / "run-2.mcap")
    assert survivor_topics(out / "run.mcap") == topics  # the first file is left as it was
    with (out / "run-2.mcap").open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        goals = [m for _, c, _, m in reader.iter_decoded_messages(topics=["/navseq/goal"])]
    assert 0 < len(goals) <= 6  # the waypoints left, the active one again
    assert (goals[-1].pose.position.x, goals[-1].pose.position.y) == (-2.0, -0.5)  # home


def test_navseq_report_rebuilds_report_and_picture_from_the_recording_without_journal(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    assert cli.main(["run", str(MISSION), "--out", str(out), "--record"]) == 0
    original = json.loads((out / "report.json").read_text())
    for name in ("journal.jsonl", "report.json", "mission.png"):
        (out / name).unlink()

    done = navseq("report", out, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["rebuilt_from_recording"] is True
    assert report["files"]["recording"] == str(out / "run.mcap")
    assert "journal" not in report["files"]
    assert report["totals"] == original["totals"]
    outcomes = [(v["number"], v["outcome"], v["distance_m"]) for v in report["visits"]]
    assert outcomes == [(v["number"], v["outcome"], v["distance_m"]) for v in original["visits"]]
    assert report["exit_code"] == 0 and report["success"] is True
    schema = json.loads((DOCS / "schemas" / "report.schema.json").read_text())
    jsonschema.validate(report, schema)
    assert (out / "mission.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_navseq_report_of_a_folder_without_journal_or_recording_says_so(tmp_path: Path) -> None:
    done = navseq("report", tmp_path, cwd=tmp_path)
    assert done.returncode == 2
    assert "holds no recording (run.mcap)" in done.stderr


# As tests/test_layers.py: every import of ROS fails, as on a machine without it.
NO_ROS = textwrap.dedent(
    """
    import importlib.abc, sys

    ROS = ("rospy", "genpy", "genmsg", "roslib", "rclpy", "std_msgs", "geometry_msgs",
           "nav_msgs", "visualization_msgs", "tf2_msgs", "builtin_interfaces", "rosbag")

    class NoRos(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ROS:
                raise ModuleNotFoundError(f"No module named {name!r} (no ROS here)")
            return None

    sys.meta_path.insert(0, NoRos())
    from navseq.cli import main
    sys.exit(main(sys.argv[1:]))
    """
)


def test_a_ros1_recording_needs_no_ros_installed(tmp_path: Path) -> None:
    out = tmp_path / "out"
    args = ["run", str(MISSION), "--to", "2", "--record", "--record-format", "ros1"]
    done = subprocess.run(
        [sys.executable, "-c", NO_ROS, *args, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    from mcap_ros1.decoder import DecoderFactory as Ros1DecoderFactory

    with (out / "run.mcap").open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[Ros1DecoderFactory()])
        (grid,) = [m for _, _, _, m in reader.iter_decoded_messages(topics=["/map"])]
    assert (grid.info.width, grid.info.height) == (384, 384)


def test_record_topics_is_refused_where_it_cannot_work(tmp_path: Path) -> None:
    done = navseq("run", MISSION, "--record-topics", "/scan", cwd=tmp_path)
    assert done.returncode == 2
    assert "--record-topics: adds topics to a recording: add --record" in done.stderr
    done = navseq("run", MISSION, "--record", "--record-topics", "/scan", cwd=tmp_path)
    assert done.returncode == 2
    assert "with --navigator ros1 or nav2 only (not sim)" in done.stderr
    # Refused before navseq looks for a ROS master (there is none here).
    ros1 = ("--navigator", "ros1", "--record", "--record-topics", "/scan")
    done = navseq("run", MISSION, *ros1, cwd=tmp_path)
    assert done.returncode == 2
    assert "records the ROS 1 stack's messages as they are published" in done.stderr
    assert "--record-format ros1" in done.stderr
    nav2 = ("--navigator", "nav2", "--record", "--record-format", "ros1", "--record-topics", "/a")
    done = navseq("run", MISSION, *nav2, cwd=tmp_path)
    assert done.returncode == 2
    assert "records the ROS 2 stack's messages as they are published" in done.stderr
    assert "--record-format ros2" in done.stderr
    assert not (tmp_path / "navseq-out").exists()


def test_record_true_survives_a_round_trip_through_the_mission_writer(tmp_path: Path) -> None:
    from navseq.mission import load_mission
    from navseq.mission.writer import dump_mission_yaml

    mission = tmp_path / "recorded.yaml"
    mission.write_text("navseq: 1\nrecord: true\nwaypoints:\n  - {x: 0, y: 0, yaw: 0}\n")
    loaded = load_mission(mission)
    assert loaded.record is True
    again = tmp_path / "again.yaml"
    again.write_text(dump_mission_yaml(loaded))
    assert load_mission(again).record is True
    mission.write_text("navseq: 1\nwaypoints:\n  - {x: 0, y: 0, yaw: 0}\n")
    assert "record" not in dump_mission_yaml(load_mission(mission))


def test_a_run_refused_before_its_start_leaves_no_recording(tmp_path: Path) -> None:
    """No navigation server: nothing ran, so there is nothing to record (as no journal)."""
    from navseq.errors import NavseqError
    from navseq.mission.model import Mission, Waypoint
    from navseq.navigators.scripted import ScriptedNavigator
    from navseq.run.request import Outputs, RunRequest, UseNavigator
    from navseq.run.session import prepare

    out = tmp_path / "out"
    out.mkdir()
    request = RunRequest(
        mission=Mission((Waypoint(1.0, 0.0),)),
        navigator=UseNavigator(ScriptedNavigator(server_available=False), {"kind": "scripted"}),
        outputs=Outputs(folder=out, journal=False, record=True),
        preflight=False,
        server_wait=0.2,
    )
    with pytest.raises(NavseqError):
        prepare(request).run()
    assert not (out / "run.mcap").exists()
