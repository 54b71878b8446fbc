"""``navseq sim --ros1``: the ROS 1 sim nodes (and a master if none) from one command.

The ROS tests run it as a user would, in its own process with ``ROS_MASTER_URI`` on a
free loopback port, drive it with ``navseq run --navigator ros1``, then stop it and check
by PID that no rosmaster or node outlived it.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
import xmlrpc.client
from pathlib import Path

import pytest

from cli_support import EXAMPLES, NAVSEQ, TURTLEBOT3_MAP, wait_for
from ros_support import RosMaster, free_port
from test_layers import run_without_ros

CLI = "import sys\nfrom navseq.cli import main\nsys.exit(main(sys.argv[1:]))\n"


def test_without_rospy_it_says_to_source_ros1_and_exits_2():
    done = run_without_ros(CLI, "sim", "--ros1", "--map", str(TURTLEBOT3_MAP))
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "source ROS 1 first" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--ns", "_robot"], "is not a ROS 1 namespace"),
        (["--speed", "0"], "--speed: must be > 0"),
        (["--start", "1,2,3,4"], "expected x,y,yaw"),
        (["--start", "0,0,0"], "--start: (0.00, 0.00) puts the robot on an obstacle"),
        (["--robot", "roomba"], "neither a built-in robot"),
        (["--replan-period", "1"], "--replan-period: Nav2's re-plan on preemption"),
    ],
)
def test_bad_options_are_one_clear_error_even_without_rospy(options, message):
    done = run_without_ros(CLI, "sim", "--ros1", "--map", str(TURTLEBOT3_MAP), *options)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr
    assert "Traceback" not in done.stderr


class SimCommand:
    """``navseq sim --ros1 ...`` in the background; its stdout and stderr collected."""

    def __init__(self, env: dict[str, str], *options: str) -> None:
        self.popen = subprocess.Popen(
            [NAVSEQ, "sim", "--ros1", *options],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.stdout: list[str] = []
        self.stderr: list[str] = []
        self._readers = [
            threading.Thread(target=self._collect, args=(stream, sink), daemon=True)
            for stream, sink in ((self.popen.stdout, self.stdout), (self.popen.stderr, self.stderr))
        ]
        for reader in self._readers:
            reader.start()

    @staticmethod
    def _collect(stream, sink: list[str]) -> None:
        for line in stream:
            sink.append(line)

    def output(self) -> str:
        return "".join(self.stdout) + "".join(self.stderr)

    def wait_ready(self, timeout: float = 90.0) -> str:
        def ready() -> bool:
            if self.popen.poll() is not None:
                raise AssertionError(f"navseq sim exited early:\n{self.output()}")
            return any("ready:" in line for line in self.stdout)

        wait_for(ready, timeout, "navseq sim's ready line")
        return next(line for line in self.stdout if "ready:" in line)

    def wait(self, timeout: float = 60.0) -> int:
        status = self.popen.wait(timeout=timeout)
        for reader in self._readers:
            reader.join(timeout=5)
        return status

    def kill(self) -> None:
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(timeout=10)


def pid_of(uri: str) -> int:
    """The PID of the master or node serving XML-RPC at ``uri``."""
    code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/test")
    assert code == 1
    return int(pid)


def node_pid(master_uri: str, node: str) -> int:
    code, message, uri = xmlrpc.client.ServerProxy(master_uri).lookupNode("/test", node)
    assert code == 1, message
    return pid_of(uri)


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.fixture
def unstarted_master(tmp_path: Path) -> RosMaster:
    """A master URI on a free port, the environment to reach it, and no master there."""
    (tmp_path / "ros").mkdir()
    return RosMaster(port=free_port(), workdir=tmp_path / "ros")


@pytest.mark.ros
def test_it_starts_a_master_serves_a_mission_and_leaves_nothing_behind(unstarted_master, tmp_path):
    env = unstarted_master.env
    sim = SimCommand(env, "--start", "-2,-0.5,0", "--speed", "5")
    try:
        ready = sim.wait_ready()
        assert "ready: /move_base on" in ready and "robot at (-2.00, -0.50)" in ready
        assert "use_sim_time is true" in ready
        assert f"no ROS master at {unstarted_master.uri}: started one" in "".join(sim.stderr)
        assert unstarted_master.get_param("/use_sim_time") is True
        pids = [pid_of(unstarted_master.uri)] + [
            node_pid(unstarted_master.uri, node) for node in ("/sim_robot", "/move_base")
        ]

        out = tmp_path / "out"
        run = subprocess.run(
            [NAVSEQ, "run", EXAMPLES / "turtlebot3_world.yaml", "--navigator", "ros1",
             "--out", out],
            env=env, cwd=tmp_path, capture_output=True, text=True, timeout=240,
        )  # fmt: skip
        assert run.returncode == 0, run.stdout + run.stderr
        report = json.loads((out / "report.json").read_text())
        assert report["success"] is True
        assert len(report["visits"]) == 7
        assert all(visit["outcome"] == "reached" for visit in report["visits"])

        sim.popen.send_signal(signal.SIGINT)
        assert sim.wait() == 0, sim.output()
    finally:
        sim.kill()
    assert "Traceback" not in sim.output()
    assert "stopped the ROS master it started" in "".join(sim.stderr)
    assert [pid for pid in pids if alive(pid)] == []
    assert not unstarted_master.master_online()


@pytest.mark.ros
def test_it_uses_a_running_master_and_sigterm_stops_only_its_nodes(ros_master):
    sim = SimCommand(ros_master.env, "--ns", "r1", "--start", "-2,-0.5,90", "--other-robots", "r2")
    try:
        ready = sim.wait_ready()
        assert "ready: /r1/move_base" in ready and "use_sim_time" not in ready
        assert f"using the ROS master at {ros_master.uri}" in "".join(sim.stderr)
        assert ros_master.get_param("/use_sim_time") is False
        # The namespaced robot's frames carry the prefix, as sim_robot.launch gives them,
        # and both nodes watch the other robot, as multi_robot.launch has them do.
        assert ros_master.get_param("/r1/sim_robot/base_frame") == "r1/base_footprint"
        for node in ("sim_robot", "move_base"):
            assert ros_master.get_param(f"/r1/{node}/other_robots") == ["r2/base_footprint"]
        ros_master.wait_for_publisher("/map")  # one world map, outside the namespace
        pids = [node_pid(ros_master.uri, node) for node in ("/r1/sim_robot", "/r1/move_base")]
        # A second simulator in the same namespace would push these nodes off the master.
        second = subprocess.run(
            [NAVSEQ, "sim", "--ros1", "--ns", "r1"],
            env=ros_master.env, capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        assert second.returncode == 2, second.stderr
        assert "a node /r1/sim_robot already runs on this master" in second.stderr
        assert all(alive(pid) for pid in pids)
        sim.popen.send_signal(signal.SIGTERM)
        assert sim.wait() == 0, sim.output()
    finally:
        sim.kill()
    assert [pid for pid in pids if alive(pid)] == []
    assert ros_master.master_online()  # not ours: left running


@pytest.mark.ros
def test_a_namespaced_robot_without_its_own_map_is_checked_on_the_global_map(ros_master, tmp_path):
    """A ROS 1 fleet shares one map_server on /map (nothing publishes /r1/map): pre-flight
    of ``navseq run --ns r1`` without --map falls back to it."""
    sim = SimCommand(ros_master.env, "--ns", "r1", "--start", "-2,-0.5,90")
    mission = tmp_path / "pillar.yaml"
    mission.write_text("waypoints:\n  - {name: pillar, x: 1.0, y: 0.0, yaw: 0}\n")
    try:
        sim.wait_ready()
        run = subprocess.run(
            [NAVSEQ, "run", str(mission), "--navigator", "ros1", "--ns", "r1",
             "--out", str(tmp_path / "out")],
            env=ros_master.env, cwd=tmp_path, capture_output=True, text=True, timeout=120,
        )  # fmt: skip
        sim.popen.send_signal(signal.SIGTERM)
        assert sim.wait() == 0, sim.output()
    finally:
        sim.kill()
    assert run.returncode == 2, run.stderr
    assert "(pre-flight on the map on /map: 384 x 384 cells at 0.050 m)" in run.stderr
    assert "waypoint 1 'pillar'" in run.stderr and "inside an obstacle" in run.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.ros
def test_a_node_that_dies_is_named_and_the_command_fails(ros_master):
    sim = SimCommand(ros_master.env)
    try:
        sim.wait_ready()
        nav_pid = node_pid(ros_master.uri, "/move_base")
        ros_master.kill_node("/sim_robot")  # what `rosnode kill /sim_robot` does
        assert sim.wait() == 1, sim.output()
    finally:
        sim.kill()
    errors = "".join(sim.stderr)
    assert "node sim_robot exited with status" in errors
    assert "its last output:" in errors and "sim robot at" in errors
    assert "Traceback" not in errors
    assert not alive(nav_pid)


def test_the_launcher_module_imports_no_ros():
    done = run_without_ros(
        "import sys, navseq.ros1.sim_launcher\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('rospy', 'rosgraph')))\n"
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.mark.ros
def test_kill_9_of_the_command_takes_its_nodes_and_master_with_it(unstarted_master):
    sim = SimCommand(unstarted_master.env)
    try:
        sim.wait_ready()
        pids = [pid_of(unstarted_master.uri)] + [
            node_pid(unstarted_master.uri, node) for node in ("/sim_robot", "/move_base")
        ]
    finally:
        sim.kill()  # SIGKILL: no chance to clean up; the kernel's parent-death signal does
    wait_for(lambda: not any(alive(pid) for pid in pids), 20, "the children to end")
