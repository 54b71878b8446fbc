"""ROS 1 benchmark: goal turnaround over real actionlib, and mission time over the sim nodes.

Run:  .venv/bin/python benchmarks/bench_ros1.py [--goals 200] [--speed 10]

Everything runs against a private ``rosmaster`` on a free 127.0.0.1 port with ROS_HOME in
a temporary folder (``tests/ros_support.py``); every ROS client and server is a
subprocess (this same script in a ``--role``), and all of them are stopped at the end.

1. **Goal turnaround**: a move_base action server (``--role server``, below) that
   accepts and succeeds every goal at once, inside its goal callback. Turnaround is
   measured on the *server's* clock: from the moment it published goal n's result to the
   moment goal n+1 arrived (and was accepted). That is everything a sequencer adds
   between two goals: receiving the result, deciding, sending the next goal. Clients:

   - navseq: :class:`~navseq.ros1.navigator.Ros1Navigator` +
     :func:`~navseq.executor.runner.run_mission`, with the executor tick the CLI and the
     node use (0.1 s) and with a 10x shorter one; with its default ``settle`` (0.05 s of
     wall time after a result before the next goal, which keeps clear of move_base's
     SUCCEEDED race, navigation #949) and, side by side, with it off (what it costs);
   - baseline: a plain ``SimpleActionClient`` loop (send_goal, wait_for_result, next).

2. **Mission time vs its lower bound**: the simulator's ROS nodes (``sim_robot_node``
   publishing ``/clock`` at ``--speed`` times real time, ``sim_nav_node`` as
   ``move_base``) driven through ``examples/turtlebot3_world.yaml`` by
   ``navseq run --navigator ros1``, once stopping at every waypoint and once passing
   through every intermediate one (0.3 m). Mission time is simulated time, from the
   journal's MissionStarted to MissionFinished. Lower bounds: the sum over legs (start ->
   waypoint 1 -> ...) of the length of the plan ``move_base/make_plan`` returns, divided by
   the top speed 0.22 m/s; and the same with the shortest collision-free path for the
   robot centre (as ``bench_sim.py`` computes it). The make_plan bound is the natural one
   for a stopping robot; passing within 0.3 m of a waypoint cuts the corner the plan
   makes there, so pass-through can come in slightly under it.

The turnaround rows use two servers: one that succeeds at once (the result reaches the
client right after it sent the goal) and one that succeeds after a random delay, as a
real robot does, so the result lands at a random moment of the client's loop. Ratios
compare with the baseline against the same server. The whole run takes about 2 minutes.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import itertools
import json
import math
import random
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

REPO_ROOT = Path(__file__).resolve().parents[1]
THIS_SCRIPT = Path(__file__).resolve()
# ros_support (rosmaster on a free port, processes stopped by PID) is shared with the tests.
sys.path.insert(0, str(REPO_ROOT / "tests"))

import turnaround  # noqa: E402  (benchmarks/turnaround.py: shared with bench_nav2.py)

from navseq.mission import Mission, load_mission, write_mission  # noqa: E402
from navseq.mission.model import FailureAction, Policy, Waypoint  # noqa: E402
from navseq.sim.robot import DiffDriveLimits  # noqa: E402
from ros_support import RosMaster, running_master  # noqa: E402

EXAMPLE = REPO_ROOT / "examples" / "turtlebot3_world.yaml"
NAVSEQ = Path(sys.executable).parent / "navseq"
ACTION = "move_base"
DEFAULT_TICK = 0.1  # s: what `navseq run` and the navseq node use
DEFAULT_SETTLE = 0.05  # s: navseq's wait after a result (Ros1Navigator's default)
RANDOM_DELAY = 0.2  # s: longest wait of the server that succeeds goals at a random moment
PASS_THROUGH = 0.3  # m, as in bench_sim.py
CLIENT_TIMEOUT = 120.0  # s of wall time for one client run; nothing waits unbounded


# ---------------------------------------------------------------------------------------
# Roles: each runs in its own process (rospy allows one node per process)
# ---------------------------------------------------------------------------------------


def role_server(log: Path, delay_max: float) -> None:
    """A move_base action server that succeeds every goal, logging times on its own clock.

    With ``delay_max`` 0 each goal succeeds inside its goal callback; otherwise after a
    random delay up to ``delay_max`` seconds, so results reach the client at a random
    moment of its loop, as a real robot's would.
    """
    import actionlib
    import rospy
    from move_base_msgs.msg import MoveBaseAction, MoveBaseResult

    rospy.init_node("bench_move_base")
    sink = open(log, "a", encoding="utf-8", buffering=1)  # noqa: SIM115 (lives with the node)
    delays = random.Random(4)  # the same delays in every run
    arrivals: dict[str, float] = {}

    def succeed(handle: Any) -> None:
        # "result" is stamped before publishing: the result goes out before the status
        # array, and the client may answer while the server still holds its lock.
        result_time = time.monotonic()
        handle.set_succeeded(MoveBaseResult(), "bench: reached")
        arrived = arrivals.pop(handle.get_goal_id().id)
        sink.write(json.dumps({"arrived": arrived, "result": result_time}) + "\n")

    def on_goal(handle: Any) -> None:
        arrivals[handle.get_goal_id().id] = time.monotonic()
        handle.set_accepted("bench: accepted")
        if delay_max <= 0:
            succeed(handle)
        else:
            threading.Timer(delays.uniform(0.0, delay_max), succeed, (handle,)).start()

    def on_cancel(handle: Any) -> None:
        handle.set_canceled(MoveBaseResult(), "bench: canceled")

    server = actionlib.ActionServer(ACTION, MoveBaseAction, on_goal, on_cancel, auto_start=False)
    server.start()
    print("bench server ready", flush=True)
    rospy.spin()


def bench_goals(count: int) -> list[tuple[float, float, float]]:
    """``count`` distinct (x, y, yaw) goals around a 2 m circle."""
    return [
        (2.0 * math.cos(angle), 2.0 * math.sin(angle), math.remainder(angle + 1.5, math.tau))
        for angle in (0.1 * i for i in range(count))
    ]


def role_navseq_client(goals: int, tick: float, settle: float) -> None:
    """navseq's sequencer (Ros1Navigator + run_mission) sending ``goals`` goals in a row."""
    from navseq.executor.runner import run_mission
    from navseq.ros1.navigator import Ros1Navigator

    mission = Mission(
        waypoints=tuple(Waypoint(x, y, yaw_rad=yaw) for x, y, yaw in bench_goals(goals)),
        defaults=Policy(goal_timeout_s=10.0, on_failure=FailureAction.STOP),
        source="<bench_ros1>",
    )
    navigator = Ros1Navigator(ACTION, node_name="bench_navseq", settle=settle)
    try:
        result = run_mission(mission, navigator, tick=tick, server_wait=30.0)
    finally:
        navigator.close()
    print(json.dumps({"success": result.success}), flush=True)


def role_baseline_client(goals: int) -> None:
    """The plain actionlib sequence: send_goal, wait_for_result, next (never in done_cb)."""
    import actionlib
    import rospy
    from actionlib_msgs.msg import GoalStatus
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

    rospy.init_node("bench_baseline", anonymous=True)
    client = actionlib.SimpleActionClient(ACTION, MoveBaseAction)
    if not client.wait_for_server(rospy.Duration(30)):
        raise SystemExit("baseline: no move_base server within 30 s")
    succeeded = 0
    for x, y, yaw in bench_goals(goals):
        goal = MoveBaseGoal()
        goal.target_pose.header.frame_id = "map"
        goal.target_pose.header.stamp = rospy.Time.now()
        goal.target_pose.pose.position.x = x
        goal.target_pose.pose.position.y = y
        goal.target_pose.pose.orientation.z = math.sin(yaw / 2)
        goal.target_pose.pose.orientation.w = math.cos(yaw / 2)
        client.send_goal(goal)
        if not client.wait_for_result(rospy.Duration(10)):
            break
        if client.get_state() != GoalStatus.SUCCEEDED:
            break
        succeeded += 1
    print(json.dumps({"success": succeeded == goals}), flush=True)


def role_plan_lengths(legs: list[list[float]]) -> None:
    """Length (m) of the plan ``move_base/make_plan`` returns for each (x0, y0, x1, y1) leg."""
    import rospy
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.srv import GetPlan

    rospy.init_node("bench_make_plan", anonymous=True)
    service = f"{ACTION}/make_plan"
    rospy.wait_for_service(service, timeout=30)
    make_plan = rospy.ServiceProxy(service, GetPlan)

    def stamped(x: float, y: float) -> PoseStamped:
        pose = PoseStamped()
        pose.header.frame_id = "map"
        pose.pose.position.x, pose.pose.position.y = x, y
        pose.pose.orientation.w = 1.0
        return pose

    lengths = []
    for x0, y0, x1, y1 in legs:
        points = [
            (p.pose.position.x, p.pose.position.y)
            for p in make_plan(stamped(x0, y0), stamped(x1, y1), 0.0).plan.poses
        ]
        if len(points) < 2:
            raise SystemExit(f"make_plan found no path from ({x0}, {y0}) to ({x1}, {y1})")
        lengths.append(sum(math.dist(a, b) for a, b in itertools.pairwise(points)))
    print(json.dumps({"lengths": lengths}), flush=True)


def run_role(args: argparse.Namespace) -> None:
    if args.role == "server":
        role_server(Path(args.log), args.delay_max)
    elif args.role == "navseq":
        role_navseq_client(args.goals, args.tick, args.settle)
    elif args.role == "baseline":
        role_baseline_client(args.goals)
    elif args.role == "plan":
        role_plan_lengths(json.loads(args.legs))


# ---------------------------------------------------------------------------------------
# Part 1: goal turnaround
# ---------------------------------------------------------------------------------------


def measure_turnaround(
    master: RosMaster, server: tuple[str, float], client: tuple[str, list[str]]
) -> turnaround.Turnaround:
    """A fresh server (name, delay_max), one run of a client (name, role arguments)."""
    (server_name, delay_max), (client_name, client_args) = server, client
    log = master.workdir / f"server-{len(master.processes)}.jsonl"
    server_process = master.start_python(
        THIS_SCRIPT,
        "--role",
        "server",
        "--log",
        str(log),
        "--delay-max",
        str(delay_max),
        label="bench_server",
    )
    try:
        master.wait_for_action_server(f"/{ACTION}", timeout=30)
        process = master.start_python(THIS_SCRIPT, *client_args, label="bench_client")
        status = process.wait(timeout=CLIENT_TIMEOUT)
        reply = turnaround.last_json_line(process.output())
        if status != 0 or not reply:
            raise RuntimeError(f"{client_name} failed ({status}):\n{process.output()[-3000:]}")
    finally:
        server_process.stop()
    return turnaround.from_server_log(log, client_name, reply, server_name)


def turnaround_rows(goals: int) -> list[tuple[turnaround.Turnaround, turnaround.Turnaround]]:
    """Each measurement paired with the baseline measured against the same server."""
    n = ["--goals", str(goals)]

    def navseq_client(tick: float, settle: float) -> tuple[str, list[str]]:
        name = f"navseq, tick {tick:g} s, settle " + (f"{settle:g} s" if settle else "off")
        return name, ["--role", "navseq", *n, "--tick", str(tick), "--settle", str(settle)]

    # Before/after the settle that keeps clear of move_base's SUCCEEDED race (#949).
    navseq = [
        navseq_client(DEFAULT_TICK, 0.0),
        navseq_client(DEFAULT_TICK, DEFAULT_SETTLE),
        navseq_client(DEFAULT_TICK / 10, DEFAULT_SETTLE),
    ]
    baseline = ("SimpleActionClient loop", ["--role", "baseline", *n])
    servers = [("at once", 0.0), (f"after U(0, {RANDOM_DELAY:g}) s", RANDOM_DELAY)]
    rows = []
    with running_master() as master:
        for server in servers:
            # The 10x shorter tick only matters for the first server: skip it for the second.
            clients = navseq if server[1] == 0 else navseq[:2]
            base = measure_turnaround(master, server, baseline)
            rows += [(measure_turnaround(master, server, client), base) for client in clients]
            rows.append((base, base))
    return rows


def turnaround_table(goals: int) -> Table:
    made = turnaround.table(
        "Goal turnaround over actionlib (server clock: result n sent -> goal n+1 received)",
        first=("server succeeds",),
    )
    for row, base in turnaround_rows(goals):
        made.add_row(row.server, *row.cells(base))
    return made


# ---------------------------------------------------------------------------------------
# Part 2: mission time over the sim nodes vs the lower bound
# ---------------------------------------------------------------------------------------


@dataclasses.dataclass
class MissionRun:
    variant: str
    success: bool
    mission_s: float  # simulated
    wall_s: float


@contextlib.contextmanager
def sim_nodes(master: RosMaster, mission: Mission, speed: float) -> Iterator[None]:
    """The sim robot (owning /clock at ``speed``) and the move_base stand-in, until exit."""
    assert mission.start is not None and mission.map is not None
    master.set_param("/use_sim_time", True)
    start = mission.start
    robot = master.start(
        [
            REPO_ROOT / "nodes" / "sim_robot_node",
            f"_map:={mission.map}",
            f"_x:={start.x}",
            f"_y:={start.y}",
            f"_yaw:={start.yaw}",
            f"_speed:={speed}",
        ],
        label="sim_robot",
    )
    nav = master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={mission.map}"], label="move_base"
    )
    try:
        master.wait_for_action_server(f"/{ACTION}", timeout=60)
        master.wait_for_service(f"/{ACTION}/make_plan", timeout=30)
        yield
    finally:
        nav.stop()
        robot.stop()


def make_plan_lengths(master: RosMaster, points: list[tuple[float, float]]) -> list[float]:
    legs = [[*a, *b] for a, b in itertools.pairwise(points)]
    caller = master.start_python(
        THIS_SCRIPT, "--role", "plan", "--legs", json.dumps(legs), label="make_plan"
    )
    status = caller.wait(timeout=CLIENT_TIMEOUT)
    reply = turnaround.last_json_line(caller.output())
    if status != 0 or "lengths" not in reply:
        raise RuntimeError(f"make_plan calls failed ({status}):\n{caller.output()[-3000:]}")
    return [float(length) for length in reply["lengths"]]


def journal_mission_time(journal: Path) -> tuple[float, bool]:
    """(simulated s from MissionStarted to MissionFinished, success) from a run's journal."""
    events = [json.loads(line) for line in journal.read_text().splitlines() if line.strip()]
    started = next(e["t"] for e in events if e.get("type") == "MissionStarted")
    finished = next(e for e in events if e.get("type") == "MissionFinished")
    return finished["t"] - started, bool(finished["success"])


def run_cli_mission(master: RosMaster, variant: str, mission_file: Path) -> MissionRun:
    out = master.workdir / f"out-{len(master.processes)}"
    began = time.monotonic()
    process = master.start(
        [NAVSEQ, "run", mission_file, "--navigator", "ros1", "--json", "--out", out],
        cwd=master.workdir,
        label="navseq-run",
    )
    status = process.wait(timeout=CLIENT_TIMEOUT * 2)
    wall = time.monotonic() - began
    journal = out / "journal.jsonl"
    if not journal.exists():
        raise RuntimeError(f"navseq run wrote no journal ({status}):\n{process.output()[-3000:]}")
    simulated, success = journal_mission_time(journal)
    return MissionRun(variant, success and status == 0, simulated, wall)


def mission_table(speed: float) -> Table:
    # Imported here: the ROS roles of this script need none of the simulator's weight.
    from bench_sim import lower_bound, with_pass_through  # same folder as this script

    from navseq.navigators.sim import SimNavigator

    mission = load_mission(EXAMPLE)
    assert mission.start is not None and mission.map is not None
    variants = [
        ("stop at every waypoint", with_pass_through(mission, None)),
        (f"pass through ({PASS_THROUGH:g} m)", with_pass_through(mission, PASS_THROUGH)),
    ]
    points = [(mission.start.x, mission.start.y)] + [(w.x, w.y) for w in mission.waypoints]
    max_v = DiffDriveLimits().max_v

    free_path_bound = lower_bound(mission, SimNavigator.from_map(mission.map, mission.start))
    plan_bound = 0.0
    runs: list[MissionRun] = []
    with tempfile.TemporaryDirectory(prefix="navseq-bench-") as folder:
        for index, (name, variant) in enumerate(variants):
            mission_file = Path(folder) / f"variant{index}.yaml"
            write_mission(variant, mission_file)
            # A fresh master and sim for each run: same start pose, /clock from zero.
            with running_master() as master, sim_nodes(master, mission, speed):
                if index == 0:
                    plan_bound = sum(make_plan_lengths(master, points)) / max_v
                runs.append(run_cli_mission(master, name, mission_file))

    table = Table(
        title=f"{EXAMPLE.name} via `navseq run --navigator ros1` on the sim nodes "
        f"(/clock at {speed:g}x)"
    )
    for column in (
        "variant",
        "reached all",
        "mission s (sim)",
        "bound make_plan s",
        "ratio",
        "bound free path s",
        "ratio",
        "wall s",
        "sim s / wall s",
    ):
        table.add_column(column, justify="right")
    for run in runs:
        table.add_row(
            run.variant,
            "yes" if run.success else "NO",
            f"{run.mission_s:.1f}",
            f"{plan_bound:.1f}",
            f"{run.mission_s / plan_bound:.3f}",
            f"{free_path_bound:.1f}",
            f"{run.mission_s / free_path_bound:.3f}",
            f"{run.wall_s:.1f}",
            f"{run.mission_s / run.wall_s:.1f}",
        )
    return table


# ---------------------------------------------------------------------------------------


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals", type=int, default=200, help="goals per turnaround client")
    parser.add_argument(
        "--speed", type=float, default=10.0, help="sim time / wall time of the sim nodes' /clock"
    )
    parser.add_argument("--skip-turnaround", action="store_true")
    parser.add_argument("--skip-mission", action="store_true")
    # Internal: this script also plays each ROS process of the benchmark.
    parser.add_argument(
        "--role", choices=("server", "navseq", "baseline", "plan"), help=argparse.SUPPRESS
    )
    parser.add_argument("--log", help=argparse.SUPPRESS)
    parser.add_argument("--delay-max", type=float, default=0.0, help=argparse.SUPPRESS)
    parser.add_argument("--tick", type=float, default=DEFAULT_TICK, help=argparse.SUPPRESS)
    parser.add_argument("--settle", type=float, default=DEFAULT_SETTLE, help=argparse.SUPPRESS)
    parser.add_argument("--legs", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.role:
        run_role(args)
        return
    if args.goals < 2:
        parser.error("--goals must be at least 2 (turnaround is between two goals)")

    console = Console(width=150)
    began = time.monotonic()
    if not args.skip_turnaround:
        console.print(turnaround_table(args.goals))
    if not args.skip_mission:
        console.print(mission_table(args.speed))
    console.print(f"total wall time {time.monotonic() - began:.0f} s")


if __name__ == "__main__":
    main()
