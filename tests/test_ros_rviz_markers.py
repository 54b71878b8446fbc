"""One RViz view for navseq's simulator and a real move_base; markers from ``navseq run``.

``rviz/navseq.rviz`` subscribes only to topics a real move_base publishes (and navseq's
markers); the sim's nodes publish the same ones. ``navseq run --navigator ros1``
publishes the waypoint markers and status the navseq node does. The ros1 navigator's
odometry pose comes from TF (odom -> base frame).
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest
import yaml

from cli_support import NAVSEQ, write_mission
from ros_clients import MAP, START, start_sim
from ros_support import REPO_ROOT, RosMaster, wait_for

pytestmark = pytest.mark.ros

RVIZ = REPO_ROOT / "rviz" / "navseq.rviz"
MARKERS, STATUS = "/navseq/waypoints", "/navseq/status"


def rviz_topics() -> set[str]:
    config = yaml.safe_load(RVIZ.read_text())
    displays = config["Visualization Manager"]["Displays"]
    return {d.get("Topic") or d.get("Marker Topic") for d in displays} - {None}


FOOTPRINT_SAMPLE = textwrap.dedent(
    """
    import json, rospy
    from geometry_msgs.msg import PolygonStamped
    rospy.init_node("footprint_sample", anonymous=True)
    msg = rospy.wait_for_message("/move_base/local_costmap/footprint", PolygonStamped, 30)
    print(json.dumps({"frame": msg.header.frame_id,
                      "points": [[p.x, p.y] for p in msg.polygon.points]}), flush=True)
    """
)


def test_every_topic_of_the_rviz_config_is_published_by_the_sim_stack(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master)
    topics = rviz_topics()
    assert "/move_base/local_costmap/footprint" in topics  # move_base's, not the sim's own
    from_the_stack = {topic for topic in topics if not topic.startswith("/navseq/")}
    assert from_the_stack == topics - {MARKERS}
    for topic in sorted(from_the_stack):
        ros_master.wait_for_publisher(topic, timeout=30)
    # The footprint is the robot's outline where the robot is, in the map frame.
    script = tmp_path / "footprint_sample.py"
    script.write_text(FOOTPRINT_SAMPLE)
    sample = ros_master.start_python(script, label="footprint_sample")
    assert sample.wait(timeout=60) == 0, sample.output()
    footprint = json.loads(sample.output().strip().splitlines()[-1])
    assert footprint["frame"] == "map" and len(footprint["points"]) >= 3
    xs, ys = zip(*footprint["points"], strict=True)
    centre = (sum(xs) / len(xs), sum(ys) / len(ys))
    assert centre == pytest.approx(START[:2], abs=0.1)


TOPIC_WATCHER = textwrap.dedent(
    """
    import json, threading, rospy
    from std_msgs.msg import String
    from visualization_msgs.msg import MarkerArray
    rospy.init_node("navseq_topic_watcher", anonymous=True)
    lock = threading.Lock()  # one callback thread per topic: keep their lines whole

    def emit(record):
        with lock:
            print(json.dumps(record), flush=True)

    def on_markers(msg):
        emit({"markers": [[m.ns, m.id, m.header.frame_id, m.color.g] for m in msg.markers]})

    def on_status(msg):
        emit({"status": json.loads(msg.data)})

    rospy.Subscriber("/navseq/waypoints", MarkerArray, on_markers, queue_size=100)
    rospy.Subscriber("/navseq/status", String, on_status, queue_size=100)
    print("watching", flush=True)
    rospy.spin()
    """
)


def test_navseq_run_publishes_waypoint_markers_and_status(ros_master: RosMaster, tmp_path: Path):
    assert MARKERS in rviz_topics()
    start_sim(ros_master)
    script = tmp_path / "topic_watcher.py"
    script.write_text(TOPIC_WATCHER)
    watcher = ros_master.start_python(script, label="topic_watcher")
    watcher.wait_for_output("watching", timeout=30)
    ros_master.wait_for_subscriber(STATUS, timeout=30)
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: west, x: -1.6, y: -0.5, yaw: 90}\n  - {x: -1.6, y: -0.9, yaw: -90}\n",
    )
    navseq = ros_master.start(
        [NAVSEQ, "run", mission, "--navigator", "ros1", "--map", MAP, "--out", tmp_path / "out"],
        cwd=tmp_path,
        label="navseq",
    )
    assert navseq.wait(timeout=120) == 0, navseq.output()[-3000:]

    def lines(key: str) -> list:
        return [
            json.loads(line)[key]
            for line in watcher.output().splitlines()
            if line.startswith(f'{{"{key}"')
        ]

    wait_for(
        lambda: any(s.get("state") == "succeeded" for s in lines("status")), 10, "the final status"
    )
    states = [s["state"] for s in lines("status")]
    assert "running" in states
    assert states[-1] == "succeeded"
    markers = lines("markers")
    assert len(markers) >= 3  # all pending, then one update per waypoint at least
    arrows = [m for m in markers[-1] if m[0] == "navseq_waypoints"]
    assert [m[1] for m in arrows] == [0, 1] and {m[2] for m in arrows} == {"map"}
    assert all(m[3] > 0.7 for m in arrows)  # both green: reached


ODOMETRY = textwrap.dedent(
    """
    import json, time
    from navseq.ros1.navigator import Ros1Navigator
    navigator = Ros1Navigator()
    navigator.require_server(30)
    elsewhere = Ros1Navigator(odom_frame="no_such_frame")
    deadline = time.monotonic() + 30
    while navigator.odometry_pose() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    odom, pose = navigator.odometry_pose(), navigator.robot_pose()
    print(json.dumps({"odom": odom and [odom.x, odom.y, odom.yaw],
                      "map": pose and [pose.x, pose.y, pose.yaw],
                      "elsewhere": elsewhere.odometry_pose() is None}), flush=True)
    """
)


def test_odometry_pose_is_the_robot_in_the_odom_frame(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    script = tmp_path / "odometry.py"
    script.write_text(ODOMETRY)
    client = ros_master.start_python(script, label="odometry")
    assert client.wait(timeout=60) == 0, client.output()
    poses = json.loads(client.output().strip().splitlines()[-1])
    # The odom frame starts where the robot starts; the map pose is the start pose.
    assert poses["odom"] == pytest.approx([0.0, 0.0, 0.0], abs=0.01)
    assert poses["map"] == pytest.approx(list(START), abs=0.01)
    assert poses["elsewhere"] is True
