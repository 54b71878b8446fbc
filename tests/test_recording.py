"""``navseq run --record``: the run as MCAP, read back the way Foxglove and rosbags would.

A sim run of the TurtleBot3 tour is recorded once per encoding (ROS 2 CDR, ROS 1) and
read with the ``mcap`` reader and the ROS 2 / ROS 1 decoders of mcap's ROS support
packages: no navseq code reads the file.
"""

from __future__ import annotations

import io
import itertools
import json
import math
import random
import struct
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from mcap.decoder import DecoderFactory as McapDecoderFactory
from mcap.exceptions import EndOfFile
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Chunk, Message, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap_ros1.decoder import DecoderFactory as Ros1DecoderFactory
from mcap_ros2.decoder import DecoderFactory as Ros2DecoderFactory

from cli_support import EXAMPLES, REPO
from navseq import cli

MISSION = EXAMPLES / "turtlebot3_world.yaml"
GREEN = (0.1, 0.75, 0.2)  # navseq.sinks.mission_status: a reached waypoint's marker
ROS_TOPICS = {
    "/map": "nav_msgs/OccupancyGrid",
    "/navseq/pose": "geometry_msgs/PoseStamped",
    "/odom": "nav_msgs/Odometry",
    "/tf": "tf2_msgs/TFMessage",
    "/plan": "nav_msgs/Path",
    "/navseq/goal": "geometry_msgs/PoseStamped",
    "/navseq/waypoints": "visualization_msgs/MarkerArray",
}


class JsonDecoderFactory(McapDecoderFactory):
    """Decodes the ``json`` channel (navseq's events), as Foxglove does."""

    def decoder_for(
        self, message_encoding: str, schema: Schema | None
    ) -> Callable[[bytes], Any] | None:
        return json.loads if message_encoding == "json" else None


def recorded_run(folder: Path, *extra: str) -> Path:
    code = cli.main(["run", str(MISSION), "--out", str(folder), "--record", *extra])
    assert code == 0
    return folder


@pytest.fixture(scope="module")
def ros2_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return recorded_run(tmp_path_factory.mktemp("ros2") / "out")


@pytest.fixture(scope="module")
def ros1_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return recorded_run(tmp_path_factory.mktemp("ros1") / "out", "--record-format", "ros1")


def decoded(path: Path, ros: McapDecoderFactory) -> list[tuple[str, str, Any]]:
    """(topic, schema name, decoded message) of every message, in log-time order."""
    with path.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[ros, JsonDecoderFactory()])
        return [
            (channel.topic, schema.name if schema else "", message)
            for schema, channel, _, message in reader.iter_decoded_messages()
        ]


def path_length(points: list[tuple[float, float]]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))


def check_recording(run: Path, ros: McapDecoderFactory, type_name: Callable[[str], str]) -> None:
    """What both encodings must show: the topics, the map, the path driven, plans, markers."""
    report = json.loads((run / "report.json").read_text())
    assert report["files"]["recording"] == str(run / "run.mcap")
    messages = decoded(run / "run.mcap", ros)
    schemas = {topic: schema for topic, schema, _ in messages}
    assert schemas == {
        **{topic: type_name(ros_type) for topic, ros_type in ROS_TOPICS.items()},
        "/navseq/events": "",  # schemaless JSON: its JSON Schema is an attachment
    }
    by_topic: dict[str, list[Any]] = {}
    for topic, _, message in messages:
        by_topic.setdefault(topic, []).append(message)

    (grid,) = by_topic["/map"]
    assert (grid.info.width, grid.info.height) == (384, 384)  # maps/turtlebot3_world.pgm
    assert grid.info.resolution == pytest.approx(0.05)
    assert len(grid.data) == 384 * 384 and 100 in set(grid.data)

    poses = [(m.pose.position.x, m.pose.position.y) for m in by_topic["/navseq/pose"]]
    assert poses[0] == pytest.approx((-2.0, -0.5), abs=0.1)  # the mission's start
    driven = report["totals"]["distance_m"]
    assert path_length(poses) == pytest.approx(driven, rel=0.03)
    odom = by_topic["/odom"][len(poses) // 2]
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
    assert 0 < odom.twist.twist.linear.x <= 0.23  # the burger's top speed, m/s
    frames = {(t.header.frame_id, t.child_frame_id) for t in by_topic["/tf"][-1].transforms}
    assert frames == {("map", "odom"), ("odom", "base_footprint")}

    waypoints = report["visits"]
    assert len(by_topic["/navseq/goal"]) == len(waypoints)
    plans = by_topic["/plan"]
    assert len(plans) >= len(waypoints) and all(len(p.poses) >= 2 for p in plans)
    assert plans[0].header.frame_id == "map"
    last_marker = by_topic["/navseq/waypoints"][-1].markers
    assert len(last_marker) == 2 * len(waypoints)  # an arrow and a label each
    for marker in last_marker:  # all reached
        assert (marker.color.r, marker.color.g, marker.color.b) == pytest.approx(GREEN, abs=1e-6)

    events = by_topic["/navseq/events"]
    assert events[0]["event"] == "MissionStarted" and events[-1]["event"] == "MissionFinished"
    schema = json.loads((REPO / "docs" / "schemas" / "events.schema.json").read_text())
    for event in events:
        jsonschema.validate(event, schema)


def test_a_recorded_run_reads_back_with_the_ros2_decoder(ros2_run: Path) -> None:
    def ros2(name: str) -> str:
        package, short = name.split("/")
        return f"{package}/msg/{short}"

    check_recording(ros2_run, Ros2DecoderFactory(), ros2)
    with (ros2_run / "run.mcap").open("rb") as stream:
        header = make_reader(stream).get_header()
    assert header.profile == "ros2"


def test_record_format_ros1_reads_back_with_the_ros1_decoder(ros1_run: Path) -> None:
    check_recording(ros1_run, Ros1DecoderFactory(), lambda name: name)
    with (ros1_run / "run.mcap").open("rb") as stream:
        header = make_reader(stream).get_header()
    assert header.profile == "ros1"


def test_the_events_json_schema_is_attached_to_the_recording(ros2_run: Path) -> None:
    with (ros2_run / "run.mcap").open("rb") as stream:
        attachments = list(make_reader(stream).iter_attachments())
    (attachment,) = attachments
    assert (attachment.name, attachment.media_type) == (
        "events.schema.json",
        "application/schema+json",
    )
    documented = REPO / "docs" / "schemas" / "events.schema.json"
    assert json.loads(attachment.data) == json.loads(documented.read_text())


def test_rosbags_reads_every_ros_topic_of_the_recording(ros2_run: Path) -> None:
    """An independent reader (rosbags, with ROS 2 Jazzy's message types, not the file's)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS2_JAZZY)
    with AnyReader([ros2_run / "run.mcap"], default_typestore=typestore) as reader:
        ros = [c for c in reader.connections if c.topic in ROS_TOPICS]
        assert {c.topic: c.msgtype for c in ros} == {
            topic: name.replace("/", "/msg/") for topic, name in ROS_TOPICS.items()
        }
        poses = [
            reader.deserialize(raw, connection.msgtype).pose.position
            for connection, _, raw in reader.messages(connections=ros)
            if connection.topic == "/navseq/pose"
        ]
    report = json.loads((ros2_run / "report.json").read_text())
    driven = path_length([(p.x, p.y) for p in poses])
    assert driven == pytest.approx(report["totals"]["distance_m"], rel=0.03)


def test_the_recording_ships_the_documented_events_schema() -> None:
    shipped = REPO / "src" / "navseq" / "sinks" / "recording" / "definitions"
    documented = REPO / "docs" / "schemas" / "events.schema.json"
    assert (shipped / "events.schema.json").read_text() == documented.read_text()


def _message_counts_per_chunk(data: bytes) -> list[tuple[int, int]]:
    """(offset where the chunk ends, messages in it) of every chunk, from the summary."""
    reader = make_reader(io.BytesIO(data))
    summary = reader.get_summary()
    assert summary is not None
    ends = []
    for index in sorted(summary.chunk_indexes, key=lambda i: i.chunk_start_offset):
        start, end = index.chunk_start_offset, index.chunk_start_offset + index.chunk_length
        chunk = next(
            iter(
                StreamReader(io.BytesIO(data[start:end]), skip_magic=True, emit_chunks=True).records
            )
        )
        assert isinstance(chunk, Chunk)
        count = sum(isinstance(r, Message) for r in breakup_chunk(chunk))
        ends.append((end, count))
    return ends


def read_as_a_survivor(data: bytes) -> list[tuple[str, int]]:
    """(topic, log time) of every message a streaming reader decodes before the file
    ends: the reader for a file whose writer died (no summary to seek with)."""
    factories = [Ros2DecoderFactory(), JsonDecoderFactory()]
    reader = NonSeekingReader(io.BytesIO(data), decoder_factories=factories)
    read = []
    try:
        # In file order, as they come: sorting by time would read the whole file first.
        for _, channel, message, _ in reader.iter_decoded_messages(log_time_order=False):
            read.append((channel.topic, message.log_time))
    except (EndOfFile, struct.error):  # where the crash cut it (struct: inside a length)
        pass
    return read


def test_a_file_cut_at_a_random_byte_reads_up_to_its_last_complete_chunk(
    ros2_run: Path,
) -> None:
    data = (ros2_run / "run.mcap").read_bytes()
    chunks = _message_counts_per_chunk(data)
    assert len(chunks) >= 5  # small chunks: a crash loses little
    whole = read_as_a_survivor(data)
    assert len(whole) == sum(count for _, count in chunks)
    rng = random.Random(18)
    for cut in sorted(rng.randrange(len(data)) for _ in range(12)):
        survived = read_as_a_survivor(data[:cut])
        complete = sum(count for end, count in chunks if end <= cut)
        assert len(survived) == complete, f"cut at byte {cut} of {len(data)}"
        assert survived == whole[: len(survived)]
    assert Counter(topic for topic, _ in whole)["/map"] == 1


def test_the_foxglove_layout_shows_topics_the_recording_has(ros2_run: Path) -> None:
    layout = json.loads((REPO / "docs" / "foxglove" / "navseq-layout.json").read_text())
    panels = layout["configById"]
    three_d = panels["3D!navseq"]
    assert three_d["followTf"] == "map"
    shown = set(three_d["topics"])
    shown.add(panels["RawMessages!navseqevents"]["topicPath"])
    shown |= {path["value"].split(".")[0] for path in panels["Plot!navseqspeed"]["paths"]}
    with (ros2_run / "run.mcap").open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    recorded = {channel.topic for channel in summary.channels.values()}
    assert {"/map", "/navseq/pose", "/plan", "/navseq/waypoints", "/navseq/events"} <= shown
    assert shown <= recorded


def test_a_long_missions_markers_change_one_waypoint_at_a_time(tmp_path: Path) -> None:
    """All markers at the start; then only the changed waypoint's, so that a recording
    of a 100 000-waypoint mission does not grow with the square of its waypoints."""
    from navseq.executor.events import (
        MissionStarted,
        WaypointFinished,
        WaypointOutcome,
        WaypointStarted,
    )
    from navseq.mission.model import Mission, Waypoint
    from navseq.sinks.recording.sink import FULL_MARKERS_UP_TO, RecordingSink

    count = FULL_MARKERS_UP_TO + 1
    mission = Mission(tuple(Waypoint(float(i), 0.0) for i in range(count)))
    path = tmp_path / "run.mcap"
    with RecordingSink(path, "ros2", mission) as sink:
        sink(MissionStarted(0.0, count, 1))
        sink(WaypointStarted(1.0, 7, 0, 1, 1, 7.0, 0.0, 0.0))
        sink(WaypointFinished(2.0, 7, 0, WaypointOutcome.REACHED, 1, 1.0, 1.0))
    arrays = [m for topic, _, m in decoded(path, Ros2DecoderFactory()) if topic.endswith("points")]
    assert [len(a.markers) for a in arrays] == [2 * count, 2, 2]
    assert {m.id for m in arrays[-1].markers} == {7}
    for marker in arrays[-1].markers:
        assert (marker.color.r, marker.color.g, marker.color.b) == pytest.approx(GREEN, abs=1e-6)
