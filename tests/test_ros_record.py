"""Recording waypoints from RViz-style pose topics and from TF, against a real rosmaster."""

from __future__ import annotations

import math
import signal
import textwrap
from pathlib import Path

import pytest

from navseq.mission import load_mission
from ros_support import RosMaster, RosProcess, wait_for

pytestmark = pytest.mark.ros

# Publishes the poses given on the command line as "x,y,yaw_deg" on a topic, one every
# 0.3 s, once the recorder listens; for */initialpose as PoseWithCovarianceStamped.
# With --tf it also broadcasts a static map -> base_footprint transform at the first pose.
POSE_PUBLISHER = textwrap.dedent(
    """
    import math, sys, time
    import rospy
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TransformStamped

    topic, frame, *poses = sys.argv[1:]
    rospy.init_node("pose_publisher", anonymous=True)
    if "--tf" in poses:
        import tf2_ros
        poses.remove("--tf")
        x, y, yaw = (float(v) for v in poses[0].split(","))
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = "map", "base_footprint"
        t.header.stamp = rospy.Time.now()
        t.transform.translation.x, t.transform.translation.y = x, y
        t.transform.rotation.z = math.sin(math.radians(yaw) / 2)
        t.transform.rotation.w = math.cos(math.radians(yaw) / 2)
        broadcaster = tf2_ros.StaticTransformBroadcaster()
        broadcaster.sendTransform(t)
        print("tf sent", flush=True)
        rospy.spin()
        sys.exit(0)
    covariance = topic.rstrip("/").endswith("initialpose")
    kind = PoseWithCovarianceStamped if covariance else PoseStamped
    pub = rospy.Publisher(topic, kind, queue_size=10)
    while pub.get_num_connections() == 0:
        time.sleep(0.05)
    for text in poses:
        x, y, yaw = (float(v) for v in text.split(","))
        msg = kind()
        msg.header.frame_id = frame
        msg.header.stamp = rospy.Time.now()
        pose = msg.pose.pose if covariance else msg.pose
        pose.position.x, pose.position.y = x, y
        pose.orientation.z = math.sin(math.radians(yaw) / 2)
        pose.orientation.w = math.cos(math.radians(yaw) / 2)
        pub.publish(msg)
        time.sleep(0.3)
    print("published", flush=True)
    """
)


def start_recorder(master: RosMaster, out: Path, **params) -> RosProcess:
    for key, value in {"out": str(out), **params}.items():
        master.set_param(f"/navseq_record/{key}", value)
    recorder = master.start_python("-m", "navseq.ros1.record", label="recorder")
    return recorder


def publish(master: RosMaster, tmp_path: Path, topic: str, *poses: str, frame="map"):
    script = tmp_path / "pose_publisher.py"
    script.write_text(POSE_PUBLISHER)
    return master.start_python(script, topic, frame, *poses)


def waypoint_count(path: Path) -> int:
    return len(load_mission(path).waypoints) if path.exists() else 0


def test_every_goal_pose_becomes_a_waypoint_and_survives_ctrl_c(
    ros_master: RosMaster, tmp_path: Path
):
    out = tmp_path / "recorded.yaml"
    recorder = start_recorder(ros_master, out)
    recorder.wait_for_output("navseq record: ready", timeout=20)
    publisher = publish(ros_master, tmp_path, "/move_base_simple/goal", "1,2,90")
    assert publisher.wait(timeout=20) == 0, publisher.output()
    wait_for(lambda: waypoint_count(out) == 1, 10, "the first waypoint in the file")
    publisher = publish(ros_master, tmp_path, "/move_base_simple/goal", "-0.5,1.5,180", "2,0,0")
    assert publisher.wait(timeout=20) == 0, publisher.output()
    wait_for(lambda: waypoint_count(out) == 3, 10, "three waypoints in the file")
    recorder.send_signal(signal.SIGINT)
    assert recorder.wait(timeout=20) == 0, recorder.output()
    mission = load_mission(out)
    assert mission.frame == "map"
    assert [(w.x, w.y) for w in mission.waypoints] == [(1, 2), (-0.5, 1.5), (2, 0)]
    assert [math.degrees(w.yaw_rad) for w in mission.waypoints] == pytest.approx([90, 180, 0])
    assert "3 waypoints saved" in recorder.output()


def test_kill_9_keeps_every_waypoint_recorded_so_far(ros_master: RosMaster, tmp_path: Path):
    out = tmp_path / "recorded.yaml"
    recorder = start_recorder(ros_master, out)
    recorder.wait_for_output("navseq record: ready", timeout=20)
    publish(ros_master, tmp_path, "/move_base_simple/goal", "1,0,0", "2,0,0").wait(timeout=20)
    wait_for(lambda: waypoint_count(out) == 2, 10, "two waypoints in the file")
    recorder.send_signal(signal.SIGKILL)
    recorder.wait(timeout=10)
    assert [w.x for w in load_mission(out).waypoints] == [1, 2]
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")] == []


def test_initialpose_topic_with_covariance(ros_master: RosMaster, tmp_path: Path):
    out = tmp_path / "recorded.yaml"
    recorder = start_recorder(ros_master, out, topic="/initialpose")
    recorder.wait_for_output("navseq record: ready", timeout=20)
    publish(ros_master, tmp_path, "/initialpose", "-2,-0.5,45").wait(timeout=20)
    wait_for(lambda: waypoint_count(out) == 1, 10, "the waypoint in the file")
    waypoint = load_mission(out).waypoints[0]
    assert (waypoint.x, waypoint.y) == (-2, -0.5)
    assert math.degrees(waypoint.yaw_rad) == pytest.approx(45)


def test_existing_file_is_never_replaced_unless_asked(ros_master: RosMaster, tmp_path: Path):
    out = tmp_path / "mine.yaml"
    out.write_text("user's precious notes\n")
    recorder = start_recorder(ros_master, out)
    assert recorder.wait(timeout=20) == 2
    assert "exists already" in recorder.output() and "Traceback" not in recorder.output()
    assert out.read_text() == "user's precious notes\n"

    recorder = start_recorder(ros_master, out, overwrite=True)
    recorder.wait_for_output("navseq record: ready", timeout=20)
    publish(ros_master, tmp_path, "/move_base_simple/goal", "1,1,0").wait(timeout=20)
    wait_for(
        lambda: "user's" not in out.read_text() and waypoint_count(out) == 1,
        10,
        "the file replaced by the recording",
    )


def test_record_service_takes_the_robot_pose_from_tf(ros_master: RosMaster, tmp_path: Path):
    out = tmp_path / "recorded.yaml"
    recorder = start_recorder(ros_master, out, from_tf=True)
    recorder.wait_for_output("navseq record: ready", timeout=20)
    tf = publish(ros_master, tmp_path, "unused", "0.75,-1.25,30", "--tf")
    tf.wait_for_output("tf sent", timeout=20)
    response = ros_master.call_service("/navseq_record/record")
    assert response["success"], response
    waypoint = load_mission(out).waypoints[0]
    assert (waypoint.x, waypoint.y) == pytest.approx((0.75, -1.25))
    assert math.degrees(waypoint.yaw_rad) == pytest.approx(30)


def test_tf_poses_are_recorded_to_the_millimetre_and_the_tenth_of_a_degree(
    ros_master: RosMaster, tmp_path: Path
):
    out = tmp_path / "recorded.yaml"
    recorder = start_recorder(ros_master, out, from_tf=True)
    recorder.wait_for_output("navseq record: ready", timeout=20)
    tf = publish(ros_master, tmp_path, "unused", "-1.8739253890256067,0.4995812,33.333333", "--tf")
    tf.wait_for_output("tf sent", timeout=20)
    assert ros_master.call_service("/navseq_record/record")["success"]
    text = out.read_text()
    assert "x: -1.874," in text and "y: 0.5," in text and "yaw: 33.3" in text, text
    assert "-1.8739" not in text and "33.333" not in text
    waypoint = load_mission(out).waypoints[0]
    assert (waypoint.x, waypoint.y) == (-1.874, 0.5)
    assert math.degrees(waypoint.yaw_rad) == pytest.approx(33.3, abs=1e-9)
