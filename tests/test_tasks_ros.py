"""A mission's ROS tasks on the real ROS navigators: ``navseq run --navigator ros1``
against a real rosmaster and ``--navigator nav2`` against real rclpy, each with a
scripted navigation server and a task peer (``ros_task_peer.py`` /
``ros2_task_peer.py``) that publishes what the tasks wait for, answers their call and
receives what they publish. Written once, run on both ROS."""

from __future__ import annotations

import json
from pathlib import Path

from PIL import Image

from cli_support import printed_events, write_mission
from ros_behaviour_support import ScriptedStack, report_of, stack
from task_peer_image import PIXELS

__all__ = ["stack"]  # the fixture, ROS 1 and ROS 2

RUN_TIMEOUT = 120.0

TASKS = """\
  - name: dock
    x: 1.0
    y: 0.0
    yaw: 0
    tasks:
      - wait_for: {topic: /counter, type: std_msgs/Int32, field: data, above: 5}
      - snapshot: {topic: /camera/image, type: sensor_msgs/msg/Image}
      - call: {service: /ready_check}
      - publish: {topic: /beep, type: std_msgs/String, message: {data: arrived at dock}}
      - snapshot: {topic: /counter, type: std_msgs/Int32}
"""


def peer_events(log: Path) -> list[dict[str, object]]:
    return [json.loads(line) for line in log.read_text().splitlines() if line.strip()]


def run(stack: ScriptedStack, tmp_path: Path, waypoints: str, defaults: str = "") -> Path:
    out = tmp_path / "out"
    header = f"defaults: {{{defaults}}}\n" if defaults else ""
    stack.start_navseq(write_mission(tmp_path / "m.yaml", waypoints, header), out)
    stack.finish(RUN_TIMEOUT)
    return out


def test_every_ros_task_runs_against_real_ros(stack: ScriptedStack, tmp_path: Path) -> None:
    stack.start_server("succeed:0.3")
    peer_log = tmp_path / "peer.jsonl"
    stack.start_task_peer(peer_log)
    out = tmp_path / "out"
    stack.start_navseq(write_mission(tmp_path / "m.yaml", TASKS), out)
    assert stack.finish(RUN_TIMEOUT) == 0, stack.output()[-4000:]

    tasks = report_of(out)["visits"][0]["tasks"]
    assert [(t["kind"], t["outcome"]) for t in tasks] == [
        ("wait_for", "succeeded"),
        ("snapshot", "succeeded"),
        ("call", "succeeded"),
        ("publish", "succeeded"),
        ("snapshot", "succeeded"),
    ], tasks
    wait_for, image, call, publish, counter = tasks
    assert wait_for["detail"].startswith("/counter data = "), wait_for
    assert int(wait_for["detail"].split(" = ")[1].split()[0]) > 5
    assert call["detail"] == "/ready_check: success true, message 'ready'"
    assert publish["detail"].startswith("published on /beep")

    # The image is a PNG of the published pixels (the rows' padding left out).
    assert image["files"] == ["snapshots/dock-task2.png"]
    with Image.open(out / image["files"][0]) as picture:
        assert picture.mode == "RGB" and picture.size == (3, 2)
        assert [list(row) for row in _rows(picture)] == [list(row) for row in PIXELS]
    # Any other message: its YAML.
    assert counter["files"] == ["snapshots/dock-task5.yaml"]
    assert "data: " in (out / counter["files"][0]).read_text()

    events = peer_events(peer_log)
    assert {"event": "called"} in events
    assert {"event": "received", "data": "arrived at dock"} in events
    assert len(printed_events(stack.output(), "TaskStarted")) == 5


def _rows(picture: Image.Image) -> list[tuple[tuple[int, int, int], ...]]:
    width, height = picture.size
    return [tuple(picture.getpixel((x, y)) for x in range(width)) for y in range(height)]


def test_a_wait_for_that_never_comes_times_out_under_on_failure(
    stack: ScriptedStack, tmp_path: Path
) -> None:
    stack.start_server("succeed:0.3")
    waypoints = (
        "  - x: 1.0\n    y: 0.0\n    on_failure: skip\n    tasks:\n"
        "      - wait_for: {topic: /never, type: std_msgs/Bool, field: data, equals: true}\n"
        "        timeout: 1\n"
        "  - {x: 2.0, y: 0.0}\n"
    )
    out = run(stack, tmp_path, waypoints)
    visits = report_of(out)["visits"]
    assert [t["outcome"] for t in visits[0]["tasks"]] == ["timed_out"], visits[0]
    assert [v["outcome"] for v in visits] == ["skipped", "reached"]  # on_failure: skip


def test_a_type_the_running_ros_lacks_is_refused_before_anything_moves(
    stack: ScriptedStack, tmp_path: Path
) -> None:
    waypoints = (
        "  - x: 1.0\n    y: 0.0\n    tasks:\n"
        "      - wait_for: {topic: /x, type: std_msgs/NoSuchType, field: data, equals: 1}\n"
        "      - call: {service: /y, type: nowhere_srvs/Nothing}\n"
        "      - publish: {topic: /z, type: std_msgs/String, message: {dta: x}}\n"
        "      - call: {service: /y, type: std_srvs/SetBool, request: {flag: true}}\n"
    )
    out = tmp_path / "out"
    stack.start_navseq(write_mission(tmp_path / "m.yaml", waypoints), out)
    assert stack.finish(RUN_TIMEOUT) == 2
    said = stack.output()
    assert "m.yaml:6, waypoint 1, task 1 (wait_for): message type std_msgs/NoSuchType" in said
    assert "m.yaml:7, waypoint 1, task 2 (call): service type nowhere_srvs/Nothing" in said
    assert (
        "m.yaml:8, waypoint 1, task 3 (publish): message does not fit a std_msgs/String "
        "message: " in said
    )
    assert (
        "m.yaml:9, waypoint 1, task 4 (call): request does not fit the request of "
        "std_srvs/SetBool: " in said
    )
    assert "Traceback" not in said
    assert not out.exists()


def test_record_topics_records_what_the_stack_publishes(
    stack: ScriptedStack, tmp_path: Path
) -> None:
    """``--record-topics`` on both ROS: the peer's messages as it published them, in the
    recording's encoding of that ROS, with the type's full definition as schema."""
    from mcap.reader import make_reader

    stack.start_server("succeed:0.5")
    stack.start_task_peer(tmp_path / "peer.jsonl")
    out = tmp_path / "out"
    record_format = "ros1" if stack.name == "ros1" else "ros2"
    waypoints = "  - {x: 1.0, y: 0.0, tasks: [{wait: 1.5}]}\n"
    stack.start_navseq(
        write_mission(tmp_path / "m.yaml", waypoints),
        out,
        *("--record", "--record-format", record_format, "--record-topics", "/counter"),
    )
    assert stack.finish(RUN_TIMEOUT) == 0, stack.output()[-4000:]
    if record_format == "ros1":
        from mcap_ros1.decoder import DecoderFactory
    else:
        from mcap_ros2.decoder import DecoderFactory  # type: ignore[no-redef]
    with (out / "run.mcap").open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None
        types = {
            c.topic: summary.schemas[c.schema_id].name
            for c in summary.channels.values()
            if c.schema_id
        }
        counts = [m.data for _, _, _, m in reader.iter_decoded_messages(topics=["/counter"])]
    expected = "std_msgs/Int32" if record_format == "ros1" else "std_msgs/msg/Int32"
    assert types["/counter"] == expected, types
    # The peer counts up every 0.1 s: the run's second and a half holds many, in order.
    assert len(counts) >= 5 and counts == sorted(counts), counts
