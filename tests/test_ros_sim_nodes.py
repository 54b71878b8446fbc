"""The simulator's ROS nodes serve ordinary move_base clients, against a real rosmaster.

Each test starts its own rosmaster, the sim robot node and the move_base stand-in
(``nodes/sim_robot_node``, ``nodes/sim_nav_node``) on the TurtleBot3 world at several
times real time, and drives them with plain rospy/actionlib clients run as
subprocesses (the client below is written to a file and fed a JSON list of steps; it
prints one JSON line per step).
"""

from __future__ import annotations

import itertools
import json
import math
import textwrap
import time
from pathlib import Path
from typing import Any

import pytest

from ros_support import REPO_ROOT, RosMaster, RosProcess

pytestmark = pytest.mark.ros

MAP = REPO_ROOT / "maps" / "turtlebot3_world.yaml"
EXAMPLE_MISSION = REPO_ROOT / "examples" / "turtlebot3_world.yaml"
SPEED = 8.0  # sim seconds per wall second: keeps each drive to a few seconds
START = (-2.0, -0.5, 0.0)
PILLAR = (0.0, 0.0)  # the centre pillar of the arena: no robot fits there

SUCCEEDED, PREEMPTED, ABORTED = 3, 2, 4

CLIENT = textwrap.dedent(
    """
    import json, math, sys
    import actionlib, rospy, tf2_ros
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
    from move_base_msgs.msg import MoveBaseAction, MoveBaseActionResult, MoveBaseGoal
    from nav_msgs.msg import Odometry
    from nav_msgs.srv import GetPlan, GetPlanRequest
    from std_srvs.srv import Empty

    steps = json.loads(sys.argv[1])
    base_frame = sys.argv[2]
    rospy.init_node("sim_client", anonymous=True)
    tf_buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(tf_buffer)
    client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
    if not client.wait_for_server(rospy.Duration(30)):
        sys.exit("no move_base action server")
    odom = {"v": 0.0, "w": 0.0}

    def on_odom(msg):
        odom["v"], odom["w"] = msg.twist.twist.linear.x, msg.twist.twist.angular.z

    rospy.Subscriber("odom", Odometry, on_odom)
    results = []
    rospy.Subscriber("move_base/result", MoveBaseActionResult,
                     lambda msg: results.append(msg.status.status))
    initialpose_pub = rospy.Publisher("initialpose", PoseWithCovarianceStamped, queue_size=1)
    simple_goal_pub = rospy.Publisher("move_base_simple/goal", PoseStamped, queue_size=1)

    def report(**fields):
        print(json.dumps(fields), flush=True)

    def stamped(x, y, yaw, frame="map"):
        msg = PoseStamped()
        msg.header.frame_id = frame
        msg.header.stamp = rospy.Time.now()
        msg.pose.position.x, msg.pose.position.y = x, y
        msg.pose.orientation.z, msg.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        return msg

    def robot_pose():
        t = tf_buffer.lookup_transform("map", base_frame, rospy.Time(0), rospy.Duration(5))
        q = t.transform.rotation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        return [t.transform.translation.x, t.transform.translation.y, yaw]

    def wait_connections(pub):
        deadline = rospy.Time.now() + rospy.Duration(10)
        while pub.get_num_connections() == 0 and rospy.Time.now() < deadline:
            rospy.sleep(0.05)

    def finish(op):
        done = client.wait_for_result(rospy.Duration(step.get("timeout", 120)))
        report(op=op, finished=done, state=client.get_state(),
               text=client.get_goal_status_text(), pose=robot_pose())

    for step in steps:
        op = step["op"]
        if op == "goal":
            client.send_goal(MoveBaseGoal(target_pose=stamped(step["x"], step["y"], step["yaw"])))
            finish(op)
        elif op == "send":
            client.send_goal(MoveBaseGoal(target_pose=stamped(step["x"], step["y"], step["yaw"])))
            report(op=op)
        elif op == "wait_result":
            finish(op)
        elif op == "wait_moving":
            deadline = rospy.Time.now() + rospy.Duration(30)
            while abs(odom["v"]) < 0.05 and rospy.Time.now() < deadline:
                rospy.sleep(0.05)
            report(op=op, v=odom["v"], pose=robot_pose())
        elif op == "cancel":
            client.cancel_goal()
            finish(op)
        elif op == "settle":
            rospy.sleep(step.get("seconds", 0.5))
            before = robot_pose()
            rospy.sleep(1.0)
            after = robot_pose()
            report(op=op, moved=math.hypot(after[0] - before[0], after[1] - before[1]),
                   turned=abs(after[2] - before[2]), v=odom["v"], w=odom["w"])
        elif op == "initialpose":
            msg = PoseWithCovarianceStamped()
            msg.header = stamped(step["x"], step["y"], step["yaw"]).header
            msg.pose.pose = stamped(step["x"], step["y"], step["yaw"]).pose
            wait_connections(initialpose_pub)
            initialpose_pub.publish(msg)
            rospy.sleep(1.0)
            report(op=op, pose=robot_pose())
        elif op == "odom_pose":
            odom_msg = rospy.wait_for_message("odom", Odometry, timeout=10)
            p, q = odom_msg.pose.pose.position, odom_msg.pose.pose.orientation
            report(op=op, frame=odom_msg.header.frame_id, child=odom_msg.child_frame_id,
                   pose=[p.x, p.y, math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z)])
        elif op == "make_plan":
            rospy.wait_for_service("move_base/make_plan", timeout=10)
            request = GetPlanRequest(goal=stamped(*step["goal"]))
            if "start" in step:
                request.start = stamped(*step["start"])
            plan = rospy.ServiceProxy("move_base/make_plan", GetPlan)(request).plan
            points = [[p.pose.position.x, p.pose.position.y] for p in plan.poses]
            report(op=op, frame=plan.header.frame_id, points=points)
        elif op == "clear_costmaps":
            rospy.wait_for_service("move_base/clear_costmaps", timeout=10)
            rospy.ServiceProxy("move_base/clear_costmaps", Empty)()
            report(op=op)
        elif op == "watch_results":
            report(op="watching")
            deadline = rospy.Time.now() + rospy.Duration(step.get("timeout", 300))
            while len(results) < step["count"] and rospy.Time.now() < deadline:
                rospy.sleep(0.05)
            report(op=op, results=list(results))
        elif op == "simple_goal":
            wait_connections(simple_goal_pub)
            del results[:]
            simple_goal_pub.publish(stamped(step["x"], step["y"], step["yaw"]))
            deadline = rospy.Time.now() + rospy.Duration(step.get("timeout", 120))
            while not results and rospy.Time.now() < deadline:
                rospy.sleep(0.05)
            report(op=op, results=list(results), pose=robot_pose())
    """
)


# -- helpers ---------------------------------------------------------------------------------


def start_sim(
    master: RosMaster, start: tuple[float, float, float] = START, speed: float = SPEED
) -> tuple[RosProcess, RosProcess]:
    """Robot node + navigation node on the TurtleBot3 world, ROS time driven by the robot."""
    master.set_param("/use_sim_time", True)
    x, y, yaw = start
    robot = master.start(
        [
            REPO_ROOT / "nodes" / "sim_robot_node",
            f"_map:={MAP}",
            f"_x:={x}",
            f"_y:={y}",
            f"_yaw:={yaw}",
            f"_speed:={speed}",
        ],
        label="sim_robot",
    )
    nav = master.start([REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={MAP}"], label="move_base")
    master.wait_for_action_server("/move_base", timeout=30)
    return robot, nav


def start_client(
    master: RosMaster,
    tmp_path: Path,
    steps: list[dict[str, Any]],
    *,
    namespace: str = "",
    label: str = "sim_client",
) -> RosProcess:
    tmp_path.mkdir(parents=True, exist_ok=True)
    script = tmp_path / "sim_client.py"
    script.write_text(CLIENT)
    base_frame = f"{namespace}/base_footprint" if namespace else "base_footprint"
    env = {"ROS_NAMESPACE": namespace} if namespace else None
    return master.start_python(script, json.dumps(steps), base_frame, env=env, label=label)


def reports(process: RosProcess) -> list[dict[str, Any]]:
    return [json.loads(line) for line in process.output().splitlines() if line.startswith("{")]


def run_client(
    master: RosMaster, tmp_path: Path, steps: list[dict[str, Any]], timeout: float = 120
) -> list[dict[str, Any]]:
    client = start_client(master, tmp_path, steps)
    assert client.wait(timeout=timeout) == 0, client.output()[-4000:]
    lines = reports(client)
    assert len(lines) == len(steps), client.output()[-4000:]
    return lines


def goal(x: float, y: float, yaw: float = 0.0, op: str = "goal") -> dict[str, Any]:
    return {"op": op, "x": x, "y": y, "yaw": yaw}


def yaw_error(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def example_mission_goals() -> tuple[tuple[float, float, float], list[tuple[float, float, float]]]:
    """Start pose and (x, y, yaw radians) of every waypoint of the example mission."""
    if not EXAMPLE_MISSION.exists():
        pytest.skip(f"{EXAMPLE_MISSION.relative_to(REPO_ROOT)} not written yet")
    from navseq.mission import load_mission

    mission = load_mission(EXAMPLE_MISSION)
    start = mission.start if getattr(mission, "start", None) is not None else None
    start_pose = (start.x, start.y, start.yaw) if start is not None else START
    return start_pose, [(w.x, w.y, w.yaw) for w in mission.waypoints]


# -- move_base clients ------------------------------------------------------------------------


def test_plain_sequence_client_reaches_every_waypoint_of_the_example_mission(
    ros_master: RosMaster, tmp_path: Path
):
    start, waypoints = example_mission_goals()
    start_sim(ros_master, start)
    results = run_client(ros_master, tmp_path, [goal(*w) for w in waypoints], timeout=240)
    for (x, y, yaw), result in zip(waypoints, results, strict=True):
        assert result["state"] == SUCCEEDED, result
        px, py, pyaw = result["pose"]
        assert math.hypot(px - x, py - y) < 0.1, result
        assert yaw_error(pyaw, yaw) < 0.25, result


def test_tutorial_done_cb_client_gets_its_first_goal_then_stalls(
    ros_master: RosMaster, tmp_path: Path
):
    from test_tutorial_donecb import TUTORIAL_DONE_CB_CLIENT

    start_sim(ros_master)
    points = [(-1.5, -0.5, 0.0), (-0.5, -1.6, 0.0), (0.5, -1.6, 90.0)]
    ros_master.set_param("/move_base_seq/p_seq", [v for x, y, _ in points for v in (x, y, 0.0)])
    ros_master.set_param("/move_base_seq/yea_seq", [yaw for _, _, yaw in points])
    # A bystander that prints every result the sim publishes.
    monitor = start_client(
        ros_master, tmp_path, [{"op": "watch_results", "count": 2}], label="monitor"
    )
    monitor.wait_for_output('"op": "watching"', timeout=30)
    script = tmp_path / "move_base_seq.py"
    script.write_text(TUTORIAL_DONE_CB_CLIENT)
    tutorial = ros_master.start_python(script)
    tutorial.wait_for_output("DONE 1 status 3", timeout=60)
    # Goal 2, sent from inside done_cb, reaches the sim and succeeds there ...
    assert monitor.wait(timeout=60) == 0, monitor.output()
    assert reports(monitor)[-1] == {"op": "watch_results", "results": [SUCCEEDED] * 2}
    # ... but the tutorial never hears of it: a bounded wait of several goal durations.
    time.sleep(3.0)
    assert tutorial.running(), tutorial.output()
    assert "DONE 2" not in tutorial.output(), tutorial.output()


def test_goal_in_a_wall_is_aborted_and_the_robot_stays(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    aborted, reachable = run_client(ros_master, tmp_path, [goal(*PILLAR), goal(-1.5, -0.5)])
    assert aborted["state"] == ABORTED, aborted
    assert aborted["text"], "an aborted goal says why"
    assert math.hypot(aborted["pose"][0] - START[0], aborted["pose"][1] - START[1]) < 0.01
    # The server is not stuck on the failure: the next goal is served.
    assert reachable["state"] == SUCCEEDED, reachable


def test_a_goal_from_another_client_preempts_the_active_one(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    first = start_client(
        ros_master,
        tmp_path,
        [goal(1.6, 0.5, op="send"), {"op": "wait_moving"}, {"op": "wait_result"}],
        label="first",
    )
    first.wait_for_output('"op": "wait_moving"', timeout=60)
    second = run_client(ros_master, tmp_path, [goal(-1.5, -1.0)])
    assert first.wait(timeout=60) == 0, first.output()
    preempted = reports(first)[-1]
    assert preempted["state"] == PREEMPTED, preempted
    assert second[0]["state"] == SUCCEEDED, second


def test_cancel_ends_the_goal_preempted_and_the_robot_stops(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    _, moving, canceled, settled = run_client(
        ros_master,
        tmp_path,
        [goal(1.6, 0.5, op="send"), {"op": "wait_moving"}, {"op": "cancel"}, {"op": "settle"}],
    )
    assert moving["v"] > 0.05, moving
    assert canceled["state"] == PREEMPTED, canceled
    assert settled["moved"] < 0.005 and settled["turned"] < 0.01, settled
    assert settled["v"] == 0.0 and settled["w"] == 0.0, settled


def test_initialpose_teleports_the_robot_and_odometry_stays_continuous(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master)
    odom_before, teleported, odom_after, refused, driven = run_client(
        ros_master,
        tmp_path,
        [
            {"op": "odom_pose"},
            {"op": "initialpose", "x": 1.6, "y": 0.5, "yaw": math.pi / 2},
            {"op": "odom_pose"},
            {"op": "initialpose", "x": PILLAR[0], "y": PILLAR[1], "yaw": 0.0},
            goal(1.6, 1.6, math.pi / 2),
        ],
    )
    assert (odom_before["frame"], odom_before["child"]) == ("odom", "base_footprint")
    assert odom_before["pose"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    assert teleported["pose"] == pytest.approx([1.6, 0.5, math.pi / 2], abs=1e-3)
    # Like a localisation jump: map -> odom moves, odometry itself does not jump.
    assert odom_after["pose"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    # A pose inside a pillar is refused; the robot stays where it was put.
    assert refused["pose"] == pytest.approx([1.6, 0.5, math.pi / 2], abs=1e-3)
    # Navigation plans from the new place.
    assert driven["state"] == SUCCEEDED, driven


def test_make_plan_and_clear_costmaps_services(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    from_robot, given_start, into_wall, cleared = run_client(
        ros_master,
        tmp_path,
        [
            {"op": "make_plan", "goal": [1.6, 0.5, 0.0]},
            {"op": "make_plan", "start": [-0.5, -1.6, 0.0], "goal": [-0.5, 1.6, 0.0]},
            {"op": "make_plan", "goal": [*PILLAR, 0.0]},
            {"op": "clear_costmaps"},
        ],
    )
    assert from_robot["frame"] == "map"
    points = from_robot["points"]
    assert points[0] == pytest.approx(list(START[:2]), abs=0.05)
    assert points[-1] == pytest.approx([1.6, 0.5], abs=0.05)
    # A path around the pillars is longer than the straight line through them.
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    assert length > math.dist(START[:2], (1.6, 0.5)) + 0.1
    assert given_start["points"][0] == pytest.approx([-0.5, -1.6], abs=0.05)
    assert given_start["points"][-1] == pytest.approx([-0.5, 1.6], abs=0.05)
    assert into_wall["points"] == []
    assert cleared == {"op": "clear_costmaps"}


def test_rviz_2d_nav_goal_on_move_base_simple_drives_the_robot(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master)
    (result,) = run_client(ros_master, tmp_path, [goal(-1.5, -1.0, -math.pi / 2, "simple_goal")])
    assert result["results"] == [SUCCEEDED], result
    assert result["pose"][:2] == pytest.approx([-1.5, -1.0], abs=0.1)


def test_a_goal_without_a_robot_is_aborted_not_hung(ros_master: RosMaster, tmp_path: Path):
    # Only the navigation node, in wall time: no TF ever arrives.
    nav = ros_master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={MAP}", "_pose_timeout:=1.0"],
        label="move_base",
    )
    ros_master.wait_for_action_server("/move_base", timeout=30)
    script = tmp_path / "lonely_client.py"
    script.write_text(
        textwrap.dedent(
            """
            import actionlib, rospy
            from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
            rospy.init_node("lonely_client")
            client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
            assert client.wait_for_server(rospy.Duration(30))
            goal = MoveBaseGoal()
            goal.target_pose.header.frame_id = "map"
            goal.target_pose.pose.position.x = -1.5
            goal.target_pose.pose.orientation.w = 1.0
            client.send_goal(goal)
            assert client.wait_for_result(rospy.Duration(20))
            print("STATE", client.get_state(), client.get_goal_status_text(), flush=True)
            """
        )
    )
    client = ros_master.start_python(script)
    assert client.wait(timeout=40) == 0, client.output() + nav.output()
    assert f"STATE {ABORTED}" in client.output()
    assert "base_footprint" in client.output()
