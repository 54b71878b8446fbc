"""The stand-in beside the real Nav2: the same missions on both, and pass-through on Nav2.

Run:  PYTHONPATH=$PWD/src .venv/bin/python benchmarks/bench_nav2_real.py [--runs 10]
          [--only nav2|stand-in] [--json FILE] [--keep DIR]
      ... --quick   one short mission, once, on the stand-in only (the test's run)

Where no ROS 2 is found it says so and exits 0; where the real Nav2 tree is missing
(``tests/nav2_real_support.py``) it says so and runs the stand-in alone. Every ROS 2
process is a subprocess on a private ``ROS_DOMAIN_ID`` with discovery on the loopback.

Stacks, each started once and given the TurtleBot3 world and the start pose (-2, -0.5, 0°):

- **Nav2**: the real Nav2 Jazzy (bt_navigator, NavFn, Regulated Pure Pursuit, behaviours
  ...) on its loopback simulator with nav2_bringup's default parameters
  (:class:`nav2_real_support.RealNav2`), in real time;
- **stand-in**: navseq's own ``python -m navseq.ros2.sim_node`` at speed 1 (the default
  robot, the TurtleBot3 burger), so both run on a clock of the same pace.

Missions, each driven by ``navseq run MISSION --navigator nav2``, the robot put back at
the start pose before every run (``--role place``: ``/initialpose`` until ``/tf`` agrees
in position and heading, then both costmaps cleared, so that no run inherits marks from
the last one):

- **stop** and **pass**: six waypoints around the arena's pillars, ``retries: 2``,
  ``on_failure: stop``; *stop* halts at each (``pass_through: null``), *pass* passes
  within 0.4 m (the last point stops). ``--runs`` of each, alternating, so that a busier
  stretch of the machine weighs on both alike;
- **edge cases**, once each, ``retries: 0``, ``goal_timeout: 60``, ``--no-preflight``: a
  goal on a pillar's wall (an occupied cell), one in the pillar's hollow centre (unknown
  cells), one outside the map, and a reachable point in a frame nobody publishes
  (``--frame nowhere``).

Tables: completed runs, mission time (journal, the stack's clock), the pass/stop ratio,
false successes caught, every other failed attempt with Nav2's status and text, the edge
cases' results, and issue 16's bar (no visit recorded reached or passed through farther
from its point than its tolerance or radius plus 0.1 m; see ``mission_runs.py`` for how
the pose is taken). For the real Nav2 it also counts telling lines of Nav2's own log.
Exit status 1 when the bar is broken (or could not be checked), else 0.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import platform
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

REPO_ROOT = Path(__file__).resolve().parents[1]
THIS_SCRIPT = Path(__file__).resolve()
# ros2_support / nav2_real_support (where ROS 2 and Nav2 are) are shared with the tests.
sys.path.insert(0, str(REPO_ROOT / "tests"))

import mission_runs  # noqa: E402  (benchmarks/mission_runs.py: the output folders, no ROS)
from mission_runs import RunRecord  # noqa: E402

from nav2_real_support import RealNav2, nav2_missing_reason  # noqa: E402
from ros2_support import SimNode, ros2_available, ros2_environment, ros2_prefix  # noqa: E402

MAP = REPO_ROOT / "maps" / "turtlebot3_world.yaml"
START = (-2.0, -0.5, 0.0)  # x, y, yaw degrees
WAYPOINTS = (
    ("a", -0.55, -1.75),
    ("b", 0.55, -0.55),
    ("c", 0.55, 0.55),
    ("d", -0.55, 0.55),
    ("e", -1.75, 0.55),
    ("home", -2.0, -0.5),
)
PASS_RADIUS = 0.4  # m
RUN_LIMIT = 300.0  # wall s for one navseq run; then it is stopped (SIGINT) and said so
PLACE_TIMEOUT = 120.0  # wall s: the first placement waits for Nav2's bringup too
SETTLE = 1.0  # wall s after placing, before the mission starts
STACKS = ("stand-in", "nav2")
#: Lines of Nav2's log worth counting: contention and where its goals went wrong.
NAV2_LOG_LINES = {
    "BT: no ack in time": "Timed out while waiting for action server to acknowledge",
    "patience exceeded": "Controller patience exceeded",
    "RPP: collision ahead": "detected collision ahead",
    "behaviour: collision ahead": "Collision Ahead - Exiting",
    "control loop late": "Control loop missed its desired rate",
    "goal frame unknown": "Failed to transform a goal pose",
}


# ---------------------------------------------------------------------------------------
# Missions
# ---------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class MissionSpec:
    """A mission the benchmark runs, and how."""

    name: str
    waypoints: tuple[tuple[str, float, float], ...]
    policy: str  # the YAML of the mission's defaults
    runs: int
    radius_m: float | None = None
    extra: tuple[str, ...] = ()  # navseq run options
    edge: bool = False

    def yaml(self) -> str:
        points = "\n".join(
            f"  - {{name: {n}, x: {x}, y: {y}, yaw: 0}}" for n, x, y in self.waypoints
        )
        return (
            f"# bench_nav2_real.py: {self.name}\nnavseq: 1\nframe: map\nmap: {MAP}\n"
            f"defaults: {self.policy}\nwaypoints:\n{points}\n"
        )

    @property
    def slug(self) -> str:
        """A folder name: the mission's name, or an edge case's waypoint's."""
        return self.waypoints[0][0] if self.edge else self.name

    @property
    def names(self) -> list[str]:
        return [name for name, _, _ in self.waypoints]


def mission_specs(runs: int) -> list[MissionSpec]:
    """The stop and pass missions, then the edge cases."""
    stop = "{retries: 2, on_failure: stop, pass_through: null}"
    passing = f"{{retries: 2, on_failure: stop, pass_through: {PASS_RADIUS}}}"
    edge = "{retries: 0, on_failure: stop, goal_timeout: 60}"
    blind = ("--no-preflight",)

    def edge_case(name: str, point: tuple[str, float, float], *extra: str) -> MissionSpec:
        return MissionSpec(name, (point,), edge, 1, extra=(*blind, *extra), edge=True)

    return [
        MissionSpec("stop", WAYPOINTS, stop, runs),
        MissionSpec("pass", WAYPOINTS, passing, runs, radius_m=PASS_RADIUS),
        edge_case("pillar wall (1.1, 0.1)", ("wall", 1.1, 0.1)),
        edge_case("pillar hollow (1.1, 0.0)", ("hollow", 1.1, 0.0)),
        edge_case("outside the map (12, 0)", ("outside", 12.0, 0.0)),
        edge_case("frame 'nowhere' (-0.55, -1.75)", ("a", -0.55, -1.75), "--frame", "nowhere"),
    ]


def quick_spec() -> MissionSpec:
    """One short mission: pass through a, stop at b."""
    policy = f"{{retries: 2, on_failure: stop, pass_through: {PASS_RADIUS}}}"
    return MissionSpec("short", WAYPOINTS[:2], policy, 1, radius_m=PASS_RADIUS)


def run_order(specs: Sequence[MissionSpec]) -> list[tuple[MissionSpec, int]]:
    """Run i of every repeated mission in turn (stop 1, pass 1, stop 2 ...), then the rest."""
    repeated = [spec for spec in specs if not spec.edge]
    order = [
        (spec, run)
        for run in range(max((spec.runs for spec in repeated), default=0))
        for spec in repeated
        if run < spec.runs
    ]
    return order + [(spec, 0) for spec in specs if spec.edge]


# ---------------------------------------------------------------------------------------
# Role: put the robot at a pose (in the ROS 2 environment)
# ---------------------------------------------------------------------------------------


def role_place(x: float, y: float, yaw_deg: float, timeout: float) -> int:
    """Teleport the robot through ``/initialpose`` until ``/tf`` puts it there (position
    and heading: the robot may end a run on the start point facing elsewhere), wait for
    ``navigate_to_pose``, then clear both costmaps so the run starts on the map alone."""
    import rclpy

    rclpy.init()
    node = rclpy.create_node("bench_nav2_real_place")
    try:
        if not _teleport(node, x, y, math.radians(yaw_deg), timeout):
            print(f"place: not at ({x}, {y}, {yaw_deg}°) within {timeout:g} s", file=sys.stderr)
            return 1
        _clear_costmaps(node)
        print("placed", flush=True)
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def _teleport(node: Any, x: float, y: float, yaw: float, timeout: float) -> bool:
    import rclpy
    from geometry_msgs.msg import PoseWithCovarianceStamped
    from nav2_msgs.action import NavigateToPose
    from rclpy.action import ActionClient
    from tf2_msgs.msg import TFMessage

    from navseq.geometry import FrameTree, normalize_angle
    from navseq.ros2.messages import add_transforms

    tree = FrameTree()
    publisher = node.create_publisher(PoseWithCovarianceStamped, "/initialpose", 10)
    node.create_subscription(TFMessage, "/tf", lambda m: add_transforms(tree, m), 100)
    client = ActionClient(node, NavigateToPose, "navigate_to_pose")
    deadline, sent = time.monotonic() + timeout, -math.inf
    while time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.05)
        pose = tree.lookup("map", "base_footprint")
        there = (
            pose is not None
            and math.hypot(pose.x - x, pose.y - y) < 0.02
            and abs(normalize_angle(pose.yaw - yaw)) < math.radians(1.0)
        )
        if there and client.server_is_ready():
            return True
        if not there and time.monotonic() - sent > 1.0:
            message = PoseWithCovarianceStamped()
            message.header.frame_id = "map"
            message.pose.pose.position.x, message.pose.pose.position.y = x, y
            message.pose.pose.orientation.z = math.sin(yaw / 2)
            message.pose.pose.orientation.w = math.cos(yaw / 2)
            publisher.publish(message)
            sent = time.monotonic()
    return False


def _clear_costmaps(node: Any, wait: float = 5.0) -> None:
    """Both of Nav2's clear-entirely services; one that is not there is skipped."""
    import rclpy
    from nav2_msgs.srv import ClearEntireCostmap

    for name in (
        "global_costmap/clear_entirely_global_costmap",
        "local_costmap/clear_entirely_local_costmap",
    ):
        client = node.create_client(ClearEntireCostmap, name)
        if client.wait_for_service(timeout_sec=wait):
            future = client.call_async(ClearEntireCostmap.Request())
            rclpy.spin_until_future_complete(node, future, timeout_sec=wait)


# ---------------------------------------------------------------------------------------
# Stacks and runs
# ---------------------------------------------------------------------------------------


@dataclasses.dataclass
class StackHandle:
    """A running stack: the environment of its clients and, for Nav2, its log."""

    name: str
    env: dict[str, str]
    log_path: Path | None = None

    def log_mark(self) -> int:
        return self.log_path.stat().st_size if self.log_path is not None else 0

    def log_counts(self, mark: int) -> dict[str, int]:
        """How often each of :data:`NAV2_LOG_LINES` appeared in the log since ``mark``."""
        if self.log_path is None:
            return {}
        with self.log_path.open("rb") as log:
            log.seek(mark)
            text = log.read().decode(errors="replace")
        return {label: text.count(needle) for label, needle in NAV2_LOG_LINES.items()}


@contextmanager
def started(stack: str, workdir: Path, speed: float) -> Iterator[StackHandle]:
    """The stack running for the block, stopped after it (every process it started)."""
    if stack == "nav2":
        nav2 = RealNav2(MAP, workdir / "nav2-logs")
        try:
            yield StackHandle(stack, nav2.env, nav2.log_path)
        finally:
            nav2.stop()
        return
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    x, y, yaw = START
    # --initial-pose teleport: role_place puts the robot back at the start between runs
    # through /initialpose, as Nav2's loopback simulator takes it.
    sim = SimNode(
        env,
        "--map",
        str(MAP),
        f"--start={x},{y},{yaw}",
        "--speed",
        f"{speed:g}",
        "--initial-pose",
        "teleport",
    )
    try:
        yield StackHandle(stack, env)
    finally:
        sim.stop()


def place(handle: StackHandle, timeout: float) -> None:
    """The robot at the start pose, costmaps cleared; RuntimeError if it cannot be."""
    x, y, yaw = START
    argv = [sys.executable, str(THIS_SCRIPT), "--role", "place", f"--pose={x},{y},{yaw}"]
    try:
        done = subprocess.run(
            [*argv, "--timeout", str(timeout)],
            env=handle.env,
            capture_output=True,
            text=True,
            timeout=timeout + 60,
        )
    except subprocess.TimeoutExpired as expired:
        raise RuntimeError(f"{handle.name}: placing the robot hung") from expired
    if done.returncode != 0:
        raise RuntimeError(f"{handle.name}: placing the robot failed:\n{done.stderr[-2000:]}")
    time.sleep(SETTLE)


def navseq_run(
    env: dict[str, str], mission: Path, out: Path, extra: Sequence[str], limit: float
) -> tuple[int, float, str]:
    """``navseq run MISSION --navigator nav2``: (exit status, wall s, note)."""
    argv = [sys.executable, "-m", "navseq", "run", str(mission), "--navigator", "nav2"]
    process = subprocess.Popen(
        [*argv, "--out", str(out), *extra],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    began = time.monotonic()
    note = ""
    try:
        _, err = process.communicate(timeout=limit)
    except subprocess.TimeoutExpired:
        process.send_signal(signal.SIGINT)  # navseq cancels the goal and writes its report
        note = f"stopped by the benchmark after {limit:g} s"
        try:
            _, err = process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            _, err = process.communicate()
    wall = time.monotonic() - began
    if process.returncode == 2 and not note:
        note = err.strip().splitlines()[-1] if err.strip() else "exit 2"
    return process.returncode, wall, note


def run_one(
    handle: StackHandle, spec: MissionSpec, run: int, workdir: Path, first: bool
) -> RunRecord:
    """Place the robot, run the mission once, read what it left."""
    place(handle, PLACE_TIMEOUT if first else 60.0)
    folder = workdir / handle.name / f"{spec.slug}-{run + 1}"
    mission = folder.with_suffix(".yaml")
    mission.parent.mkdir(parents=True, exist_ok=True)
    mission.write_text(spec.yaml(), encoding="utf-8")
    mark = handle.log_mark()
    code, wall, note = navseq_run(handle.env, mission, folder, spec.extra, RUN_LIMIT)
    record = RunRecord(handle.name, spec.name, run, code, wall, note=note, edge=spec.edge)
    record.nav2_log = handle.log_counts(mark)
    return mission_runs.read_run(folder, record, spec.radius_m, spec.names)


def run_stack(
    stack: str,
    specs: Sequence[MissionSpec],
    workdir: Path,
    speed: float,
    say: Callable[[str], None],
) -> list[RunRecord]:
    """Every run of ``specs`` on one stack. A robot that cannot be placed (the stack
    died or hangs) ends this stack's runs: the tables show what was measured before."""
    records: list[RunRecord] = []
    with started(stack, workdir, speed) as handle:
        for spec, run in run_order(specs):
            try:
                record = run_one(handle, spec, run, workdir, first=not records)
            except RuntimeError as error:
                say(f"{stack}: stopped before {spec.name} run {run + 1}: {error}")
                break
            records.append(record)
            took = "-" if record.mission_s is None else f"{record.mission_s:.1f} s"
            say(
                f"{stack} {spec.name} run {run + 1}: exit {record.exit_code}, mission {took}, "
                f"{len(record.failures)} failed attempt(s) {record.note}"
            )
    return records


# ---------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------


def _mean(values: Sequence[float]) -> float | None:
    return statistics.fmean(values) if values else None


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"


def _times(records: Sequence[RunRecord]) -> list[float]:
    """Mission times of the completed runs (a stopped mission's time is not comparable)."""
    return [r.mission_s for r in records if r.completed and r.mission_s is not None]


def _groups(records: Sequence[RunRecord]) -> dict[tuple[str, str], list[RunRecord]]:
    groups: dict[tuple[str, str], list[RunRecord]] = {}
    for record in records:
        groups.setdefault((record.stack, record.mission), []).append(record)
    return groups


def missions_table(records: Sequence[RunRecord]) -> Table:
    table = Table(title="Same missions on both stacks (mission time: journal, the stack's clock)")
    for column in ("stack", "mission", "completed", "mean s", "max s", "pass/stop"):
        table.add_column(column, justify="right")
    for column in ("false successes caught", "other failed attempts", "recoveries", "wall s"):
        table.add_column(column, justify="right")
    groups = _groups([r for r in records if not r.edge])
    for (stack, mission), runs in groups.items():
        times = _times(runs)
        false = [f for r in runs for f in r.failures if f.false_success]
        after = Counter(outcome for r in runs for outcome in r.after_false_success)
        then = ", ".join(f"{n} {outcome}" for outcome, n in after.items())
        table.add_row(
            stack,
            mission,
            f"{sum(r.completed for r in runs)}/{len(runs)}",
            _seconds(_mean(times)),
            _seconds(max(times, default=None)),
            _ratio(groups, stack) if mission == "pass" else "",
            f"{len(false)}" + (f" (then {then})" if then else ""),
            str(sum(len(r.failures) for r in runs) - len(false)),
            str(sum(r.recoveries for r in runs)),
            _seconds(_mean([r.wall_s for r in runs])),
        )
    return table


def _ratio(groups: dict[tuple[str, str], list[RunRecord]], stack: str) -> str:
    """Mean pass mission time over mean stop mission time, completed runs only."""
    stop = _mean(_times(groups.get((stack, "stop"), [])))
    passing = _mean(_times(groups.get((stack, "pass"), [])))
    if stop is None or passing is None:
        return "-"
    return f"{passing / stop:.2f}"


def failures_table(records: Sequence[RunRecord]) -> Table:
    table = Table(title="Failed attempts by status and text")
    for column in ("stack", "mission", "status: text", "attempts", "runs"):
        table.add_column(column, justify="right" if column in ("attempts", "runs") else "left")
    for (stack, mission), runs in _groups([r for r in records if not r.edge]).items():
        kinds = Counter(f.kind() for r in runs for f in r.failures)
        in_runs = Counter(kind for r in runs for kind in {f.kind() for f in r.failures})
        for kind, count in kinds.most_common():
            table.add_row(stack, mission, kind, str(count), f"{in_runs[kind]}/{len(runs)}")
        if not kinds:
            table.add_row(stack, mission, "(none)", "0", f"0/{len(runs)}")
    return table


def edge_table(records: Sequence[RunRecord]) -> Table:
    table = Table(title="Edge cases, one run each (retries 0, goal_timeout 60 s, --no-preflight)")
    for column in ("case", "stack", "exit", "outcome", "status", "text", "s to result"):
        table.add_column(column, justify="right" if column in ("exit", "s to result") else "left")
    for record in (r for r in records if r.edge):
        first = record.first
        table.add_row(
            record.mission,
            record.stack,
            str(record.exit_code),
            first.outcome if first else "-",
            first.status if first else "-",
            (first.text if first else "") or record.note or "-",
            _seconds(first.seconds if first else None),
        )
    return table


def bar_table(records: Sequence[RunRecord]) -> tuple[Table, bool]:
    """Issue 16's bar per stack and mission, and whether it held everywhere."""
    table = Table(title="Issue 16's bar: visits recorded reached vs tolerance or radius + 0.1 m")
    for column in ("stack", "mission", "visits", "over the bar"):
        table.add_column(column, justify="left" if column in ("stack", "mission") else "right")
    for column in ("worst stop m (bar)", "at", "worst pass-through m (bar)", "at"):
        table.add_column(column, justify="left" if column == "at" else "right")
    table.add_column("pose Δt max s", justify="right")
    held = True
    for (stack, mission), runs in _groups([r for r in records if not r.edge]).items():
        unchecked = [r for r in runs if r.tolerance_m is None and r.mission_s is not None]
        checks = [(r.run, c) for r in runs for c in r.arrivals]
        over = [c for _, c in checks if c.over]
        held = held and not over and not unchecked
        table.add_row(
            stack,
            mission,
            str(len(checks)) + (f" ({len(unchecked)} runs unchecked)" if unchecked else ""),
            str(len(over)),
            *_worst([rc for rc in checks if not rc[1].passed_through]),
            *_worst([rc for rc in checks if rc[1].passed_through]),
            f"{max((c.pose_dt_s for _, c in checks), default=0.0):.2f}",
        )
    return table, held


def _worst(checks: Sequence[tuple[int, mission_runs.ArrivalCheck]]) -> tuple[str, str]:
    """The farthest of ``checks`` from its point, with its bar, and where it was."""
    if not checks:
        return "-", "-"
    run, check = max(checks, key=lambda rc: rc[1].distance_m)
    return f"{check.distance_m:.3f} ({check.bound_m:.2f})", f"{check.waypoint}, run {run + 1}"


def nav2_log_table(records: Sequence[RunRecord]) -> Table | None:
    rows = [(k, runs) for k, runs in _groups(records).items() if any(r.nav2_log for r in runs)]
    if not rows:
        return None
    table = Table(title="Lines of Nav2's own log during the runs")
    table.add_column("mission")
    for label in NAV2_LOG_LINES:
        table.add_column(label, justify="right")
    for (_, mission), runs in rows:
        table.add_row(
            mission, *(str(sum(r.nav2_log.get(label, 0) for r in runs)) for label in NAV2_LOG_LINES)
        )
    return table


def robots(records: Sequence[RunRecord]) -> list[str]:
    """Each stack's robot as navseq read it from the stack's parameters (its stderr note)."""
    seen: dict[str, str] = {}
    for record in records:
        if record.robot and record.stack not in seen:
            seen[record.stack] = record.robot
    return [f"{stack}: {robot}" for stack, robot in seen.items()]


def machine() -> str:
    model = "?"
    with open("/proc/cpuinfo", encoding="utf-8") as cpuinfo:
        for line in cpuinfo:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    load = ", ".join(f"{value:.2f}" for value in os.getloadavg())
    return (
        f"{os.cpu_count()} cores ({model}), {platform.system()} {platform.release()}, load {load}"
    )


# ---------------------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------------------


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=["place"])
    parser.add_argument("--pose", default="-2,-0.5,0")
    parser.add_argument("--timeout", type=float, default=PLACE_TIMEOUT)
    parser.add_argument("--runs", type=int, default=10, help="runs of each of stop and pass")
    parser.add_argument("--only", choices=STACKS, help="one stack only")
    parser.add_argument("--quick", action="store_true", help="a short mission once, stand-in only")
    parser.add_argument("--json", type=Path, metavar="FILE", help="every run's record as JSON")
    parser.add_argument("--keep", type=Path, metavar="DIR", help="keep the runs' folders here")
    return parser.parse_args()


def print_tables(console: Console, records: Sequence[RunRecord]) -> bool:
    console.print(missions_table(records))
    for line in robots(records):
        console.print(f"  robot {line}")
    console.print(failures_table(records))
    if any(r.edge for r in records):
        console.print(edge_table(records))
    table, held = bar_table(records)
    console.print(table)
    console.print(
        "  The journal keeps no pose with WaypointFinished: each visit is judged on the "
        "WaypointProgress pose nearest in time (Δt above), the pose navseq itself had."
    )
    console.print(f"  Issue 16's bar: {'held' if held else 'BROKEN (or not checked)'}.")
    log_table = nav2_log_table(records)
    if log_table is not None:
        console.print(log_table)
    return held


def main() -> int:
    args = parse_args()
    if args.role == "place":
        x, y, yaw = (float(part) for part in args.pose.split(","))
        return role_place(x, y, yaw, args.timeout)
    available, why = ros2_available()
    if not available:
        print(f"bench_nav2_real: skipped, no usable ROS 2: {why}")
        return 0
    stacks = ["stand-in"] if args.quick else [args.only] if args.only else list(STACKS)
    missing = nav2_missing_reason()
    if "nav2" in stacks and missing:
        print(f"bench_nav2_real: the real Nav2 is skipped: {missing}")
        stacks.remove("nav2")
    if not stacks:
        return 0
    specs = [quick_spec()] if args.quick else mission_specs(args.runs)
    speed = 4.0 if args.quick else 1.0
    console = Console(width=160)
    log = Console(stderr=True)
    console.print(
        f"bench_nav2_real {' '.join(sys.argv[1:])}: {time.strftime('%Y-%m-%d %H:%M')}, {machine()}"
    )
    with tempfile.TemporaryDirectory(prefix="bench_nav2_real-") as folder:
        workdir = args.keep or Path(folder)
        records = [r for stack in stacks for r in run_stack(stack, specs, workdir, speed, log.log)]
    load = ", ".join(f"{value:.2f}" for value in os.getloadavg())
    console.print(f"  finished {time.strftime('%H:%M')}, load {load}")
    held = print_tables(console, records)
    if args.json:
        args.json.write_text(json.dumps([dataclasses.asdict(r) for r in records], indent=1) + "\n")
    return 0 if held else 1


if __name__ == "__main__":
    sys.exit(main())
