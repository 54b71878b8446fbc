"""ROS 2 benchmark: goal turnaround over real rclpy actions, and mission time on the sim node.

Run:  .venv/bin/python benchmarks/bench_nav2.py [--goals 200] [--speed 4]

Where no ROS 2 is found (``tests/ros2_support.py``: ``$NAVSEQ_ROS2_PREFIX``,
``/opt/ros2min`` or a sourced ROS 2) it says so and exits 0, so ``make bench`` runs
everywhere. Every ROS 2 process is a subprocess (this script in a ``--role``) on a
private ``ROS_DOMAIN_ID`` with discovery on the loopback, and is stopped at the end.

1. **Goal turnaround**: a ``navigate_to_pose`` server (``--role server``) that accepts
   every ``nav2_msgs/action/NavigateToPose`` goal and succeeds it at once. Turnaround is
   measured on the *server's* clock: from the moment its execute callback returned goal
   n's result to the moment goal n+1's request arrived. That is everything a sequencer
   adds between two goals: receiving the result, deciding, sending the next goal.
   Clients, each against a fresh server:

   - navseq: :class:`~navseq.ros2.navigator.Nav2Navigator` +
     :func:`~navseq.executor.runner.run_mission`, with the executor tick ``navseq run``
     uses (0.1 s) and a 10x shorter one;
   - baseline: a plain rclpy ``ActionClient`` loop (send_goal_async, wait for the goal
     handle, get_result_async, wait for the result, next goal).

2. **Mission time**: ``examples/turtlebot3_world.yaml`` driven by ``navseq run
   --navigator nav2`` through the ROS 2 simulator node (``python -m
   navseq.ros2.sim_node --speed S``, publishing ``/clock``), side by side with the same
   mission on the in-process simulator (``navseq run``). Mission time is simulated time
   from the journal's MissionStarted to MissionFinished; the ratio says what going
   through ROS 2 (feedback at 10 Hz wall, the executor's tick, DDS) costs the robot.
   Efficiency is mission time over the lower bound that ``bench_sim.py`` uses (the
   shortest collision-free leg lengths from the start pose, at top speed); issue 11's
   target is the same efficiency through ROS 2 as in process, within 5 %.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

REPO_ROOT = Path(__file__).resolve().parents[1]
THIS_SCRIPT = Path(__file__).resolve()
# ros2_support (where ROS 2 is, the environment of a ROS 2 process) is shared with the tests.
sys.path.insert(0, str(REPO_ROOT / "tests"))

import turnaround  # noqa: E402  (benchmarks/turnaround.py: shared with bench_ros1.py)

from ros2_support import ros2_available, ros2_environment, ros2_prefix  # noqa: E402

EXAMPLE = REPO_ROOT / "examples" / "turtlebot3_world.yaml"
NAVSEQ = Path(sys.executable).parent / "navseq"
DEFAULT_TICK = 0.1  # s: what `navseq run` uses
CLIENT_TIMEOUT = 180.0  # s of wall time for one client run; nothing waits unbounded


# ---------------------------------------------------------------------------------------
# Roles: each runs in its own process, in the ROS 2 environment
# ---------------------------------------------------------------------------------------


def role_server(log: Path) -> None:
    """A navigate_to_pose server that succeeds every goal at once, logging its own times."""
    import rclpy
    from nav2_msgs.action import NavigateToPose
    from rclpy.action import ActionServer
    from rclpy.executors import ExternalShutdownException

    rclpy.init()
    node = rclpy.create_node("bench_nav2_server")
    sink = open(log, "a", encoding="utf-8", buffering=1)  # noqa: SIM115 (lives with the node)
    arrivals: dict[bytes, float] = {}

    class TimedServer(ActionServer):
        """Stamps a goal's arrival where its request leaves the middleware (the goal
        callback does not see the goal's id)."""

        async def _execute_goal_request(self, request_header_and_message: Any) -> Any:
            _header, request = request_header_and_message
            arrivals[bytes(request.goal_id.uuid)] = time.monotonic()
            return await super()._execute_goal_request(request_header_and_message)

    def execute(handle: Any) -> Any:
        handle.succeed()
        arrived = arrivals.pop(bytes(handle.goal_id.uuid), float("nan"))
        sink.write(json.dumps({"arrived": arrived, "result": time.monotonic()}) + "\n")
        return NavigateToPose.Result()

    TimedServer(node, NavigateToPose, "navigate_to_pose", execute_callback=execute)
    print("bench server ready", flush=True)
    with contextlib.suppress(KeyboardInterrupt, ExternalShutdownException):
        rclpy.spin(node)


def bench_goals(count: int) -> list[tuple[float, float, float]]:
    """``count`` distinct (x, y, yaw) goals around a 2 m circle."""
    return [
        (2.0 * math.cos(angle), 2.0 * math.sin(angle), math.remainder(angle + 1.5, math.tau))
        for angle in (0.1 * i for i in range(count))
    ]


def role_navseq_client(goals: int, tick: float) -> None:
    """navseq's sequencer (Nav2Navigator + run_mission) sending ``goals`` goals in a row."""
    from navseq.executor.runner import run_mission
    from navseq.mission import Mission
    from navseq.mission.model import FailureAction, Policy, Waypoint
    from navseq.ros2.navigator import Nav2Navigator

    mission = Mission(
        waypoints=tuple(Waypoint(x, y, yaw_rad=yaw) for x, y, yaw in bench_goals(goals)),
        defaults=Policy(goal_timeout_s=10.0, on_failure=FailureAction.STOP),
        source="<bench_nav2>",
    )
    navigator = Nav2Navigator(node_name="bench_navseq", use_sim_time=False)
    try:
        result = run_mission(mission, navigator, tick=tick, server_wait=30.0)
    finally:
        navigator.close()
    print(json.dumps({"success": result.success}), flush=True)


def role_baseline_client(goals: int) -> None:
    """The plain rclpy sequence: send, wait for acceptance, wait for the result, next."""
    import rclpy
    from action_msgs.msg import GoalStatus
    from nav2_msgs.action import NavigateToPose
    from rclpy.action import ActionClient

    rclpy.init()
    node = rclpy.create_node("bench_baseline")
    client = ActionClient(node, NavigateToPose, "navigate_to_pose")
    if not client.wait_for_server(timeout_sec=30):
        raise SystemExit("baseline: no navigate_to_pose server within 30 s")
    succeeded = 0
    for x, y, yaw in bench_goals(goals):
        goal = NavigateToPose.Goal()
        goal.pose.header.frame_id = "map"
        goal.pose.header.stamp = node.get_clock().now().to_msg()
        goal.pose.pose.position.x = x
        goal.pose.pose.position.y = y
        goal.pose.pose.orientation.z = math.sin(yaw / 2)
        goal.pose.pose.orientation.w = math.cos(yaw / 2)
        sent = client.send_goal_async(goal)
        rclpy.spin_until_future_complete(node, sent, timeout_sec=10)
        handle = sent.result()
        if handle is None or not handle.accepted:
            break
        result = handle.get_result_async()
        rclpy.spin_until_future_complete(node, result, timeout_sec=10)
        if result.result() is None or result.result().status != GoalStatus.STATUS_SUCCEEDED:
            break
        succeeded += 1
    print(json.dumps({"success": succeeded == goals}), flush=True)


def run_role(args: argparse.Namespace) -> None:
    if args.role == "server":
        role_server(Path(args.log))
    elif args.role == "navseq":
        role_navseq_client(args.goals, args.tick)
    elif args.role == "baseline":
        role_baseline_client(args.goals)


# ---------------------------------------------------------------------------------------
# Processes
# ---------------------------------------------------------------------------------------


def start(env: dict[str, str], *argv: str | Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [str(arg) for arg in argv],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_ready(process: subprocess.Popen[str], word: str, timeout: float = 60.0) -> None:
    """Read stdout until a line has ``word`` (the server's or the sim's ready line)."""
    assert process.stdout is not None
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if not line:
            break
        if word in line:
            return
    process.kill()
    raise RuntimeError(f"not ready: {process.args!r}\n{process.communicate()[1][-3000:]}")


def stop(process: subprocess.Popen[str]) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    try:
        process.wait(timeout=20)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


# ---------------------------------------------------------------------------------------
# Part 1: goal turnaround
# ---------------------------------------------------------------------------------------


def measure_turnaround(
    env: dict[str, str], workdir: Path, name: str, client_args: list[str]
) -> turnaround.Turnaround:
    log = workdir / f"server-{name.replace(' ', '_').replace(',', '')}.jsonl"
    server = start(env, sys.executable, THIS_SCRIPT, "--role", "server", "--log", log)
    try:
        wait_ready(server, "bench server ready")
        client = subprocess.run(
            [sys.executable, str(THIS_SCRIPT), *client_args],
            env=env,
            capture_output=True,
            text=True,
            timeout=CLIENT_TIMEOUT,
        )
        reply = turnaround.last_json_line(client.stdout)
        if client.returncode != 0 or not reply:
            raise RuntimeError(f"{name} failed ({client.returncode}):\n{client.stderr[-3000:]}")
    finally:
        stop(server)
    return turnaround.from_server_log(log, name, reply)


def turnaround_table(env: dict[str, str], workdir: Path, goals: int) -> Table:
    n = ["--goals", str(goals)]
    base = measure_turnaround(env, workdir, "ActionClient loop", ["--role", "baseline", *n])
    rows = [
        measure_turnaround(
            env, workdir, f"navseq, tick {tick:g} s", ["--role", "navseq", *n, "--tick", str(tick)]
        )
        for tick in (DEFAULT_TICK, DEFAULT_TICK / 10)
    ]
    made = turnaround.table(
        "Goal turnaround over rclpy actions (server clock: result n returned -> goal n+1 received)"
    )
    for row in [*rows, base]:
        made.add_row(*row.cells(base))
    return made


# ---------------------------------------------------------------------------------------
# Part 2: mission time on the ROS 2 sim node vs in process
# ---------------------------------------------------------------------------------------


@dataclasses.dataclass
class MissionRun:
    variant: str
    success: bool
    mission_s: float  # simulated
    wall_s: float
    distance_m: float


def journal_mission_time(journal: Path) -> tuple[float, bool]:
    """(simulated s from MissionStarted to MissionFinished, success) from a run's journal."""
    events = [json.loads(line) for line in journal.read_text().splitlines() if line.strip()]
    started = next(e["t"] for e in events if e.get("type") == "MissionStarted")
    finished = next(e for e in events if e.get("type") == "MissionFinished")
    return finished["t"] - started, bool(finished["success"])


def run_cli(env: dict[str, str] | None, variant: str, out: Path, *extra: str) -> MissionRun:
    began = time.monotonic()
    done = subprocess.run(
        [str(NAVSEQ), "run", str(EXAMPLE), "--out", str(out), *extra],
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    wall = time.monotonic() - began
    if done.returncode not in (0, 1):
        raise RuntimeError(f"{variant}: navseq run exited {done.returncode}:\n{done.stderr}")
    mission_s, success = journal_mission_time(out / "journal.jsonl")
    report = json.loads((out / "report.json").read_text())
    return MissionRun(variant, success, mission_s, wall, report["totals"]["distance_m"])


def example_lower_bound() -> float:
    """Seconds the example mission needs at least, from the start the sim node is given."""
    sys.path.insert(0, str(THIS_SCRIPT.parent))
    from bench_sim import lower_bound

    from navseq.geometry import Pose2D
    from navseq.mission import load_mission
    from navseq.navigators.sim import SimNavigator

    mission = load_mission(EXAMPLE)
    assert mission.map is not None
    return lower_bound(mission, SimNavigator.from_map(mission.map, Pose2D(-2.0, -0.5, 0.0)))


def mission_table(env: dict[str, str], workdir: Path, speed: float) -> Table:
    bound = example_lower_bound()
    in_process = run_cli(
        None, "in-process simulator (navseq run)", workdir / "sim", "--start=-2,-0.5,0"
    )
    sim = start(
        env,
        sys.executable,
        "-m",
        "navseq.ros2.sim_node",
        "--map",
        REPO_ROOT / "maps" / "turtlebot3_world.yaml",
        "--start=-2,-0.5,0",
        "--speed",
        str(speed),
    )
    try:
        wait_ready(sim, "ready")
        nav2 = run_cli(
            env,
            f"ROS 2 sim node at {speed:g}x (--navigator nav2)",
            workdir / "nav2",
            "--navigator",
            "nav2",
        )
    finally:
        stop(sim)
    table = Table(
        title=f"{EXAMPLE.name}: mission time (simulated s) vs its lower bound ({bound:.1f} s)"
    )
    columns = (
        "navigator",
        "all reached",
        "mission s",
        "efficiency",
        "vs in-process",
        "driven m",
        "wall s",
    )
    for column in columns:
        table.add_column(column, justify="right")
    for run in (in_process, nav2):
        table.add_row(
            run.variant,
            "yes" if run.success else "NO",
            f"{run.mission_s:.1f}",
            f"{run.mission_s / bound:.3f}",
            f"{run.mission_s / in_process.mission_s:.3f}x",
            f"{run.distance_m:.2f}",
            f"{run.wall_s:.1f}",
        )
    return table


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=["server", "navseq", "baseline"])
    parser.add_argument("--log")
    parser.add_argument("--goals", type=int, default=200)
    parser.add_argument("--tick", type=float, default=DEFAULT_TICK)
    parser.add_argument("--speed", type=float, default=4.0, help="sim node speed (part 2)")
    parser.add_argument("--skip-mission", action="store_true", help="only part 1")
    args = parser.parse_args()
    if args.role:
        run_role(args)
        return 0
    available, why = ros2_available()
    prefix = ros2_prefix()
    if not available or prefix is None:
        print(f"bench_nav2: skipped, no usable ROS 2: {why}")
        return 0
    env = ros2_environment(prefix)
    console = Console(width=150)
    with tempfile.TemporaryDirectory(prefix="bench_nav2-") as folder:
        workdir = Path(folder)
        console.print(turnaround_table(env, workdir, args.goals))
        if not args.skip_mission:
            console.print(mission_table(env, workdir, args.speed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
