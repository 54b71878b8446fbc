"""``navseq run --navigator ros1 --record``: a real ROS 1 stack's run recorded, with
``--record-topics`` the stack's own messages as it published them.

Against navseq's simulated move_base and robot on a private rosmaster (real nodes).
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros1.decoder import DecoderFactory

from cli_support import NAVSEQ, write_mission
from ros_clients import MAP, start_sim

pytestmark = pytest.mark.ros

PLAN = "/move_base/NavfnROS/plan"


def test_record_topics_records_what_the_stack_publishes(ros_master, tmp_path: Path) -> None:
    start_sim(ros_master)
    mission = write_mission(
        tmp_path / "ros.yaml",
        "  - {name: west, x: -1.6, y: -0.5, yaw: 90}\n",
        "defaults: {goal_timeout: 120}\n",
    )
    out = tmp_path / "out"
    process = ros_master.start(
        [
            NAVSEQ,
            "run",
            mission,
            "--navigator",
            "ros1",
            "--map",
            MAP,
            "--out",
            out,
            "--record",
            "--record-format",
            "ros1",
            "--record-topics",
            f"/odom,{PLAN}",
        ],
        cwd=tmp_path,
        label="navseq",
    )
    assert process.wait(timeout=120) == 0, process.output()
    report = json.loads((out / "report.json").read_text())
    assert report["files"]["recording"] == str(out / "run.mcap")
    with (out / "run.mcap").open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None
        types = {
            c.topic: summary.schemas[c.schema_id].name
            for c in summary.channels.values()
            if c.schema_id  # 0: the events' schemaless JSON
        }
        odom = [m for _, _, _, m in reader.iter_decoded_messages(topics=["/odom"])]
    assert types.get("/odom") == "nav_msgs/Odometry" and types.get(PLAN) == "nav_msgs/Path", types
    assert types["/navseq/pose"] == "geometry_msgs/PoseStamped"  # navseq's own, still there
    # The stack's odometry (its child frame, its rate), not navseq's rebuilt one.
    assert Counter(m.header.frame_id for m in odom) == {"odom": len(odom)}
    # In the stack's odom frame, which begins where the robot started (-2.0, -0.5):
    # navseq's own odometry would say the map's -1.6.
    assert odom[-1].pose.pose.position.x == pytest.approx(0.4, abs=0.2)
    with (out / "run.mcap").open("rb") as stream:
        statistics = make_reader(stream).get_summary().statistics  # type: ignore[union-attr]
    counts = {summary.channels[c].topic: n for c, n in statistics.channel_message_counts.items()}
    assert counts[PLAN] >= 1 and counts["/odom"] > counts["/navseq/pose"]
