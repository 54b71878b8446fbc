"""``navseq run --fleet FLEET --navigator nav2``: one namespaced ROS 2 stand-in per robot
(``python -m navseq.ros2.sim_node --ns robotK --other-robots ...``, robots that see each
other but know no right of way, as two Nav2 bringups), driven from one navseq process
whose fleet coordinator (navseq.fleet.coordinator) gives way among them. Without it the
swap below ends ABORTED "blocked by another robot" (tests/test_fleet_coordinator.py shows
that on the same servers in process)."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from cli_support import NAVSEQ
from navseq.sim.mapgen import save_map
from ros2_support import SimNode, ros2_environment, ros2_prefix
from test_right_of_way import corridor_between_rooms

pytestmark = pytest.mark.ros2

FLEET = """\
navseq_fleet: 1
map: corridor.yaml
mission:
  defaults: {{goal_timeout: 240}}
  waypoints:
{waypoints}
robots:
  - {{name: robot1, start: {{x: 2.6, y: 1.2, yaw: 0}}}}
  - {{name: robot2, start: {{x: {robot2_x}, y: 1.2, yaw: 180}}}}
waypoints:
{rules}
"""


@pytest.fixture
def env() -> dict[str, str]:
    prefix = ros2_prefix()
    assert prefix is not None
    return ros2_environment(prefix)


def write_fleet(folder: Path, robot2_x: float, waypoints: dict[str, tuple], rules: dict) -> Path:
    save_map(corridor_between_rooms(), folder / "corridor.yaml")
    listed = "\n".join(
        f"    - {{name: {name}, x: {x}, y: {y}, yaw: {yaw}}}"
        for name, (x, y, yaw) in waypoints.items()
    )
    ruled = "\n".join(f"  {name}: {{robots: [{robot}]}}" for name, robot in rules.items())
    path = folder / "fleet.yaml"
    path.write_text(FLEET.format(waypoints=listed, robot2_x=robot2_x, rules=ruled))
    return path


def stacks(env: dict[str, str], folder: Path, starts: dict[str, str]) -> list[SimNode]:
    """A stand-in per robot, each seeing the others."""
    nodes = []
    try:
        for name, start in starts.items():
            others = ",".join(other for other in starts if other != name)
            nodes.append(
                SimNode(
                    env,
                    "--map",
                    str(folder / "corridor.yaml"),
                    f"--start={start}",
                    "--ns",
                    name,
                    *(("--other-robots", others) if others else ()),
                )
            )
    except BaseException:
        for node in nodes:
            node.stop()
        raise
    return nodes


@pytest.fixture
def running(env: dict[str, str], tmp_path: Path) -> Iterator[list[SimNode]]:
    holder: list[SimNode] = []
    yield holder
    logs = [node.stop() for node in holder]
    for log in logs:
        assert "Traceback" not in log, log


def fleet_run(
    env: dict[str, str], fleet: Path, out: Path, *extra: str
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [NAVSEQ, "run", "--fleet", fleet, "--navigator", "nav2", "--out", out, *extra],
        env=env,
        cwd=fleet.parent,
        capture_output=True,
        text=True,
        timeout=400,
    )


def journal_text(out: Path, robot: str) -> str:
    return (out / robot / "journal.jsonl").read_text()


def test_two_robots_swap_the_ends_of_a_one_robot_corridor(
    env: dict[str, str], tmp_path: Path, running: list[SimNode]
):
    fleet = write_fleet(
        tmp_path,
        4.8,
        {"east": (4.8, 1.2, 0), "west": (2.6, 1.2, 180)},
        {"east": "robot1", "west": "robot2"},
    )
    running += stacks(env, tmp_path, {"robot1": "2.6,1.2,0", "robot2": "4.8,1.2,180"})
    done = fleet_run(env, fleet, tmp_path / "run")
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "run" / "fleet-report.json").read_text())
    assert (report["reached"], report["failed"], report["skipped"]) == (2, 0, 0), report
    assert report["robot_overlaps"] == 0, report
    assert report["coordinator"]["sent_aside"] >= 1, report
    for robot in ("robot1", "robot2"):
        assert "blocked" not in journal_text(tmp_path / "run", robot)
        assert (tmp_path / "run" / robot / "report.json").is_file()
    assert (tmp_path / "run" / "fleet.png").is_file()
    assert "Traceback" not in done.stderr


def test_a_robot_parked_on_the_others_goal_moves_aside(
    env: dict[str, str], tmp_path: Path, running: list[SimNode]
):
    fleet = write_fleet(
        tmp_path,
        3.7,
        {"middle": (3.7, 1.2, 0), "far": (6.2, 1.2, 0)},
        {"middle": "robot1", "far": "robot1"},
    )
    running += stacks(env, tmp_path, {"robot1": "1.2,1.2,0", "robot2": "3.7,1.2,180"})
    done = fleet_run(env, fleet, tmp_path / "run")
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "run" / "fleet-report.json").read_text())
    assert (report["reached"], report["failed"]) == (2, 0), report
    assert report["coordinator"]["sent_aside"] >= 1, report
    assert "blocked" not in journal_text(tmp_path / "run", "robot1")


def test_a_fleet_run_on_stacks_is_recorded_in_one_file_and_printed_as_json(
    env: dict[str, str], tmp_path: Path, running: list[SimNode]
):
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    fleet = write_fleet(
        tmp_path,
        3.7,
        {"middle": (3.7, 1.2, 0), "far": (6.2, 1.2, 0)},
        {"middle": "robot1", "far": "robot1"},
    )
    running += stacks(env, tmp_path, {"robot1": "1.2,1.2,0", "robot2": "3.7,1.2,180"})
    out = tmp_path / "run"
    done = fleet_run(env, fleet, out, "--record", "--json", "--record-topics", "/scan,/odom")
    assert done.returncode == 0, done.stderr
    records = [json.loads(line) for line in done.stdout.splitlines()]
    assert {r["robot"] for r in records} == {"robot1"}  # robot2 has no share: no events
    assert [r["outcome"] for r in records if r["event"] == "WaypointFinished"] == ["reached"] * 2
    report = json.loads((out / "fleet-report.json").read_text())
    assert report["files"]["recording"] == str(out / "fleet.mcap")
    with AnyReader([out / "fleet.mcap"], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as bag:
        topics = {c.topic for c in bag.connections}
        poses = [c for c in bag.connections if c.topic == "/robot1/navseq/pose"]
        stamps = [t for _, t, _ in bag.messages(connections=poses)]
        tf = [c for c in bag.connections if c.topic == "/tf"]
        frames = {
            transform.child_frame_id
            for connection, _, raw in bag.messages(connections=tf)
            for transform in bag.deserialize(raw, connection.msgtype).transforms
        }
        # --record-topics: the robot's stack's own, under its namespace, as published.
        stack = {c.topic: c for c in bag.connections if c.topic in ("/robot1/scan", "/robot1/odom")}
        odom_frames = {
            bag.deserialize(raw, connection.msgtype).header.frame_id
            for connection, _, raw in bag.messages(connections=[stack["/robot1/odom"]])
        }
    assert {"/map", "/tf", "/robot1/plan", "/robot1/navseq/goal"} <= topics
    assert len(stamps) > 10 and stamps == sorted(stamps)  # the stack's ROS time, forward
    assert frames == {"robot1/odom", "robot1/base_footprint"}
    assert stack["/robot1/scan"].msgtype == "sensor_msgs/msg/LaserScan"
    assert stack["/robot1/scan"].msgcount > 10
    assert odom_frames == {"odom"}  # the stand-in's (Nav2's convention), not navseq's


def test_a_namespace_no_stack_serves_is_refused_before_anything_moves(
    env: dict[str, str], tmp_path: Path, running: list[SimNode]
):
    fleet = write_fleet(
        tmp_path,
        4.8,
        {"east": (4.8, 1.2, 0), "west": (2.6, 1.2, 180)},
        {"east": "robot1", "west": "robot2"},
    )
    running += stacks(env, tmp_path, {"robot1": "2.6,1.2,0"})  # nobody serves robot2
    done = subprocess.run(
        [
            NAVSEQ,
            "run",
            "--fleet",
            fleet,
            "--navigator",
            "nav2",
            "--out",
            tmp_path / "run",
            "--server-timeout",
            "3",
        ],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert "robot 'robot2'" in done.stderr and "/robot2/navigate_to_pose" in done.stderr
    assert "robot1" not in done.stderr.replace("robot 'robot2'", "")  # robot1's stack is fine
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "run").exists()  # nothing written, nothing moved


def test_a_fleet_run_stopped_with_ctrl_c_resumes_on_the_same_stacks(
    env: dict[str, str], tmp_path: Path, running: list[SimNode]
):
    import signal
    import time

    fleet = write_fleet(
        tmp_path,
        4.8,
        {"east": (4.8, 1.2, 0), "west": (2.6, 1.2, 180)},
        {"east": "robot1", "west": "robot2"},
    )
    running += stacks(env, tmp_path, {"robot1": "2.6,1.2,0", "robot2": "4.8,1.2,180"})
    out = tmp_path / "run"
    process = subprocess.Popen(
        [NAVSEQ, "run", "--fleet", fleet, "--navigator", "nav2", "--out", out],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not all(
            (out / robot / "journal.jsonl").exists()
            and "WaypointStarted" in (out / robot / "journal.jsonl").read_text()
            for robot in ("robot1", "robot2")
        ):
            assert process.poll() is None, process.communicate()
            time.sleep(0.2)
        time.sleep(2.0)  # under way
    finally:
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    stopped = json.loads((out / "fleet-report.json").read_text())
    assert stopped["interrupted"] == "SIGINT" and stopped["reached"] < 2, stopped
    # The run's own kind (nav2, from fleet-run.json) when --navigator is left out.
    done = subprocess.run(
        [NAVSEQ, "run", "--fleet", fleet, "--resume", out],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=400,
    )
    assert done.returncode == 0, done.stderr
    report = json.loads((out / "fleet-report.json").read_text())
    assert (report["reached"], report["interrupted"]) == (2, None), report
    assert "Traceback" not in done.stderr
