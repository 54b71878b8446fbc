"""The ROS 2 ``navseq_node`` against the ROS 2 simulator node, over real rclpy.

Every test starts ``python -m navseq.ros2.sim_node`` at 4x speed (it publishes
``/clock``; the node follows it) on a private ROS_DOMAIN_ID and runs the node as
``python -m navseq.ros2.navseq_node --ros-args ...``, as ``ros2 run`` does. Services
and topics are reached by small rclpy scripts run as subprocesses: nothing imports
rclpy in pytest's process.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from cli_support import NAVSEQ, REPO, write_mission
from ros2_support import ros2_environment, ros2_prefix
from test_ros2_navigator import START, OdomWatcher, SimNode

pytestmark = pytest.mark.ros2

TUTORIAL_PARAMS = REPO / "examples" / "tutorial_params_ros2.yaml"

# Calls the Trigger services named in argv in turn (waiting for each), printing one
# JSON line per answer: [name, success, message].
SERVICE_CALLER = r"""
import json, sys
import rclpy
from std_srvs.srv import Trigger
rclpy.init()
node = rclpy.create_node("trigger_caller")
for name in sys.argv[1:]:
    client = node.create_client(Trigger, name)
    assert client.wait_for_service(timeout_sec=30), name
    future = client.call_async(Trigger.Request())
    rclpy.spin_until_future_complete(node, future, timeout_sec=30)
    answer = future.result()
    print(json.dumps([name, answer.success, answer.message]), flush=True)
"""

# Subscribes late, transient local, and prints the markers and status it is given.
LATE_SUBSCRIBER = r"""
import json, time
import rclpy
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray
rclpy.init()
node = rclpy.create_node("late_subscriber")
qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                 durability=DurabilityPolicy.TRANSIENT_LOCAL)
got = {}
node.create_subscription(MarkerArray, "/navseq/waypoints", lambda m: got.setdefault("markers", [
    [k.ns, k.id, k.text, k.pose.position.x, k.pose.position.y,
     [k.color.r, k.color.g, k.color.b]] for k in m.markers]), qos)
node.create_subscription(
    String, "/navseq/status", lambda m: got.setdefault("status", json.loads(m.data)), qos)
deadline = time.monotonic() + 30
while len(got) < 2 and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.1)
print(json.dumps(got), flush=True)
"""


class NavseqNode:
    """A running ``python -m navseq.ros2.navseq_node``; its log is read as it comes."""

    def __init__(self, env: dict[str, str], *ros_args: str) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "navseq.ros2.navseq_node", "--ros-args", *ros_args],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.lines: list[str] = []
        self._changed = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            with self._changed:
                self.lines.append(line.rstrip("\n"))
                self._changed.notify_all()

    def wait_for(self, text: str, timeout: float = 90) -> str:
        """The first log line containing ``text``, waiting for it (not past the node's end)."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while True:
                for line in self.lines:
                    if text in line:
                        return line
                left = deadline - time.monotonic()
                if left <= 0 or self.process.poll() is not None:
                    raise AssertionError(f"no {text!r} in the node's log:\n" + self.log())
                self._changed.wait(min(left, 0.5))

    def finish(self, timeout: float = 120) -> int:
        code = self.process.wait(timeout=timeout)
        time.sleep(0.2)
        return code

    def log(self) -> str:
        return "\n".join(self.lines)

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


@pytest.fixture
def env() -> dict[str, str]:
    prefix = ros2_prefix()
    assert prefix is not None
    return ros2_environment(prefix)


@pytest.fixture
def sim(env: dict[str, str]) -> Any:
    node = SimNode(env, f"--start={START}", "--speed", "4")
    yield node
    assert "Traceback" not in node.stop()


def rclpy_script(env: dict[str, str], script: str, *args: str) -> list[Any]:
    done = subprocess.run(
        [sys.executable, "-c", script, *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    return [json.loads(line) for line in done.stdout.splitlines() if line.strip()]


def far_mission(tmp_path: Path) -> Path:
    return write_mission(
        tmp_path / "far.yaml",
        "  - {name: east, x: 1.75, y: -0.55, yaw: 0}\n"
        "  - {name: north, x: -0.5, y: 1.6, yaw: 90}\n"
        "  - {name: west, x: -1.6, y: -0.5, yaw: 180}\n",
    )


def test_the_tutorial_params_alone_complete_with_one_log_line_per_waypoint_event(
    sim: SimNode, env: dict[str, str]
):
    node = NavseqNode(env, "--params-file", str(TUTORIAL_PARAMS))
    try:
        code = node.finish()
    finally:
        node.kill()
    log = node.log()
    assert code == 0, log
    assert "Traceback" not in log
    assert "4 waypoints from param /navseq p_seq; waiting for /navigate_to_pose" in log
    # The tutorial's params name no robot: the node judges arrival by Nav2's own.
    assert "robot from Nav2's parameters under /: footprint 4 points" in log
    going = [line for line in node.lines if ": going to (" in line]
    reached = [line for line in node.lines if ": reached after " in line]
    assert len(going) == 4 and len(reached) == 4, log
    # The tutorial's degrees reach Nav2 as given: waypoint 2 at 60°.
    assert "waypoint 2/4: going to (0.50, -1.60, 60°)" in going[1]
    assert "mission succeeded (completed)" in log


def test_markers_and_status_are_transient_local_for_a_late_subscriber(
    sim: SimNode, env: dict[str, str]
):
    node = NavseqNode(env, "--params-file", str(TUTORIAL_PARAMS), "-p", "keep_alive:=true")
    try:
        node.wait_for("staying up (keep_alive)")
        # Subscribed only now, long after the last message was published.
        (got,) = rclpy_script(env, LATE_SUBSCRIBER)
        node.process.send_signal(signal.SIGINT)
        code = node.finish(30)
    finally:
        node.kill()
    assert code == 0, node.log()  # kept alive: being stopped is the expected end
    assert got["status"]["state"] == "succeeded"
    assert got["status"]["event"] == "MissionFinished"
    markers = got["markers"]
    arrows = [m for m in markers if m[0] == "navseq_waypoints"]
    labels = [m for m in markers if m[0] == "navseq_labels"]
    assert [m[1] for m in arrows] == [0, 1, 2, 3]
    assert [m[2] for m in labels] == ["1", "2", "3", "4"]
    assert arrows[1][3:5] == pytest.approx([0.5, -1.6])
    green = [0.1, 0.75, 0.2]
    assert all(m[5] == pytest.approx(green) for m in arrows)  # every waypoint reached


def test_pause_resume_skip_and_cancel_services(sim: SimNode, env: dict[str, str], tmp_path: Path):
    node = NavseqNode(env, "-p", f"mission:={far_mission(tmp_path)}")
    try:
        node.wait_for("waypoint 1/3 'east': going to")
        answers = rclpy_script(
            env,
            SERVICE_CALLER,
            "/navseq/pause",
            "/navseq/pause",
            "/navseq/resume",
            "/navseq/resume",
            "/navseq/skip",
        )
        node.wait_for("waypoint 2/3 'north': going to")
        (cancel,) = rclpy_script(env, SERVICE_CALLER, "/navseq/cancel")
        code = node.finish(60)
    finally:
        node.kill()
    log = node.log()
    assert [a[1:] for a in answers] == [
        [True, "paused; the active goal was cancelled"],
        [False, "already paused"],
        [True, "resumed"],
        [False, "not paused"],
        [True, "waypoint 1 skipped; going on with the next one"],
    ]
    assert cancel[1] is True, cancel
    assert code == 1, log  # not every waypoint reached
    assert "waypoint 1/3 'east': paused (paused by the operator (~/pause))" in log
    assert "waypoint 1/3 'east': resumed after" in log
    assert "waypoint 1/3 'east': skipped (skipped by the operator (~/skip))" in log
    assert "mission cancelled by the operator (~/cancel)" in log


def test_sigint_cancels_the_goal_and_the_robot_stops(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    watcher = OdomWatcher(env)
    node = NavseqNode(env, "-p", f"mission:={far_mission(tmp_path)}")
    try:
        node.wait_for("waypoint 1/3 'east': going to")
        time.sleep(2.0)  # well on its way
        signalled = time.monotonic()
        node.process.send_signal(signal.SIGINT)
        code = node.finish(30)
    finally:
        node.kill()
    time.sleep(1.5)
    samples = watcher.samples()
    log = node.log()
    assert code == 130, log
    assert "interrupted (SIGINT); the active goal was cancelled" in log
    assert "Traceback" not in log
    moving = [s for s in samples if s[0] < signalled and s[1] > 0.1]
    assert moving, "the robot never drove"
    after = [s for s in samples if s[0] > signalled + 1.0]
    assert after and all(s[1] < 1e-3 for s in after), after[:5]  # stopped within 1 s


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["-p", "p_seq:=[1.0, 2.0, 0.0, 3.0]", "-p", "yea_seq:=[0.0]"],
            "param /navseq p_seq, field p_seq: has 4 numbers, which is not a multiple of 3",
        ),
        (
            ["-p", "p_seq:=[1.0, 2.0, 0.0]", "-p", "yea_seq:=[0.0, 90.0]"],
            "has 2 yaws but p_seq has 1 point",
        ),
        (["-p", "yea_seq:=[0.0]"], "'yea_seq' is set but 'p_seq' (the flat list"),
        ([], "give the waypoints exactly one way"),
        (["-p", "waypoints:='[{x: 1'"], "param /navseq waypoints: is not valid YAML"),
        (
            ["-p", "p_seq:=[1.0, 2.0, 0.0]", "-p", "yea_seq:=[0.0]", "-p", "tick:=-1.0"],
            "param /navseq tick: expected a number of seconds > 0",
        ),
        (
            ["-p", "p_seq:=[1.0, 2.0, 0.0]", "-p", "yea_seq:=[0.0]", "-p", "server_wait:=1.0"],
            "no action server '/navigate_to_pose'",
        ),
    ],
)
def test_bad_params_are_one_clear_error_and_exit_2(
    env: dict[str, str], args: list[str], message: str
):
    node = NavseqNode(env, *args)
    try:
        code = node.finish(60)
    finally:
        node.kill()
    log = node.log()
    assert code == 2, log
    assert message in log
    assert "Traceback" not in log
    errors = [line for line in node.lines if "[ERROR]" in line]
    assert len(errors) == 1, log


@pytest.mark.ros
def test_the_same_mission_gives_the_same_visits_on_sim_ros1_and_nav2(
    ros_master: Any, env: dict[str, str], tmp_path: Path
):
    from ros_clients import start_sim

    # Pre-flight off: the pillar is found by each stack's planner.
    mission = write_mission(
        tmp_path / "same.yaml",
        "  - {name: west, x: -1.6, y: -0.5, yaw: 90}\n"
        "  - {name: pillar, x: -1.1, y: 0.0, yaw: 0, on_failure: skip}\n"
        "  - {name: south, x: -0.55, y: -1.75, yaw: 0}\n",
        "defaults: {retries: 0, goal_timeout: 120}\n",
    )

    def run(navigator: str, run_env: dict[str, str] | None) -> list[tuple[str, str, int]]:
        out = tmp_path / navigator
        # The in-process simulator needs the map as its world. Pre-flight, which would
        # refuse the pillar before the robot moves (on the stacks' own map for ros1 and
        # nav2), is off so that each planner meets it.
        world = ["--map", str(REPO / "maps" / "turtlebot3_world.yaml"), "--start=-2,-0.5,0"]
        extra = [*world, "--no-preflight"] if navigator == "sim" else ["--no-preflight"]
        done = subprocess.run(
            [NAVSEQ, "run", str(mission), "--navigator", navigator, "--out", str(out), *extra],
            env=run_env,
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 1, done.stderr  # the pillar is not reached
        report = json.loads((out / "report.json").read_text())
        return [(v["name"], v["outcome"], len(v["attempts"])) for v in report["visits"]]

    on_sim = run("sim", None)
    start_sim(ros_master)
    on_ros1 = run("ros1", ros_master.env)
    nav2_sim = SimNode(env, f"--start={START}", "--speed", "4")
    try:
        on_nav2 = run("nav2", env)
    finally:
        nav2_sim.stop()
    expected = [("west", "reached", 1), ("pillar", "skipped", 1), ("south", "reached", 1)]
    assert on_sim == expected
    assert on_ros1 == expected
    assert on_nav2 == expected


def test_confirm_service_confirms_the_input_task_waiting(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: east, x: 1.75, y: -0.55, yaw: 0, tasks: [{input: {prompt: Load the tray}}]}\n",
    )
    node = NavseqNode(env, "-p", f"mission:={mission}")
    try:
        node.wait_for("Load the tray — call /navseq/confirm to go on")
        (answer,) = rclpy_script(env, SERVICE_CALLER, "/navseq/confirm")
        code = node.finish(60)
    finally:
        node.kill()
    assert answer[1:] == [True, "input confirmed; going on"]
    assert code == 0, node.log()
