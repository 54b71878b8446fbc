"""Nav2's own client scripts — nav2_simple_commander's jazzy examples and demos — run
against ``navseq sim --ros2`` as a Nav2 user would run them (issue 20).

Each script is copied from the real Nav2 tree unchanged except its pose numbers: they
place the robot in Nav2's depot and warehouse worlds, so every (x, y) is moved onto a
free spot of the TurtleBot3 arena by the one table :data:`ARENA_SPOTS` (a script's pair
missing from the table fails the test, so a changed upstream script is noticed). Then
``python SCRIPT`` runs (what ``ros2 run nav2_simple_commander ...`` does) against a fresh
stand-in per script — several scripts end with ``lifecycleShutdown()``, which finalizes
Nav2's nodes for good — while ``tests/nav2/goal_witness.py`` records where the robot was
when each goal ended. The test asserts the script's own success line and exit status and
that every goal left the robot where the script sent it.

Sim time: the scripts leave ``use_sim_time`` false, so their stamps are wall time (the
stand-in, like Nav2 for goals in ``map``, does not reject them); their timeouts read
either the server's ``navigation_time`` (simulated) or their own wall clock, both of
which only get further from firing at ``--speed`` > 1. So the stand-ins run at
:data:`SPEED`.
"""

from __future__ import annotations

import json
import math
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import pytest

from nav2_real_support import nav2_missing_reason, nav2_prefix
from ros2_support import SimNode, ros2_environment
from test_ros2_sim import MAP

pytestmark = pytest.mark.ros2

WITNESS = Path(__file__).with_name("nav2") / "goal_witness.py"
SPEED = "6"
START = (-2.0, -0.5)
SCRIPT_TIMEOUT = 240.0  # wall s: the longest (demo_inspection) takes ~30 s at SPEED
REACHED = 0.15  # m: xy goal tolerance (Nav2's 0.25) and the witness's sampling lag

#: Nav2's demo spots (x, y) -> free spots of the TurtleBot3 arena. The arena's pillars
#: stand on a 1.1 m grid around (0, 0); its lanes run at +-0.55 m between them.
ARENA_SPOTS: dict[tuple[float, float], tuple[float, float]] = {
    (0.0, 0.0): START,  # every script's initial pose (and a pillar of the arena)
    (7.0, 0.5): (0.55, -0.5),  # example_follow_path's goal
    (10.15, -0.77): (-0.55, -0.55),  # the depot's route (nav_to_pose, through_poses,
    (17.86, -0.77): (0.55, -0.55),  #   waypoint_follower, demo_security)
    (21.58, -3.5): (1.65, -0.55),
    (19.4, -6.4): (0.55, -1.65),
    (-6.0, 5.0): (-1.1, 1.65),  # demo_security's last stop, demo_picking's bays
    (-6.0, 0.0): (-2.0, 0.0),
    (-6.0, -5.0): (-1.1, -1.65),
    (8.21, 1.3): (-1.65, -0.55),  # the warehouse's shelves (demo_inspection,
    (8.7, 4.0): (-1.65, 0.55),  #   demo_picking, demo_recoveries)
    (11.6, 4.0): (-0.55, 0.55),
    (11.6, 1.3): (-0.55, -0.55),
    (12.6, 1.3): (0.55, -0.55),
    (12.6, 4.0): (0.55, 0.55),
    (15.27, 1.3): (1.1, -0.55),
    (16.4, 1.3): (1.65, -0.55),
    (19.0, 1.3): (1.65, 0.0),
    (19.0, 4.0): (1.65, 0.55),
}

# A pose as the scripts write it: ``...position.x = X`` then ``...position.y = Y`` on the
# next line, or a list ``[X, Y]`` / ``[X, Y, YAW]``.
_NUMBER = r"-?\d+\.\d+"
POSE_LINES = re.compile(rf"(position\.x = )({_NUMBER})(\n[^\n]*position\.y = )({_NUMBER})")
POSE_LISTS = re.compile(rf"(\[)({_NUMBER})(, )({_NUMBER})(?=(?:, {_NUMBER})?\])")


def moved_onto_arena(source: str) -> tuple[str, list[tuple[float, float]]]:
    """The script with every pose moved by :data:`ARENA_SPOTS`, and the pairs moved."""
    moved: list[tuple[float, float]] = []

    def move(match: re.Match[str]) -> str:
        spot = (float(match[2]), float(match[4]))
        assert spot in ARENA_SPOTS, f"no arena spot for Nav2's {spot}: add it to ARENA_SPOTS"
        moved.append(spot)
        x, y = ARENA_SPOTS[spot]
        return f"{match[1]}{x}{match[3]}{y}"

    source = POSE_LINES.sub(move, source)
    return POSE_LISTS.sub(move, source), moved


@dataclass(frozen=True)
class Example:
    """One script, the line it prints on success, and the goals it sends, in order:
    (action, terminal status, where the robot is then: a Nav2 spot or an arena spot)."""

    script: str
    success: str | None
    goals: tuple[tuple[str, str, tuple[float, float]], ...]
    endless: bool = False  # loops until killed: stopped after its success line


def arena(spot: tuple[float, float]) -> tuple[float, float]:
    return ARENA_SPOTS.get(spot, spot)


EXAMPLES = (
    Example(
        "example_nav_to_pose.py",
        "Goal succeeded!",
        (("navigate_to_pose", "SUCCEEDED", (17.86, -0.77)),),
    ),
    Example(
        "example_nav_through_poses.py",
        "Goal succeeded!",
        (("navigate_through_poses", "SUCCEEDED", (21.58, -3.5)),),
    ),
    Example(
        "example_waypoint_follower.py",
        "Goal succeeded!",
        (("follow_waypoints", "SUCCEEDED", (21.58, -3.5)),),
    ),
    Example(
        "example_follow_path.py",
        "Goal succeeded!",
        (("follow_path", "SUCCEEDED", (7.0, 0.5)),),
    ),
    # The operator sends no teleop command: the robot stays; the behaviour ends at its
    # 20 s time allowance, ABORTED with TIMEOUT as Nav2's assisted_teleop does.
    Example(
        "example_assisted_teleop.py",
        None,
        (("assisted_teleop", "ABORTED", (0.0, 0.0)),),
    ),
    Example(
        "demo_picking.py",
        "Got product from shelf_A! Bringing product to shipping destination (frieght_bay_3)...",
        (
            ("navigate_to_pose", "SUCCEEDED", (8.21, 1.3)),
            ("navigate_to_pose", "SUCCEEDED", (-6.0, -5.0)),
        ),
    ),
    Example(
        "demo_inspection.py",
        "Inspection of shelves complete! Returning to start...",
        (
            ("follow_waypoints", "SUCCEEDED", (19.0, 4.0)),
            ("navigate_to_pose", "SUCCEEDED", (0.0, 0.0)),
        ),
    ),
    Example(
        "demo_recoveries.py",
        "Dead end confirmed! Returning to start...",
        (
            ("navigate_to_pose", "SUCCEEDED", (8.21, 1.3)),
            # backup(0.5 m) from the shelf facing +x, then a half turn on the spot
            ("backup", "SUCCEEDED", (-2.15, -0.55)),
            ("spin", "SUCCEEDED", (-2.15, -0.55)),
            ("navigate_to_pose", "SUCCEEDED", (0.0, 0.0)),
        ),
    ),
    Example(
        "demo_security.py",
        "Route complete! Restarting...",
        (("navigate_through_poses", "SUCCEEDED", (-6.0, 5.0)),),
        endless=True,
    ),
)


class Witness:
    """``goal_witness.py`` running: the goals that ended, as they end."""

    def __init__(self, env: dict[str, str]) -> None:
        self.process = subprocess.Popen(
            [sys.executable, str(WITNESS)],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.ended: list[dict[str, object]] = []
        self._watching = threading.Event()
        threading.Thread(target=self._read, daemon=True).start()
        assert self._watching.wait(60), "goal witness did not start"

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            if line.startswith("{"):
                self.ended.append(json.loads(line))
            elif "watching" in line:
                self._watching.set()

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


class Script:
    """The moved script running; its stdout lines as they come."""

    def __init__(self, path: Path, env: dict[str, str]) -> None:
        self.process = subprocess.Popen(
            [sys.executable, str(path)],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.lines: list[str] = []
        self._stderr: list[str] = []
        threading.Thread(
            target=self._read, args=(self.process.stdout, self.lines), daemon=True
        ).start()
        threading.Thread(
            target=self._read, args=(self.process.stderr, self._stderr), daemon=True
        ).start()

    @staticmethod
    def _read(stream: IO[str] | None, into: list[str]) -> None:
        assert stream is not None
        for line in stream:
            into.append(line.rstrip("\n"))

    def wait_for(self, line: str, timeout: float) -> bool:
        end = time.monotonic() + timeout
        while time.monotonic() < end and self.process.poll() is None:
            if line in self.lines:
                return True
            time.sleep(0.1)
        return line in self.lines

    def stop(self, timeout: float) -> int:
        """Its exit status once it ends on its own within ``timeout``; else it is
        interrupted (SIGINT, then killed) and this fails."""
        try:
            return self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.interrupt()
            raise AssertionError(f"script did not end: {self.output()}") from None

    def interrupt(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()

    def output(self) -> str:
        time.sleep(0.2)  # the readers' last lines
        return "\n".join(self.lines[-20:] + self._stderr[-30:])


@pytest.fixture
def nav2_env() -> Iterator[Path]:
    reason = nav2_missing_reason()
    if reason is not None:
        pytest.skip(reason)
    prefix = nav2_prefix()
    assert prefix is not None
    yield prefix


def test_every_pose_of_every_script_has_an_arena_spot() -> None:
    """The table moves exactly what the scripts hold: none of Nav2's poses is left."""
    reason = nav2_missing_reason()
    if reason is not None:
        pytest.skip(reason)
    prefix = nav2_prefix()
    assert prefix is not None
    scripts = next(prefix.glob("lib/python3*/site-packages/nav2_simple_commander"))
    used: set[tuple[float, float]] = set()
    for example in EXAMPLES:
        source, moved = moved_onto_arena((scripts / example.script).read_text())
        assert moved, example.script
        used.update(moved)
        for x, y in ARENA_SPOTS:  # Nav2's numbers are gone where they were poses
            if (x, y) != (0.0, 0.0):
                assert f"x = {x}\n" not in source and f"[{x}, {y}" not in source
    assert used == set(ARENA_SPOTS)


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda example: example.script[:-3])
def test_nav2_simple_commander_script_runs_unchanged_but_its_poses(
    example: Example, nav2_env: Path, tmp_path: Path
) -> None:
    scripts = next(nav2_env.glob("lib/python3*/site-packages/nav2_simple_commander"))
    source, _ = moved_onto_arena((scripts / example.script).read_text())
    copy = tmp_path / example.script
    copy.write_text(source)
    env = ros2_environment(nav2_env)
    start = f"--start={START[0]},{START[1]},0"
    sim = SimNode(env, "--map", str(MAP), start, "--speed", SPEED)
    witness = Witness(env)
    script = Script(copy, env)
    try:
        if example.endless:
            assert example.success is not None
            succeeded = script.wait_for(example.success, SCRIPT_TIMEOUT)
            script.interrupt()
            assert succeeded, script.output()
        else:
            status = script.stop(SCRIPT_TIMEOUT)
            assert status == 0, script.output()
            if example.success is not None:
                assert example.success in script.lines, script.output()
            assert "Traceback" not in script.output()
        time.sleep(0.5)  # the last status reaches the witness
    finally:
        script.interrupt()
        witness.stop()
        err = sim.stop()
    assert sim.process.returncode == 0, err
    assert "Traceback" not in err
    ended = witness.ended[: len(example.goals)]
    assert [(goal["action"], goal["status"]) for goal in ended] == [
        (action, status) for action, status, _ in example.goals
    ], witness.ended
    for goal, (_, _, spot) in zip(ended, example.goals, strict=True):
        pose = goal["pose"]
        assert isinstance(pose, list), goal
        x, y = arena(spot)
        assert math.dist(pose[:2], (x, y)) < REACHED, (goal, (x, y))
