"""``navseq run --navigator nav2`` against the ROS 2 simulator node, over real rclpy.

Every test starts ``python -m navseq.ros2.sim_node`` (Nav2's interfaces around the
simulator) on a private ROS_DOMAIN_ID at 4x speed, so it publishes ``/clock`` and
navseq runs on simulation time, and runs ``navseq run ... --navigator nav2`` as a
subprocess, as a user would from a shell where ROS 2 is sourced. Nothing imports rclpy
in pytest's process. Robots are watched through ``odom`` by a small rclpy script
(:data:`ODOM_WATCHER`) run as a subprocess too.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import ros2_support
from cli_support import (
    NAVSEQ,
    REPO,
    driven_towards,
    journal_events,
    printed_events,
    wait_for,
    write_mission,
)
from ros2_support import ros2_environment, ros2_prefix

pytestmark = pytest.mark.ros2

MAP = REPO / "maps" / "turtlebot3_world.yaml"
EXAMPLE = REPO / "examples" / "turtlebot3_world.yaml"
CLIENTS = Path(__file__).with_name("ros2_clients.py")
START = "-2,-0.5,0"
SPEED = "4"
CRUISE = 0.22  # m/s: the TurtleBot3 burger the simulator drives by default
# A killed process leaves the DDS graph after its lease: 10 s by default in Cyclone DDS.
SHORT_LEASE = (
    "<CycloneDDS><Domain><Discovery><LeaseDuration>1s</LeaseDuration>"
    "</Discovery></Domain></CycloneDDS>"
)

# Prints one JSON line when stopped (SIGINT/SIGTERM): every odom sample as
# [monotonic time, |linear speed|, x, y]. CLOCK_MONOTONIC is system-wide, so the
# times compare with the test's own time.monotonic().
ODOM_WATCHER = r"""
import json, signal, sys, time
import rclpy
from nav_msgs.msg import Odometry
from rclpy.qos import qos_profile_sensor_data
rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
node = rclpy.create_node("odom_watcher")
samples = []
stop = []
def on_odom(m):
    p = m.pose.pose.position
    samples.append([time.monotonic(), abs(m.twist.twist.linear.x), p.x, p.y])
node.create_subscription(Odometry, sys.argv[1], on_odom, qos_profile_sensor_data)
signal.signal(signal.SIGINT, lambda *a: stop.append(1))
signal.signal(signal.SIGTERM, lambda *a: stop.append(1))
print("watching", flush=True)
while not stop:
    rclpy.spin_once(node, timeout_sec=0.05)
print(json.dumps(samples), flush=True)
"""


# Calls bt_navigator/change_state (argv[1]: activate / deactivate) as Nav2's lifecycle
# manager does, then get_state; prints {"success": ..., "state": the state's label}.
LIFECYCLE_CLIENT = r"""
import json, sys
import rclpy
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
rclpy.init()
node = rclpy.create_node("lifecycle_test_client")
client = node.create_client(ChangeState, "bt_navigator/change_state")
if not client.wait_for_service(timeout_sec=30):
    sys.exit(3)
request = ChangeState.Request()
request.transition.id = {
    "activate": Transition.TRANSITION_ACTIVATE, "deactivate": Transition.TRANSITION_DEACTIVATE
}[sys.argv[1]]
future = client.call_async(request)
rclpy.spin_until_future_complete(node, future, timeout_sec=30)
success = bool(future.result() is not None and future.result().success)
get_state = node.create_client(GetState, "bt_navigator/get_state")
get_state.wait_for_service(timeout_sec=30)
state = get_state.call_async(GetState.Request())
rclpy.spin_until_future_complete(node, state, timeout_sec=30)
print(json.dumps({"success": success, "state": state.result().current_state.label}))
"""

# A Nav2 whose costmap services misbehave: navigate_to_pose aborts every goal at once;
# global_costmap/clear_entirely_global_costmap takes calls but never answers; the local
# costmap's service does not exist. Every goal and call goes to stdout as a JSON line.
SILENT_COSTMAP_NAV2 = r"""
import json, signal, sys, threading, time
import rclpy
from nav2_msgs.action import NavigateToPose
from nav2_msgs.srv import ClearEntireCostmap
from rclpy.action import ActionServer
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
node = rclpy.create_node("silent_costmap_nav2")
group = ReentrantCallbackGroup()
stop = threading.Event()
def say(event):
    print(json.dumps({"event": event, "t": time.monotonic()}), flush=True)
def execute(handle):
    say("goal")
    handle.abort()
    result = NavigateToPose.Result()
    result.error_msg = "scripted abort"
    return result
def clear(_request, response):
    say("clear_global")
    stop.wait()  # never answers while the test runs
    return response
ActionServer(node, NavigateToPose, "navigate_to_pose", execute, callback_group=group)
node.create_service(
    ClearEntireCostmap, "global_costmap/clear_entirely_global_costmap", clear,
    callback_group=group,
)
executor = MultiThreadedExecutor(num_threads=8)
executor.add_node(node)
signal.signal(signal.SIGTERM, lambda *a: stop.set())
signal.signal(signal.SIGINT, lambda *a: stop.set())
threading.Thread(target=executor.spin, daemon=True).start()
say("ready")
stop.wait()
executor.shutdown(timeout_sec=1)
"""


class SimNode(ros2_support.SimNode):
    """The sim node on the TurtleBot3 world (``ARGS`` add to ``--map``)."""

    def __init__(self, env: dict[str, str], *args: str) -> None:
        super().__init__(env, "--map", str(MAP), *args)


class OdomWatcher:
    def __init__(self, env: dict[str, str], topic: str = "/odom") -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-c", ODOM_WATCHER, topic],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert self.process.stdout is not None
        assert self.process.stdout.readline().strip() == "watching"

    def samples(self) -> list[list[float]]:
        self.process.send_signal(signal.SIGINT)
        out, err = self.process.communicate(timeout=30)
        assert self.process.returncode == 0, err
        return list(json.loads(out.strip().splitlines()[-1]))


@pytest.fixture
def env() -> dict[str, str]:
    prefix = ros2_prefix()
    assert prefix is not None
    return ros2_environment(prefix)


@pytest.fixture
def sim(env: dict[str, str]) -> Iterator[SimNode]:
    node = SimNode(env, f"--start={START}", "--speed", SPEED)
    yield node
    assert "Traceback" not in node.stop()


def run_nav2(
    env: dict[str, str], mission: Path, out: Path, *extra: str, timeout: float = 300
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--out", str(out), *extra],
        env=env,
        cwd=out.parent,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


class Nav2Run:
    """``navseq run --navigator nav2 --json`` in the background; stdout goes to a file."""

    def __init__(self, env: dict[str, str], mission: Path, out: Path, *extra: str) -> None:
        self.stdout_path = out.parent / f"{out.name}.stdout.jsonl"
        with self.stdout_path.open("w") as stdout:
            self.process = subprocess.Popen(
                [NAVSEQ, "run", mission, "--navigator", "nav2", "--json", "--out", out, *extra],
                env=env,
                cwd=out.parent,
                stdout=stdout,
                stderr=subprocess.PIPE,
                text=True,
            )

    def stdout(self) -> str:
        return self.stdout_path.read_text()

    def wait_driving(self, metres: float = 0.05) -> None:
        """Block until navseq reports the robot ``metres`` along its first waypoint."""

        def driving() -> bool:
            if self.process.poll() is not None:
                raise AssertionError(f"navseq exited early: {self.process.communicate()[1]}")
            return driven_towards(self.stdout(), 0, metres)

        wait_for(driving, 90, "the robot driving")

    def finish(self, timeout: float) -> str:
        """Wait for navseq to exit; its stderr."""
        try:
            return self.process.communicate(timeout=timeout)[1]
        finally:
            if self.process.poll() is None:
                self.process.kill()
                self.process.wait()


def report_of(out: Path) -> dict[str, Any]:
    return dict(json.loads((out / "report.json").read_text()))


def test_the_example_mission_completes_with_the_same_visits_as_on_the_simulator(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    done = run_nav2(env, EXAMPLE, tmp_path / "nav2", "--json")
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    on_sim = subprocess.run(
        [NAVSEQ, "run", str(EXAMPLE), "--out", str(tmp_path / "sim")],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert on_sim.returncode == 0, on_sim.stderr
    nav2, embedded = report_of(tmp_path / "nav2"), report_of(tmp_path / "sim")

    def visits(report: dict[str, Any]) -> list[tuple[str, str, bool]]:
        return [(v["name"], v["outcome"], v["passed_through"]) for v in report["visits"]]

    assert visits(nav2) == visits(embedded)
    assert all(outcome == "reached" for _, outcome, _ in visits(nav2))
    navigator = nav2["navigator"]
    assert navigator["kind"] == "nav2"
    assert navigator["action"] == "/navigate_to_pose"
    assert navigator["use_sim_time"] is True  # /clock published at --speed 4: followed
    assert "simulation time" in done.stderr
    # The robot's pose comes from /tf (map -> odom -> base_footprint): where it started.
    assert nav2["start_source"] == "robot"
    assert [nav2["start"]["x"], nav2["start"]["y"]] == pytest.approx([-2.0, -0.5], abs=0.02)
    # Distance driven is measured on odom: about the same as on the embedded simulator.
    assert nav2["totals"]["distance_m"] == pytest.approx(embedded["totals"]["distance_m"], rel=0.15)
    # Nav2's feedback reaches --json: its own time on the goal, its recovery count.
    records = [json.loads(line) for line in done.stdout.splitlines()]
    # (Progress from a pose alone, before a goal's first feedback, has neither.)
    fed = [r for r in records if r["event"] == "WaypointProgress" and r["navigation_time_s"]]
    assert len(fed) > 20 and all(r["recoveries"] == 0 for r in fed)
    times = [r["navigation_time_s"] for r in fed if r["index"] == 1]
    assert times[-1] > 5.0 and times == sorted(times)  # simulated seconds on goal 2
    assert all(a["recoveries"] == 0 for v in nav2["visits"] for a in v["attempts"])
    assert (tmp_path / "nav2" / "mission.png").exists()


def test_goals_in_a_pillar_and_deep_in_a_wall_are_judged_truthfully_and_skipped(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    # Pre-flight off: it would refuse both on the map Nav2 publishes; the stack must
    # answer instead. As Nav2's NavFn (tolerance 0.5 m), the stand-in drives to a free
    # cell near the pillar's centre and says SUCCEEDED there: navseq's arrival check
    # makes that a failed attempt. The wall's corner is beyond the tolerance: ABORTED.
    mission = write_mission(
        tmp_path / "wall.yaml",
        "  - {name: pillar, x: -1.1, y: 0.0, yaw: 0, on_failure: skip}\n"
        "  - {name: wall, x: -2.3, y: -2.3, yaw: 0, on_failure: skip}\n"
        "  - {name: free, x: -1.5, y: -0.5, yaw: 0}\n",
        "defaults: {retries: 0, goal_timeout: 60}\n",
    )
    done = run_nav2(env, mission, tmp_path / "out", "--no-preflight")
    assert done.returncode == 1, done.stderr  # not every waypoint reached
    assert "the map on /map: 384 x 384 cells at 0.050 m (no pre-flight" in done.stderr
    pillar, wall, free = report_of(tmp_path / "out")["visits"]
    assert pillar["outcome"] == wall["outcome"] == "skipped"
    near = pillar["attempts"][0]
    assert near["status"] == "SUCCEEDED"
    assert re.fullmatch(r"succeeded far from goal \(0\.[2-6]\d m\)", near["reason"]), near
    attempt = wall["attempts"][0]
    assert attempt["status"] == "ABORTED"
    # Nav2's error_msg first, then the planner's code by its nav2_msgs name.
    assert attempt["text"].endswith("(ComputePathToPose GOAL_OCCUPIED, error_code 206)")
    assert "in an obstacle" in attempt["text"]
    assert free["outcome"] == "reached"


def test_without_a_map_file_pre_flight_runs_on_the_map_nav2_publishes(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    # (1.0, 0.0): the edge of the east pillar (navseq validate --map: inside an obstacle).
    pillar = write_mission(
        tmp_path / "pillar.yaml",
        "  - {name: west, x: -1.4, y: -0.5, yaw: 90}\n  - {name: pillar, x: 1.0, y: 0.0, yaw: 0}\n",
    )
    refused = run_nav2(env, pillar, tmp_path / "refused", timeout=120)
    assert refused.returncode == 2, refused.stderr
    assert "(pre-flight on the map on /map: 384 x 384 cells at 0.050 m)" in refused.stderr
    assert "waypoint 2 'pillar'" in refused.stderr
    assert "inside an obstacle" in refused.stderr
    assert "Traceback" not in refused.stderr
    assert not (tmp_path / "refused").exists()

    good = write_mission(tmp_path / "good.yaml", "  - {name: west, x: -1.4, y: -0.5, yaw: 90}\n")
    done = run_nav2(env, good, tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert "navseq run: pre-flight on the map on /map: 384 x 384 cells at 0.050 m" in done.stderr
    report = report_of(tmp_path / "out")
    assert report["navigator"]["map_source"] == "the map on /map: 384 x 384 cells at 0.050 m"
    assert report["visits"][0]["outcome"] == "reached"
    # The refused mission sent no goal: the only one is the good mission's.
    assert sim_log_sequence(sim.stop()) == ["goal"]


def test_no_server_is_a_clear_error_within_the_server_timeout(env: dict[str, str], tmp_path: Path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: -1.5, y: -0.5, yaw: 0}\n")
    # Bounded by run_nav2's own timeout; the message says how long it waited (no timed
    # assertion: starting Python and rclpy on a loaded machine takes what it takes).
    done = run_nav2(env, mission, tmp_path / "out", "--server-timeout", "2")
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert "no action server '/navigate_to_pose'" in done.stderr
    assert "within 2 s" in done.stderr and "ROS_DOMAIN_ID" in done.stderr
    assert not (tmp_path / "out").exists()  # nothing written, nothing moved


def test_sigint_mid_goal_cancels_it_the_robot_stops_and_the_report_is_written(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    mission = write_mission(tmp_path / "far.yaml", "  - {name: far, x: 1.75, y: -0.55, yaw: 0}\n")
    out = tmp_path / "out"
    watcher = OdomWatcher(env)
    run = Nav2Run(env, mission, out)
    run.wait_driving(0.3)
    signalled = time.monotonic()
    run.process.send_signal(signal.SIGINT)
    err = run.finish(timeout=30)
    time.sleep(1.5)
    samples = watcher.samples()
    assert run.process.returncode == 130, err
    assert "Traceback" not in err
    report = report_of(out)
    assert report["interrupted"] == "SIGINT" and report["exit_code"] == 130
    assert report["visits"][0]["outcome"] == "failed"
    before = [v for t, v, _, _ in samples if t < signalled]
    after = [(t - signalled, v) for t, v, _, _ in samples if t >= signalled]
    assert max(before[-10:]) > 0.1  # it was driving
    stopped_at = next(t for t, v in after if v < 1e-3)
    assert stopped_at < 1.0, after[:40]
    assert all(v < 1e-3 for t, v in after if t >= stopped_at)  # and it stays stopped
    assert "navigate_to_pose: CANCELED" in sim.stop()


def test_a_goal_preempted_by_another_client_is_a_failed_attempt_then_retried(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: east, x: 1.75, y: -0.55, yaw: 90}\n",
        "defaults: {retries: 1, goal_timeout: 120, on_failure: stop}\n",
    )
    out = tmp_path / "out"
    run = Nav2Run(env, mission, out)
    run.wait_driving()
    # Another Nav2 client's goal, far from the robot: Nav2 preempts ours with it (ABORTED).
    other = subprocess.run(
        [sys.executable, str(CLIENTS), "navigate", "--", "-0.5,1.6,0"],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    stderr = run.finish(timeout=240)
    assert run.process.returncode == 0, stderr
    # navseq's retry preempted the other client's goal in turn.
    assert json.loads(other.stdout.strip().splitlines()[-1])["status"] == "ABORTED"
    (visit,) = report_of(out)["visits"]
    assert visit["outcome"] == "reached"
    first, second = visit["attempts"]
    assert first["status"] == "ABORTED" and first["text"] == "preempted by a new goal"
    assert second["status"] == "SUCCEEDED"
    (failed,) = printed_events(run.stdout(), "AttemptFailed")
    assert failed["will_retry"] and failed["text"] == "preempted by a new goal", failed


def test_a_server_killed_mid_goal_and_restarted_is_waited_for_and_the_mission_completes(
    env: dict[str, str], tmp_path: Path
):
    env = {**env, "CYCLONEDDS_URI": SHORT_LEASE}
    first = SimNode(env, f"--start={START}", "--speed", SPEED)
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: near, x: -1.0, y: -0.55, yaw: 0}\n",
        "server_timeout: 60\ndefaults: {goal_timeout: 120}\n",
    )
    out = tmp_path / "out"
    run = Nav2Run(env, mission, out)
    second = None
    try:
        run.wait_driving()
        first.process.kill()  # no goodbye: the server just vanishes
        first.process.wait()
        wait_for(
            lambda: journal_events(out / "journal.jsonl", "ServerStatusChanged"),
            30,
            "navseq noticing the server is gone",
        )
        second = SimNode(env, f"--start={START}", "--speed", SPEED)
        stderr = run.finish(timeout=180)
    finally:
        if second is not None:
            second.stop()
    assert run.process.returncode == 0, stderr
    changes = [e["available"] for e in journal_events(out / "journal.jsonl", "ServerStatusChanged")]
    assert changes == [False, True]
    (visit,) = report_of(out)["visits"]
    assert visit["outcome"] == "reached"
    assert "Traceback" not in stderr


def test_the_robot_passes_through_a_pass_through_waypoint_above_half_its_cruise_speed(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    radius = 0.3
    mission = write_mission(
        tmp_path / "line.yaml",
        f"  - {{name: via, x: -1.3, y: -0.5, yaw: 0, pass_through: {radius}}}\n"
        "  - {name: end, x: -0.55, y: -0.55, yaw: 0}\n",
    )
    watcher = OdomWatcher(env)
    done = run_nav2(env, mission, tmp_path / "out")
    samples = watcher.samples()
    assert done.returncode == 0, done.stderr
    via, end = report_of(tmp_path / "out")["visits"]
    assert via["passed_through"] and end["outcome"] == "reached"
    # The robot stands at the start (-2, -0.5, facing +x) at the first sample and odom
    # is not rotated against the map there: a map position is a shift of an odom one.
    _, _, x0, y0 = samples[0]
    near = [v for _, v, x, y in samples if math.hypot(x - x0 - 0.7, y - y0) <= radius]
    cruise = max(v for _, v, _, _ in samples)
    assert cruise == pytest.approx(CRUISE, abs=0.02)
    assert near, "no odom sample near the pass-through point"
    assert min(near) > cruise / 2, near


def test_nav2s_replan_race_on_pass_through_is_caught_and_retried_to_the_missions_end(
    env: dict[str, str], tmp_path: Path
):
    """Nav2 re-plans a preempting goal only at its tree's next tick; with --replan-period
    the simulator does too, and a pass-through goal then ends SUCCEEDED where the robot
    stopped for the preempted one. navseq must not count that as a visit."""
    # 20 s between ticks, longer than any leg here: every pass-through's next goal loses
    # the race (the robot covers the 0.35 m from the radius to the burger's 0.05 m
    # tolerance in about 1.6 s). With Nav2's 1 s the tick's phase decides, as on Nav2.
    sim = SimNode(env, f"--start={START}", "--speed", SPEED, "--replan-period", "20")
    radius = 0.4
    points = {"via1": (-1.3, -0.5), "via2": (-0.55, -0.55), "end": (-0.55, -1.75)}
    mission = write_mission(
        tmp_path / "race.yaml",
        f"  - {{name: via1, x: -1.3, y: -0.5, yaw: 0, pass_through: {radius}}}\n"
        f"  - {{name: via2, x: -0.55, y: -0.55, yaw: -90, pass_through: {radius}}}\n"
        "  - {name: end, x: -0.55, y: -1.75, yaw: 0}\n",
        "defaults: {retries: 2, goal_timeout: 120, on_failure: stop}\n",
    )
    watcher = OdomWatcher(env)
    try:
        done = run_nav2(env, mission, tmp_path / "out", "--json")
    finally:
        samples = watcher.samples()
        log = sim.stop()
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "Traceback" not in log
    via1, via2, end = report_of(tmp_path / "out")["visits"]
    assert [v["outcome"] for v in (via1, via2, end)] == ["reached"] * 3
    # via1 is passed; the goal that preempted it, via2's, SUCCEEDED at via1: a failed
    # attempt, retried; the same again from via2 to the end.
    assert via1["passed_through"] and len(via1["attempts"]) == 1
    for visit, stopped_at in ((via2, "via1"), (end, "via2")):
        first, second = visit["attempts"]
        assert first["status"] == "SUCCEEDED" and not first["reached"], visit
        far = re.fullmatch(r"succeeded far from goal \(([0-9.]+) m\)", first["reason"])
        assert far is not None, first
        # ... measured from where the robot stopped: the preempted goal (burger: 5 cm).
        off = math.dist(points[stopped_at], points[visit["name"]])
        assert float(far.group(1)) == pytest.approx(off, abs=0.1), first
        assert second["reached"] and second["reason"] == "", visit
    assert via2["passed_through"] and not end["passed_through"]
    failed = printed_events(done.stdout, "AttemptFailed")
    assert [(f["index"], f["reason"].split(" (")[0], f["will_retry"]) for f in failed] == [
        (1, "succeeded far from goal", True),
        (2, "succeeded far from goal", True),
    ]
    assert log.count("SUCCEEDED on the preempted goal's path") == 2, log
    # Truthful visits: odom (a shift of the map frame, see the pass-through speed test)
    # shows the robot within the radius of each passed point, and stopped at the end.
    _, _, x0, y0 = samples[0]
    start_x, start_y = -2.0, -0.5
    track = [(x - x0 + start_x, y - y0 + start_y) for _, _, x, y in samples]

    def closest(name: str) -> float:
        return min(math.dist(point, points[name]) for point in track)

    assert closest("via1") <= radius and closest("via2") <= radius
    assert math.dist(track[-1], points["end"]) < 0.1


@pytest.mark.parametrize("tf_convention", ["nav2", "ros1"])
def test_a_namespaced_nav2_is_driven_with_ns(
    env: dict[str, str], tmp_path: Path, tf_convention: str
):
    """The robot's frames are found in either convention: Nav2's (``odom`` ... on
    ``/robot1/tf``, the simulator's default) and ROS 1's (``robot1/odom`` on ``/tf``)."""
    sim = SimNode(
        env,
        f"--start={START}",
        "--speed",
        SPEED,
        "--ns",
        "robot1",
        "--tf-convention",
        tf_convention,
    )
    mission = write_mission(tmp_path / "m.yaml", "  - {x: -1.4, y: -0.5, yaw: 90}\n")
    try:
        done = run_nav2(env, mission, tmp_path / "out", "--ns", "robot1")
    finally:
        sim.stop()
    assert done.returncode == 0, done.stderr
    report = report_of(tmp_path / "out")
    assert report["navigator"]["action"] == "/robot1/navigate_to_pose"
    assert report["navigator"]["ns"] == "robot1"
    # The robot came from the namespace's own Nav2 nodes, and the map from its map_server.
    assert "Nav2's parameters under /robot1: footprint" in report["navigator"]["robot_source"]
    assert report["navigator"]["map_source"] == (
        "the map on /robot1/map: 384 x 384 cells at 0.050 m"
    )
    # The robot's transforms (either convention), and /robot1/odom, were found.
    assert report["start_source"] == "robot"
    assert report["visits"][0]["distance_m"] == pytest.approx(0.6, abs=0.25)


def test_arrival_is_judged_with_the_goal_tolerance_nav2_itself_uses(
    env: dict[str, str], tmp_path: Path
):
    """Nav2 ends a goal SUCCEEDED within its goal checker's tolerance (0.25 m on most
    robots): navseq reads it from Nav2's parameters, so such an arrival is one."""
    robot = tmp_path / "loose.yaml"
    robot.write_text(
        "base: turtlebot3_waffle\nname: loose\nxy_goal_tolerance: 0.3\nyaw_goal_tolerance: 40\n"
    )
    sim = SimNode(env, f"--start={START}", "--speed", SPEED, "--robot", str(robot))
    mission = write_mission(
        tmp_path / "m.yaml", "  - {x: -1.4, y: -0.5, yaw: 90}\n  - {x: -1.4, y: 0.6, yaw: 0}\n"
    )
    try:
        done = run_nav2(env, mission, tmp_path / "out")
    finally:
        sim.stop()
    assert done.returncode == 0, done.stderr
    source = report_of(tmp_path / "out")["navigator"]["robot_source"]
    assert source.startswith("robot from Nav2's parameters under /: footprint 4 points"), source
    assert "tolerance 0.3 m / 40°" in source and source in done.stderr
    visits = report_of(tmp_path / "out")["visits"]
    assert [visit["outcome"] for visit in visits] == ["reached", "reached"]
    assert all(len(visit["attempts"]) == 1 for visit in visits)  # none "far from goal"


def test_without_ros2_the_nav2_navigator_says_to_source_it(tmp_path: Path):
    """Where rclpy does not import (ROS 2 not sourced): one message, exit 2."""
    plain = {
        key: value
        for key, value in os.environ.items()
        if key not in ("PYTHONPATH", "LD_LIBRARY_PATH", "AMENT_PREFIX_PATH")
    }
    probe = subprocess.run([sys.executable, "-c", "import rclpy"], env=plain, capture_output=True)
    if probe.returncode == 0:
        pytest.skip("rclpy imports without sourcing ROS 2 here")
    mission = write_mission(tmp_path / "m.yaml", "  - {x: -1.5, y: -0.5, yaw: 0}\n")
    done = subprocess.run(
        [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--out", str(tmp_path / "out")],
        env=plain,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "the nav2 navigator needs ROS 2's Python packages" in done.stderr
    assert "source ROS 2 first" in done.stderr
    assert not (tmp_path / "out").exists()


def test_start_is_refused_for_a_real_robot(tmp_path: Path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: -1.5, y: -0.5, yaw: 0}\n")
    done = subprocess.run(
        [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--start", "0,0,0"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2
    assert "--navigator nav2 the robot is where it is" in done.stderr
    assert "Traceback" not in done.stderr


def change_navigator_state(env: dict[str, str], transition: str) -> None:
    done = subprocess.run(
        [sys.executable, "-c", LIFECYCLE_CLIENT, transition],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    state = "active" if transition == "activate" else "inactive"
    assert json.loads(done.stdout.strip().splitlines()[-1]) == {"success": True, "state": state}


def test_goals_rejected_while_bt_navigator_is_inactive_spend_the_retries_then_the_policy_applies(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    # Nav2 between configure and activate: the action server is found, goals rejected.
    change_navigator_state(env, "deactivate")
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: first, x: -1.5, y: -0.5, yaw: 0, retries: 1, on_failure: skip}\n"
        "  - {name: second, x: -1.0, y: -0.5, yaw: 0}\n",
        "defaults: {retries: 0, on_failure: stop, goal_timeout: 60}\n",
    )
    # A hang would run into the subprocess timeout; the three rejections take seconds.
    done = run_nav2(env, mission, tmp_path / "out", "--json", timeout=120)
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    first, second = report_of(tmp_path / "out")["visits"]
    assert first["outcome"] == "skipped" and second["outcome"] == "failed"
    attempts = first["attempts"] + second["attempts"]
    assert [a["status"] for a in attempts] == ["REJECTED"] * 3
    assert all("the server rejected the goal: " in a["text"] for a in attempts)
    assert all("is bt_navigator active?" in a["text"] for a in attempts)
    failed = printed_events(done.stdout, "AttemptFailed")
    assert [(e["index"], e["will_retry"], e["status"]) for e in failed] == [
        (0, True, "REJECTED"),
        (0, False, "REJECTED"),
        (1, False, "REJECTED"),
    ]
    log = sim.stop()
    assert log.count("Action server is inactive. Rejecting the goal.") == 3
    assert "navigate_to_pose: goal to" not in log  # the robot was never sent anywhere


def test_a_goal_rejected_before_bt_navigator_is_activated_is_retried_and_reached(
    sim: SimNode, env: dict[str, str], tmp_path: Path
):
    """navseq started while Nav2 is still coming up: once activated, the retry is taken."""
    change_navigator_state(env, "deactivate")
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: near, x: -1.5, y: -0.5, yaw: 0}\n",
        # on_failure: retry: a rejection is retried after a growing back-off (1, 2, 4 ...
        # 30 s), and the activation comes from a ROS 2 process that may take seconds to
        # start on a loaded machine: 8 rejections in a row give it two minutes.
        "defaults: {on_failure: retry, retries: 8, goal_timeout: 60}\n",
    )
    out = tmp_path / "out"
    run = Nav2Run(env, mission, out)
    wait_for(lambda: bool(printed_events(run.stdout(), "AttemptFailed")), 60, "a rejected attempt")
    change_navigator_state(env, "activate")
    stderr = run.finish(timeout=120)
    assert run.process.returncode == 0, stderr
    (visit,) = report_of(out)["visits"]
    assert visit["outcome"] == "reached"
    statuses = [a["status"] for a in visit["attempts"]]
    assert statuses[0] == "REJECTED" and statuses[-1] == "SUCCEEDED"
    assert set(statuses[:-1]) == {"REJECTED"}


def sim_log_sequence(log: str) -> list[str]:
    """The sim node's goals and clear-costmap calls, in the order it logged them."""
    kinds = {
        "navigate_to_pose: goal to": "goal",
        "global_costmap: cleared": "clear_global",
        "local_costmap: cleared": "clear_local",
    }
    return [kind for line in log.splitlines() for text, kind in kinds.items() if text in line]


@pytest.mark.parametrize("clear", [True, False])
def test_a_retry_clears_both_costmaps_before_its_goal_only_when_asked(
    clear: bool, sim: SimNode, env: dict[str, str], tmp_path: Path
):
    # A goal deep beyond the arena's wall, farther than the planner's 0.5 m tolerance
    # from free space (pre-flight off): Nav2's planner aborts it, and its retry too.
    mission = write_mission(
        tmp_path / "wall.yaml",
        "  - {name: wall, x: -2.3, y: -2.3, yaw: 0}\n",
        "defaults: {retries: 1, on_failure: skip, goal_timeout: 60, "
        f"clear_costmaps_on_retry: {str(clear).lower()}}}\n",
    )
    done = run_nav2(env, mission, tmp_path / "out", "--no-preflight", timeout=120)
    assert done.returncode == 1, done.stderr
    (visit,) = report_of(tmp_path / "out")["visits"]
    assert [a["status"] for a in visit["attempts"]] == ["ABORTED", "ABORTED"]
    sequence = sim_log_sequence(sim.stop())
    if clear:
        # Both services answered before the retry's goal went out.
        assert sequence[0] == "goal" and sequence[-1] == "goal", sequence
        assert sorted(sequence[1:-1]) == ["clear_global", "clear_local"], sequence
    else:
        assert sequence == ["goal", "goal"]
    assert "unavailable" not in done.stderr and "did not answer" not in done.stderr


def test_a_missing_or_silent_clear_service_delays_the_retry_but_never_hangs_it(
    env: dict[str, str], tmp_path: Path
):
    server = subprocess.Popen(
        [sys.executable, "-c", SILENT_COSTMAP_NAV2],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert server.stdout is not None
        assert '"ready"' in server.stdout.readline()
        mission = write_mission(
            tmp_path / "m.yaml",
            "  - {name: a, x: 1.0, y: 0.0, yaw: 0}\n",
            "defaults: {retries: 2, on_failure: stop, goal_timeout: 30, "
            "clear_costmaps_on_retry: true}\n",
        )
        # A clear call that waited for its answer would never return: the run would
        # hit this timeout instead of ending with three attempts.
        done = run_nav2(env, mission, tmp_path / "out", timeout=120)
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            out, _ = server.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            out, _ = server.communicate()
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    (visit,) = report_of(tmp_path / "out")["visits"]
    assert [a["status"] for a in visit["attempts"]] == ["ABORTED"] * 3
    events = [json.loads(line)["event"] for line in out.splitlines() if line.startswith("{")]
    assert events == ["goal", "clear_global", "goal", "clear_global", "goal"]
    # Each misbehaving service is named once, not on every retry.
    missing = "local_costmap/clear_entirely_local_costmap unavailable"
    silent = "global_costmap/clear_entirely_global_costmap did not answer within 1 s"
    assert done.stderr.count(missing) == 1, done.stderr
    assert done.stderr.count(silent) == 1, done.stderr
