"""The Nav2 stand-in's own speed: its real-time factor with 1 and 10 robots, and a goal's
round trip beside a plain rclpy action server (issue 20).

Run:  PYTHONPATH=$PWD/src .venv/bin/python benchmarks/bench_standin.py
          [--robots 1,10] [--speeds 10,100] [--seconds 10] [--rounds 50]

Where no ROS 2 is found it says so and exits 0. Every ROS 2 process is a subprocess on a
private ``ROS_DOMAIN_ID`` with discovery on the loopback (``tests/ros2_support.py``);
the clients are ``tests/nav2/clock_rate.py`` and ``tests/nav2/goal_latency.py``.

- **Real-time factor**: N stand-ins (``python -m navseq.ros2.sim_node``) on the
  TurtleBot3 arena, namespaced ``robot1`` ... ``robotN`` and each given all the others
  with ``--other-robots`` (so each hears every other robot's ``/robotK/tf`` and keeps
  their footprints in its costmap and scan), standing on free lanes, no goal running.
  ``robot1`` steps at the requested ``--speed`` and publishes ``/clock``; the others
  follow it (``--follow-clock``), as a fleet faster than real time runs. Measured over
  ``--seconds`` wall seconds: simulated seconds per wall second of ``/clock`` and of the
  slowest robot's ``odom`` stamps (a follower that cannot keep up lags there).
- **Goal round trip**: ``navigate_to_pose`` goals at the pose the robot already stands
  on, alternating between the stand-in (speed 1, as under RViz) and a plain rclpy
  ``ActionServer`` that accepts and succeeds at once (``tests/nav2/instant_nav_server.py``),
  in the same run: wall ms from ``send_goal`` to accepted and to the result (median and
  90th percentile of ``--rounds`` each, after one warm-up round).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import threading
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

REPO_ROOT = Path(__file__).resolve().parents[1]
# ros2_support (where ROS 2 is, the sim node as a subprocess) is shared with the tests.
sys.path.insert(0, str(REPO_ROOT / "tests"))

from ros2_support import SimNode, ros2_available, ros2_environment, ros2_prefix  # noqa: E402

MAP = REPO_ROOT / "maps" / "turtlebot3_world.yaml"
CLIENTS = REPO_ROOT / "tests" / "nav2"
START = (-2.0, -0.5)
# Free spots of the arena (its pillars stand on a 1.1 m grid around the origin), one per
# robot, at least 0.5 m apart.
SPOTS = [
    START,
    (-2.0, 0.5),
    (-1.65, -0.55),
    (-0.55, 0.55),
    (-0.55, -0.55),
    (0.55, 0.55),
    (0.55, -0.55),
    (1.65, 0.55),
    (1.65, -0.55),
    (2.0, 0.0),
]


def _ints(text: str) -> list[int]:
    return [int(part) for part in text.split(",") if part]


def _floats(text: str) -> list[float]:
    return [float(part) for part in text.split(",") if part]


@contextmanager
def fleet(env: dict[str, str], robots: int, speed: float) -> Iterator[list[SimNode]]:
    """``robots`` stand-ins that see each other, started at once, stopped at the end."""
    names = [f"robot{index + 1}" for index in range(robots)]

    def start(index: int) -> SimNode:
        x, y = SPOTS[index]
        args = ["--map", str(MAP), f"--start={x},{y},0"]
        if robots > 1:
            others = ",".join(name for name in names if name != names[index])
            args += ["--ns", names[index], "--other-robots", others]
        args += ["--speed", f"{speed:g}"] if index == 0 else ["--follow-clock"]
        return SimNode(env, *args)

    with ThreadPoolExecutor(max_workers=robots) as pool:
        futures = [pool.submit(start, index) for index in range(robots)]
        nodes = [future.result() for future in futures]
    try:
        yield nodes
    finally:
        for node in nodes:
            node.stop()


def real_time_factor(env: dict[str, str], robots: int, speed: float, seconds: float) -> dict:
    with fleet(env, robots, speed):
        prefix = "" if robots == 1 else "/robot{}"
        topics = [f"{prefix.format(index + 1)}/odom" for index in range(robots)]
        done = subprocess.run(
            [sys.executable, str(CLIENTS / "clock_rate.py"), "--seconds", str(seconds), *topics],
            env=env,
            capture_output=True,
            text=True,
            timeout=seconds + 120,
        )
    if done.returncode != 0:
        raise SystemExit(f"clock_rate.py failed: {done.stderr[-2000:]}")
    measured = json.loads(done.stdout.strip().splitlines()[-1])
    odom = [rate for rate in measured["odom"].values() if rate is not None]
    return {
        "clock": measured["clock"],
        "slowest": min(odom) if len(odom) == robots else None,
    }


@contextmanager
def instant_server(env: dict[str, str]) -> Iterator[None]:
    process = subprocess.Popen(
        [sys.executable, str(CLIENTS / "instant_nav_server.py")],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    ready = threading.Event()

    def read() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            if "ready" in line:
                ready.set()

    threading.Thread(target=read, daemon=True).start()
    try:
        if not ready.wait(60):
            raise SystemExit("instant_nav_server.py did not start")
        yield
    finally:
        process.terminate()
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def round_trips(env: dict[str, str], rounds: int) -> dict[str, Any]:
    with fleet(env, 1, 1.0), instant_server(env):
        done = subprocess.run(
            [
                sys.executable,
                str(CLIENTS / "goal_latency.py"),
                "--rounds",
                str(rounds),
                "--",  # the pose starts with a minus: not an option
                f"{START[0]},{START[1]},0",
                "/navigate_to_pose",
                "/instant/navigate_to_pose",
            ],
            env=env,
            capture_output=True,
            text=True,
            timeout=600,
        )
    if done.returncode != 0:
        raise SystemExit(f"goal_latency.py failed: {done.stderr[-2000:]}")
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def _ms(values: Sequence[float]) -> str:
    ordered = sorted(values)
    p90 = ordered[min(len(ordered) - 1, int(0.9 * len(ordered)))]
    return f"{statistics.median(ordered):.1f} / {p90:.1f}"


def _factor(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}x"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=_ints, default=[1, 10])
    parser.add_argument("--speeds", type=_floats, default=[10.0, 100.0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--rounds", type=int, default=50)
    args = parser.parse_args(argv)
    available, why = ros2_available()
    prefix = ros2_prefix()
    if not available or prefix is None:
        print(f"bench_standin: skipped, no usable ROS 2: {why}")
        return 0
    console = Console()
    console.print(
        f"{platform.node()}: {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}, "
        f"Python {platform.python_version()}, ROS 2 from {prefix}"
    )
    env = ros2_environment(prefix)

    rtf = Table(title="Real-time factor (simulated s per wall s; robots idle, seeing each other)")
    for column in ("robots", "--speed asked", "/clock", "slowest robot's odom"):
        rtf.add_column(column, justify="right")
    for robots in args.robots:
        for speed in args.speeds:
            measured = real_time_factor(env, robots, speed, args.seconds)
            rtf.add_row(
                str(robots), f"{speed:g}x", _factor(measured["clock"]), _factor(measured["slowest"])
            )
    console.print(rtf)

    trips = round_trips(env, args.rounds)
    latency = Table(
        title=f"navigate_to_pose round trip, goal at the robot ({args.rounds} goals each, "
        "alternating; wall ms, median / p90)"
    )
    for column in ("server", "results", "send_goal -> accepted", "send_goal -> result"):
        latency.add_column(column, justify="right")
    names = {
        "/navigate_to_pose": "navseq stand-in (speed 1)",
        "/instant/navigate_to_pose": "plain rclpy server (succeeds at once)",
    }
    for action, seen in trips.items():
        statuses = ", ".join(f"{count} {status}" for status, count in seen["statuses"].items())
        latency.add_row(names[action], statuses, _ms(seen["accepted"]), _ms(seen["result"]))
    console.print(latency)
    return 0


if __name__ == "__main__":
    sys.exit(main())
