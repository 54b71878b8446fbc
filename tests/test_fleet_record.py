"""``navseq run --fleet FLEET --record``: one MCAP for the fleet, each robot under its namespace.

Read back as a Foxglove user's tools read it (rosbags, the mcap ROS decoders): one map,
one tf tree joining every robot's frames at ``map``, each robot's topics under its
namespace, every robot on the one clock, and each robot's path the one its run drove.
"""

from __future__ import annotations

import itertools
import json
import math
import signal
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from mcap_ros1.decoder import DecoderFactory as Ros1DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from cli_support import (
    EXAMPLES,
    TURTLEBOT3_MAP,
    assert_clean_error,
    journal_events,
    navseq,
    start_navseq,
    wait_for,
)

FLEET = EXAMPLES / "fleet.yaml"
PER_ROBOT = {
    "/navseq/pose": "geometry_msgs/msg/PoseStamped",
    "/odom": "nav_msgs/msg/Odometry",
    "/plan": "nav_msgs/msg/Path",
    "/navseq/goal": "geometry_msgs/msg/PoseStamped",
    "/navseq/waypoints": "visualization_msgs/msg/MarkerArray",
}


def read_ros2(path: Path) -> dict[str, list[tuple[int, Any]]]:
    """Topic -> (log time ns, decoded message) in file order, with rosbags (no ROS)."""
    by_topic: dict[str, list[tuple[int, Any]]] = {}
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        ros = [c for c in reader.connections if c.msgtype != "__schemaless__"]
        for connection, t, raw in reader.messages(connections=ros):
            message = reader.deserialize(raw, connection.msgtype)
            by_topic.setdefault(connection.topic, []).append((t, message))
        types = {c.topic: c.msgtype for c in reader.connections}
    by_topic["<types>"] = [(0, types)]
    return by_topic


def json_events(path: Path, topic: str) -> list[dict[str, Any]]:
    with path.open("rb") as stream:
        return [
            json.loads(data)
            for _, channel, message in make_reader(stream).iter_messages(topics=[topic])
            for data in (message.data,)
            if channel.message_encoding == "json"
        ]


def path_length(points: list[tuple[float, float]]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fleet-record")
    done = navseq("run", "--fleet", FLEET, "--out", folder / "run", "--record", cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder / "run"


def test_one_file_for_the_fleet_each_robot_under_its_namespace(recorded: Path) -> None:
    report = json.loads((recorded / "fleet-report.json").read_text())
    assert report["files"]["recording"] == str(recorded / "fleet.mcap")
    robots = [row["name"] for row in report["robots"]]
    assert robots == ["alpha", "beta", "gamma"]
    for name in robots:  # no one-robot recordings beside the fleet's
        assert not list((recorded / name).glob("*.mcap"))
    by_topic = read_ros2(recorded / "fleet.mcap")
    types = by_topic.pop("<types>")[0][1]
    expected = {"/map": "nav_msgs/msg/OccupancyGrid", "/tf": "tf2_msgs/msg/TFMessage"}
    for name in robots:
        expected.update({f"/{name}{topic}": kind for topic, kind in PER_ROBOT.items()})
        expected[f"/{name}/navseq/events"] = "__schemaless__"
    assert types == expected
    ((_, grid),) = by_topic["/map"]  # one map for all
    assert (grid.info.width, grid.info.height) == (384, 384)

    # One tf tree: every robot's frames carry its namespace and meet at map.
    frames = {
        (t.header.frame_id, t.child_frame_id) for _, m in by_topic["/tf"] for t in m.transforms
    }
    assert frames == {
        pair
        for name in robots
        for pair in (("map", f"{name}/odom"), (f"{name}/odom", f"{name}/base_footprint"))
    }
    for row in report["robots"]:
        name = row["name"]
        poses = by_topic[f"/{name}/navseq/pose"]
        odom = by_topic[f"/{name}/odom"]
        tf_of_robot = [
            m for _, m in by_topic["/tf"] if m.transforms[0].child_frame_id == f"{name}/odom"
        ]
        assert len(poses) == len(odom) == len(tf_of_robot) > 10
        assert (odom[5][1].header.frame_id, odom[5][1].child_frame_id) == (
            f"{name}/odom",
            f"{name}/base_footprint",
        )
        # Its stamps go forward, on the fleet's one clock (0 when the robots set out).
        stamps = [t for t, _ in poses]
        assert stamps == sorted(stamps)
        assert stamps[0] / 1e9 < 1.0
        assert stamps[-1] / 1e9 == pytest.approx(row["mission_time_s"], abs=1.0)
        # The path it drove, as its own run measured it, from its start in the fleet file.
        points = [(m.pose.position.x, m.pose.position.y) for _, m in poses]
        assert path_length(points) == pytest.approx(row["distance_m"], rel=0.03)
        assert len(by_topic[f"/{name}/navseq/goal"]) == row["waypoints"]
        last = by_topic[f"/{name}/navseq/waypoints"][-1][1].markers
        assert len(last) == 2 * row["waypoints"]  # an arrow and a label each
        # Its events are its journal's: every waypoint it finished, in the same order.
        recorded_ends = [
            (e["index"], e["outcome"])
            for e in json_events(recorded / "fleet.mcap", f"/{name}/navseq/events")
            if e["event"] == "WaypointFinished"
        ]
        journal = recorded / name / "journal.jsonl"
        assert recorded_ends == [
            (e["index"], e["outcome"]) for e in journal_events(journal, "WaypointFinished")
        ]
    starts = {name: by_topic[f"/{name}/navseq/pose"][0][1].pose.position for name in robots}
    assert (starts["beta"].x, starts["beta"].y) == pytest.approx((2.0, 0.5), abs=0.1)
    with (recorded / "fleet.mcap").open("rb") as stream:
        reader = make_reader(stream)
        (metadata,) = list(reader.iter_metadata())
        attachments = [a.name for a in reader.iter_attachments()]
    assert metadata.name == "navseq.fleet"
    assert json.loads(metadata.metadata["robots"]) == {name: name for name in robots}
    assert attachments == ["events.schema.json"]  # once for the file


def two_robot_fleet(folder: Path, namespace: str = "", record: str = "") -> Path:
    (folder / "mission.yaml").write_text(
        f"navseq: 1\n{record}waypoints:\n"
        "  - {name: near, x: -1.6, y: -0.5, yaw: 0}\n"
        "  - {name: east-dock, x: 1.75, y: -0.55, yaw: 90}\n"
        "  - {name: inner-east, x: 0.55, y: 0.55, yaw: 180}\n"
        "  - {name: north-dock, x: 0.0, y: 1.75, yaw: 180}\n"
    )
    fleet = folder / "fleet.yaml"
    fleet.write_text(
        f"navseq_fleet: 1\nmission: mission.yaml\nmap: {TURTLEBOT3_MAP}\nrobots:\n"
        f"  - {{name: a, {namespace}start: {{x: -2.0, y: -0.5, yaw: 0}}}}\n"
        "  - {name: b, start: {x: 2.0, y: 0.5, yaw: 180}}\n"
        "waypoints:\n  near: {robots: [a]}\n  east-dock: {robots: [b]}\n"
        "  inner-east: {robots: [b]}\n  north-dock: {robots: [b]}\n"
    )
    return fleet


def test_record_true_in_the_mission_records_the_fleet_in_ros1_encoding(tmp_path: Path) -> None:
    fleet = two_robot_fleet(tmp_path, "namespace: /site/a, ", "record: true\n")
    out = tmp_path / "run"
    done = navseq("run", "--fleet", fleet, "--out", out, "--record-format", "ros1", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert not list(out.glob("*/*.mcap"))  # not one file per robot
    with (out / "fleet.mcap").open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[Ros1DecoderFactory()])
        assert reader.get_header().profile == "ros1"
        summary = reader.get_summary()
        assert summary is not None
        ros_topics = [c.topic for c in summary.channels.values() if c.message_encoding == "ros1"]
        messages = [
            (channel.topic, schema.name, message)
            for schema, channel, _, message in reader.iter_decoded_messages(topics=ros_topics)
            if schema is not None
        ]
    topics = {topic for topic, _, _ in messages}
    assert "/site/a/navseq/pose" in topics and "/b/navseq/pose" in topics
    assert {name for topic, name, _ in messages if topic == "/site/a/odom"} == {"nav_msgs/Odometry"}
    frames = {t.child_frame_id for topic, _, m in messages if topic == "/tf" for t in m.transforms}
    assert frames == {"site/a/odom", "site/a/base_footprint", "b/odom", "b/base_footprint"}
    manifest = json.loads((out / "fleet-run.json").read_text())
    assert (manifest["record"], manifest["record_format"]) == (True, "ros1")


def test_a_resumed_recorded_fleet_run_records_beside_the_first_file(tmp_path: Path) -> None:
    fleet = two_robot_fleet(tmp_path)
    run = tmp_path / "run"
    process = start_navseq(
        "run", "--fleet", fleet, "--out", run, "--record", "--realtime", "2", cwd=tmp_path
    )
    try:
        # a is done and b has reached its first waypoint (of three): stop the fleet.
        wait_for(
            lambda: (
                journal_events(run / "a" / "journal.jsonl", "MissionFinished")
                and any(
                    e["outcome"] == "reached"
                    for e in journal_events(run / "b" / "journal.jsonl", "WaypointFinished")
                )
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
    first = (run / "fleet.mcap").read_bytes()

    resumed = navseq("run", "--fleet", fleet, "--resume", run, cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert (run / "fleet.mcap").read_bytes() == first  # nothing written is touched
    report = json.loads((run / "fleet-report.json").read_text())
    assert report["files"]["recording"] == str(run / "fleet-2.mcap")
    before = read_ros2(run / "fleet.mcap")
    after = read_ros2(run / "fleet-2.mcap")
    assert "/a/navseq/pose" in before and "/b/navseq/pose" in before
    # Only b drives on (a's share was done); the map is there again for the new file.
    assert "/a/navseq/pose" not in after and len(after["/map"]) == 1
    ends = [
        e["index"]
        for e in json_events(run / "fleet-2.mcap", "/b/navseq/events")
        if e["event"] == "WaypointFinished"
    ]
    done_before = [
        e["index"]
        for e in json_events(run / "fleet.mcap", "/b/navseq/events")
        if e["event"] == "WaypointFinished" and e["outcome"] == "reached"
    ]
    assert sorted(done_before + ends) == [0, 1, 2]  # each of b's waypoints reached once


def test_a_fleet_run_killed_mid_run_leaves_a_file_read_up_to_its_last_chunk(
    tmp_path: Path,
) -> None:
    import io
    import struct

    from mcap.exceptions import EndOfFile
    from mcap.reader import NonSeekingReader

    from cli_support import kill_9_when

    fleet = two_robot_fleet(tmp_path)
    run = tmp_path / "run"
    process = start_navseq(
        "run", "--fleet", fleet, "--out", run, "--record", "--realtime", "4", cwd=tmp_path
    )

    def a_done_and_b_later() -> bool:
        # b steps on past a's end only once a's run has left the fleet's clock: its
        # recording's part is handed to the system by then (flushed as it ends).
        a_end = journal_events(run / "a" / "journal.jsonl", "MissionFinished")
        b_ends = journal_events(run / "b" / "journal.jsonl", "WaypointFinished")
        return bool(a_end) and any(e["t"] > a_end[0]["t"] for e in b_ends)

    kill_9_when(process, a_done_and_b_later, 60, "robot a done, then b at a waypoint")
    topics = []
    reader = NonSeekingReader(io.BytesIO((run / "fleet.mcap").read_bytes()))
    try:  # no summary: a streaming reader reads the records in file order
        for _, channel, _ in reader.iter_messages(log_time_order=False):
            topics.append(channel.topic)
    except (EndOfFile, struct.error):
        pass
    # Flushed at every waypoint's end: what a's journal says is done is in the file.
    assert topics.count("/map") == 1 and "/a/navseq/goal" in topics
    assert topics.count("/a/navseq/pose") > 5 and "/b/navseq/pose" in topics
    assert "/a/navseq/events" in topics


def test_record_topics_is_refused_where_a_fleet_cannot_record_them(tmp_path: Path) -> None:
    for extra, said in (
        (("--record-topics", "/scan"), "add --record"),
        (("--record", "--record-topics", "/scan"), "with --navigator ros1 or nav2 only"),
        (
            (
                "--record",
                "--record-topics",
                "/scan",
                "--navigator",
                "nav2",
                "--record-format",
                "ros1",
            ),
            "add --record-format ros2",
        ),
    ):
        done = navseq("run", "--fleet", FLEET, *extra, cwd=tmp_path)
        assert_clean_error(done)
        assert "--record-topics" in done.stderr and said in done.stderr
        assert not (tmp_path / "navseq-out").exists()
