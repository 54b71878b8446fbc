"""Two ways to pass through waypoints on the real Nav2, side by side.

Run:  .venv/bin/python benchmarks/bench_nav2_pass_modes.py [--runs 10]

Issue 16 asked which way of not stopping at intermediate waypoints navseq should take on
Nav2: **preempt** (navseq's way: within the waypoint's radius, send the next
``navigate_to_pose`` goal, which Nav2 takes over from the running one) or **through-poses**
(send the remaining waypoints as one ``navigate_through_poses`` goal and let Nav2 pass
them). Both drive the same five waypoints around the TurtleBot3 arena's pillars from the
same start, the last one a stop, ``--runs`` times each, alternating, on the real Nav2 Jazzy
on its loopback simulator (``tests/nav2_real_support.py``), robot put back at the start
before every run:

- **preempt**: ``navseq run --navigator nav2``, ``pass_through: 0.4``, ``retries: 2``;
  the time is the journal's MissionStarted .. MissionFinished (Nav2's clock);
- **through-poses**: a plain rclpy client sending one ``NavigateThroughPoses`` goal with
  the five poses; the time is from sending to the result (Nav2's clock); a via pose
  counts as passed when Nav2's feedback ``number_of_poses_remaining`` drops.
- **closed tour, through-poses**: the same with the start pose appended as the last
  pose (a patrol back home), once per run: what Nav2 does with a tour that ends where
  the robot stands.

Where no real Nav2 is found it says so and exits 0. Every process is a subprocess on a
private ``ROS_DOMAIN_ID`` with discovery on the loopback.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import tempfile
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

REPO_ROOT = Path(__file__).resolve().parents[1]
THIS_SCRIPT = Path(__file__).resolve()
sys.path.insert(0, str(REPO_ROOT / "tests"))

from nav2_real_support import RealNav2, nav2_missing_reason  # noqa: E402

MAP = REPO_ROOT / "maps" / "turtlebot3_world.yaml"
START = (-2.0, -0.5, 0.0)  # x, y, yaw degrees
WAYPOINTS: tuple[tuple[float, float, float], ...] = (
    (-0.55, -1.75, 0.0),
    (0.55, -0.55, 90.0),
    (0.55, 0.55, 180.0),
    (-0.55, 0.55, 180.0),
    (-1.75, 0.55, -90.0),
)
RADIUS = 0.4
RUN_TIMEOUT = 300.0


@dataclass
class Outcome:
    """One run: did it complete, how long it took (Nav2's clock), and what it said."""

    mode: str
    completed: bool
    seconds: float | None
    detail: str = ""
    false_successes: int = 0
    passed_at: list[float] = field(default_factory=list)  # s when each via was passed


def role_through(closed: bool) -> int:
    """One ``navigate_through_poses`` goal; prints the outcome as one JSON line."""
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from nav2_msgs.action import NavigateThroughPoses
    from rclpy.action import ActionClient

    rclpy.init()
    node = rclpy.create_node("bench_through_poses")
    node.set_parameters([rclpy.parameter.Parameter("use_sim_time", value=True)])
    client = ActionClient(node, NavigateThroughPoses, "navigate_through_poses")
    if not client.wait_for_server(timeout_sec=30):
        print(json.dumps({"completed": False, "detail": "no navigate_through_poses server"}))
        return 1
    goal = NavigateThroughPoses.Goal()
    for x, y, yaw in WAYPOINTS + ((START,) if closed else ()):
        pose = PoseStamped()
        pose.header.frame_id = "map"
        pose.pose.position.x, pose.pose.position.y = x, y
        pose.pose.orientation.z = math.sin(math.radians(yaw) / 2)
        pose.pose.orientation.w = math.cos(math.radians(yaw) / 2)
        goal.poses.append(pose)

    def now() -> float:
        return float(node.get_clock().now().nanoseconds) * 1e-9

    while now() <= 0.0:  # a valid /clock first
        rclpy.spin_once(node, timeout_sec=0.05)
    remaining: list[tuple[float, int]] = []
    started = now()

    def on_feedback(message: Any) -> None:
        left = int(message.feedback.number_of_poses_remaining)
        if not remaining or remaining[-1][1] != left:
            remaining.append((now() - started, left))

    sent = client.send_goal_async(goal, feedback_callback=on_feedback)
    rclpy.spin_until_future_complete(node, sent, timeout_sec=30)
    handle = sent.result()
    if handle is None or not handle.accepted:
        print(json.dumps({"completed": False, "detail": "rejected"}))
        return 1
    result = handle.get_result_async()
    rclpy.spin_until_future_complete(node, result, timeout_sec=RUN_TIMEOUT)
    answer = result.result()
    elapsed = now() - started
    status = {4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}.get(answer.status, str(answer.status))
    text = f"{status} {answer.result.error_code} {answer.result.error_msg}".strip()
    passed = [t for t, _left in remaining[1:]]
    print(json.dumps({"completed": status == "SUCCEEDED", "seconds": elapsed, "detail": text,
                      "passed_at": passed}))  # fmt: skip
    return 0


def through_poses(nav2: RealNav2, closed: bool) -> Outcome:
    mode = "closed tour, through-poses" if closed else "through-poses"
    args = [sys.executable, str(THIS_SCRIPT), "--role", "closed" if closed else "through"]
    done = subprocess.run(args, env=nav2.env, capture_output=True, text=True, timeout=400)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if not lines:
        return Outcome(mode, False, None, f"no answer: {done.stderr[-300:]}")
    found = json.loads(lines[-1])
    return Outcome(
        mode, found["completed"], found.get("seconds"), found.get("detail", ""),
        passed_at=found.get("passed_at", []),
    )  # fmt: skip


def preempt(nav2: RealNav2, workdir: Path, number: int) -> Outcome:
    points = "".join(
        f"  - {{name: p{i + 1}, x: {x}, y: {y}, yaw: {yaw}}}\n"
        for i, (x, y, yaw) in enumerate(WAYPOINTS)
    )
    mission = workdir / "preempt.yaml"
    mission.write_text(
        "navseq: 1\nframe: map\n"
        f"defaults: {{retries: 2, on_failure: stop, pass_through: {RADIUS}}}\n"
        f"waypoints:\n{points}"
    )
    out = workdir / f"preempt-{number}"
    navseq = str(Path(sys.executable).with_name("navseq"))
    done = subprocess.run(
        [navseq, "run", str(mission), "--navigator", "nav2", "--out", str(out)],
        env=nav2.env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
    )
    events = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    events = [e for e in events if e.get("kind") == "event"]
    times = {e["type"]: e["t"] for e in events if e["type"] in ("MissionStarted",)}
    finished = [e for e in events if e["type"] == "MissionFinished"]
    seconds = finished[-1]["t"] - times["MissionStarted"] if finished else None
    passes = [
        e["t"] - times["MissionStarted"]
        for e in events
        if e["type"] == "WaypointFinished" and e.get("passed_through")
    ]
    false = sum(
        1
        for e in events
        if e["type"] == "AttemptFailed" and str(e["reason"]).startswith("succeeded far")
    )
    detail = f"exit {done.returncode}" + (f", {false} false success(es) caught" if false else "")
    return Outcome("preempt (navseq)", done.returncode == 0, seconds, detail, false, passes)


def table(outcomes: list[Outcome]) -> Table:
    result = Table(title="Passing through 4 waypoints to a 5th on the real Nav2")
    columns = ("mode", "completed", "mean s", "min s", "max s", "poses passed", "false successes")
    for column in (*columns, "failures"):
        result.add_column(column)
    for mode in dict.fromkeys(o.mode for o in outcomes):
        runs = [o for o in outcomes if o.mode == mode]
        times = [o.seconds for o in runs if o.completed and o.seconds is not None]
        failures = Counter(o.detail for o in runs if not o.completed)
        passed = [len(o.passed_at) for o in runs]
        result.add_row(
            mode,
            f"{sum(o.completed for o in runs)}/{len(runs)}",
            f"{statistics.mean(times):.1f}" if times else "-",
            f"{min(times):.1f}" if times else "-",
            f"{max(times):.1f}" if times else "-",
            f"{min(passed)}-{max(passed)}" if passed else "-",
            str(sum(o.false_successes for o in runs)),
            ", ".join(f"{count}x {detail}" for detail, count in failures.items()) or "-",
        )
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--role", choices=("through", "closed"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.role:
        return role_through(args.role == "closed")
    console = Console(width=160)
    missing = nav2_missing_reason()
    if missing is not None:
        console.print(f"bench_nav2_pass_modes: {missing}; nothing to measure")
        return 0
    outcomes: list[Outcome] = []
    with tempfile.TemporaryDirectory() as tmp, RealNav2(MAP, Path(tmp) / "logs") as nav2:
        for number in range(args.runs):
            for mode in ("preempt", "through", "closed"):
                nav2.place(*START)
                if mode == "preempt":
                    outcome = preempt(nav2, Path(tmp), number)
                else:
                    outcome = through_poses(nav2, closed=mode == "closed")
                outcomes.append(outcome)
                console.log(
                    f"{outcome.mode} run {number + 1}: completed {outcome.completed}, "
                    f"{outcome.seconds if outcome.seconds is None else round(outcome.seconds, 1)}"
                    f" s {outcome.detail}"
                )
    console.print(table(outcomes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
