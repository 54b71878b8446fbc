"""ROS clients and servers shared by several test modules, with the helpers that run them.

- the scripted move_base server (``ros_scripted_server.py``): start it, read its log;
- the simulator's ROS nodes on the TurtleBot3 world, and a plain rospy/actionlib client
  of them (``SIM_CLIENT``) fed a JSON list of steps, printing one JSON line per step;
- the classic ``move_base_seq`` tutorial node that sends goals from ``done_cb``.

Every client is a script written to a file and run as a subprocess of a
:class:`ros_support.RosMaster` (rospy allows one ``init_node`` per process).
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

from ros_support import REPO_ROOT, TESTS_DIR, RosMaster, RosProcess

SCRIPTED_SERVER = TESTS_DIR / "ros_scripted_server.py"

MAP = REPO_ROOT / "maps" / "turtlebot3_world.yaml"
EXAMPLE_MISSION = REPO_ROOT / "examples" / "turtlebot3_world.yaml"
SPEED = 8.0  # sim seconds per wall second: keeps each drive to a few seconds
START = (-2.0, -0.5, 0.0)

# actionlib_msgs/GoalStatus values, as the clients print them.
SUCCEEDED, PREEMPTED, ABORTED = 3, 2, 4


# -- the scripted move_base server ------------------------------------------------------------


def start_scripted_server(master: RosMaster, *args: str) -> RosProcess:
    """``ros_scripted_server.py *args``, once it has said it is ready."""
    server = master.start_python(SCRIPTED_SERVER, *args)
    server.wait_for_output("scripted move_base ready", timeout=20)
    return server


def server_log(path: Path) -> list[dict[str, Any]]:
    """The scripted server's ``--log`` records so far (none before it wrote any)."""
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


# -- the simulator's nodes and a plain move_base client -----------------------------------------

SIM_CLIENT = textwrap.dedent(
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


def start_sim(
    master: RosMaster,
    start: tuple[float, float, float] = START,
    speed: float = SPEED,
    nav_params: tuple[str, ...] = (),
    *,
    set_sim_time: bool = True,
) -> tuple[RosProcess, RosProcess]:
    """Robot node + navigation node on the TurtleBot3 world, ROS time driven by the robot.

    ``nav_params`` are extra ``_name:=value`` arguments of the navigation node.
    """
    if set_sim_time:
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
    nav = master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={MAP}", *nav_params], label="move_base"
    )
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
    script.write_text(SIM_CLIENT)
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


# -- observers of a running stack -----------------------------------------------------------

# Prints one JSON line per move_base result: its status, the goal it ended, and where the
# robot really is then (TF map -> base_footprint): the truth a SUCCEEDED should match.
RESULT_WATCHER = textwrap.dedent(
    """
    import json, math
    import rospy, tf2_ros
    from move_base_msgs.msg import MoveBaseActionGoal, MoveBaseActionResult

    rospy.init_node("result_watcher", anonymous=True)
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    goals = {}

    def on_goal(msg):
        p = msg.goal.target_pose.pose.position
        goals[msg.goal_id.id] = [p.x, p.y]

    def on_result(msg):
        t = buffer.lookup_transform("map", "base_footprint", rospy.Time(0), rospy.Duration(2))
        robot = [t.transform.translation.x, t.transform.translation.y]
        goal = goals.get(msg.status.goal_id.id)
        away = math.dist(goal, robot) if goal else None
        print(json.dumps({"status": msg.status.status, "goal": goal, "robot": robot,
                          "distance": away}), flush=True)

    rospy.Subscriber("move_base/goal", MoveBaseActionGoal, on_goal, queue_size=100)
    rospy.Subscriber("move_base/result", MoveBaseActionResult, on_result, queue_size=100)
    print("watching", flush=True)
    rospy.spin()
    """
)


def start_result_watcher(master: RosMaster, tmp_path: Path) -> RosProcess:
    script = tmp_path / "result_watcher.py"
    script.write_text(RESULT_WATCHER)
    watcher = master.start_python(script, label="result_watcher")
    watcher.wait_for_output("watching", timeout=30)
    master.wait_for_subscriber("/move_base/result", timeout=30)
    return watcher


# -- the tutorial's move_base_seq node --------------------------------------------------------

# The tutorial's node, trimmed of its logging, with its structure and callback logic kept.
TUTORIAL_DONE_CB_CLIENT = textwrap.dedent(
    """
    import math
    import actionlib
    import rospy
    from geometry_msgs.msg import Point, Pose, Quaternion
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal


    def quaternion_from_euler(roll, pitch, yaw, axes="sxyz"):
        # Debian has no python3-tf; the tutorial only ever rotates about z.
        return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


    class MoveBaseSeq:
        def __init__(self):
            rospy.init_node("move_base_seq")
            points_seq = rospy.get_param("move_base_seq/p_seq")
            yaweulerangles_seq = rospy.get_param("move_base_seq/yea_seq")
            quat_seq = [
                Quaternion(*quaternion_from_euler(0, 0, yaw * math.pi / 180, axes="sxyz"))
                for yaw in yaweulerangles_seq
            ]
            self.pose_seq = []
            self.goal_cnt = 0
            points = [points_seq[i:i + 3] for i in range(0, len(points_seq), 3)]
            for n, point in enumerate(points):
                self.pose_seq.append(Pose(Point(*point), quat_seq[n]))
            self.client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
            # The tutorial waits 5 s; here ROS time runs 8x, so allow 10 s of wall time
            # for the connection on a loaded machine.
            if not self.client.wait_for_server(rospy.Duration(80.0)):
                rospy.signal_shutdown("Action server not available!")
                return
            self.movebase_client()

        def active_cb(self):
            pass

        def feedback_cb(self, feedback):
            pass

        def done_cb(self, status, result):
            self.goal_cnt += 1
            print("DONE %d status %d" % (self.goal_cnt, status), flush=True)
            if status == 3:
                if self.goal_cnt < len(self.pose_seq):
                    next_goal = MoveBaseGoal()
                    next_goal.target_pose.header.frame_id = "map"
                    next_goal.target_pose.header.stamp = rospy.Time.now()
                    next_goal.target_pose.pose = self.pose_seq[self.goal_cnt]
                    self.client.send_goal(next_goal, self.done_cb, self.active_cb,
                                          self.feedback_cb)
                else:
                    print("FINAL GOAL REACHED", flush=True)
                    rospy.signal_shutdown("Final goal pose reached!")
            else:
                rospy.signal_shutdown("goal failed")

        def movebase_client(self):
            goal = MoveBaseGoal()
            goal.target_pose.header.frame_id = "map"
            goal.target_pose.header.stamp = rospy.Time.now()
            goal.target_pose.pose = self.pose_seq[self.goal_cnt]
            self.client.send_goal(goal, self.done_cb, self.active_cb, self.feedback_cb)
            rospy.spin()


    if __name__ == "__main__":
        MoveBaseSeq()
    """
)
