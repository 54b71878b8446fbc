"""navseq's launch files, run with ``roslaunch`` from the project's venv.

The repository is on ``ROS_PACKAGE_PATH`` (``ros_support`` sets it) and the venv's
``python3`` is first on ``PATH``, so ``roslaunch navseq ...`` runs the scripts in
``nodes/`` with the venv's interpreter — the way docs/ros.md describes for users who
do not build a catkin workspace.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from ros_clients import EXAMPLE_MISSION, SPEED, SUCCEEDED, goal, reports, start_client
from ros_support import REPO_ROOT, RosMaster, RosProcess

pytestmark = pytest.mark.ros

LAUNCH = REPO_ROOT / "launch"
RVIZ = REPO_ROOT / "rviz" / "navseq.rviz"


def roslaunch_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "ROS_NAMESPACE"}
    env["ROS_PACKAGE_PATH"] = str(REPO_ROOT)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def roslaunch_query(*args: str) -> str:
    """``roslaunch --nodes/--args ...``: parses the files, needs no master."""
    result = subprocess.run(
        ["roslaunch", *args], env=roslaunch_env(), capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def roslaunch(master: RosMaster, *args: str) -> RosProcess:
    return master.start(["roslaunch", "navseq", *args], label="roslaunch")


@pytest.mark.parametrize(
    ("launch_file", "nodes"),
    [
        ("sim.launch", {"/sim_robot", "/move_base"}),
        ("demo.launch", {"/sim_robot", "/move_base", "/navseq"}),
        ("navseq.launch", {"/navseq"}),
        (
            "multi_robot.launch",
            {"/robot1/sim_robot", "/robot1/move_base", "/robot2/sim_robot", "/robot2/move_base"},
        ),
    ],
)
def test_launch_file_names_its_nodes_and_runs_the_scripts_in_nodes(launch_file, nodes):
    listed = set(roslaunch_query("--nodes", "navseq", launch_file).split())
    assert listed == nodes
    for node in nodes:
        command = roslaunch_query("--args", node, "navseq", launch_file)
        # After environment assignments (ROS_MASTER_URI=... ROS_NAMESPACE=...).
        script = next(word for word in command.split() if "=" not in word)
        assert Path(script).parent == REPO_ROOT / "nodes", command


def test_navseq_launch_passes_the_tutorial_params_as_lists():
    dumped = yaml.safe_load(
        roslaunch_query(
            "--dump-params", "navseq", "navseq.launch", "p_seq:=[1,2,0,3,4,0]", "yea_seq:=[90,0]"
        )
    )
    assert dumped["/navseq/p_seq"] == [1, 2, 0, 3, 4, 0]
    assert dumped["/navseq/yea_seq"] == [90, 0]
    assert "/navseq/mission" not in dumped


def test_demo_launch_starts_the_robot_where_the_example_mission_starts():
    from navseq.mission import load_mission

    start = load_mission(EXAMPLE_MISSION).start
    assert start is not None, "the example mission should say where the robot starts"
    dumped = yaml.safe_load(roslaunch_query("--dump-params", "navseq", "demo.launch"))
    launched = [float(dumped[f"/sim_robot/{axis}"]) for axis in ("x", "y", "yaw")]
    assert launched == pytest.approx([start.x, start.y, start.yaw], abs=1e-3)


@pytest.mark.parametrize(
    ("launch_file", "namespaces"),
    [
        ("sim.launch", [""]),
        ("demo.launch", [""]),
        ("sim_robot.launch", [""]),
        ("multi_robot.launch", ["/robot1", "/robot2"]),
    ],
)
def test_the_robot_argument_reaches_both_sim_nodes_of_every_robot(launch_file, namespaces):
    def robots(*args: str) -> dict[str, str]:
        dumped = yaml.safe_load(roslaunch_query("--dump-params", "navseq", launch_file, *args))
        return {
            f"{ns}/{node}": dumped[f"{ns}/{node}/robot"]
            for ns in namespaces
            for node in ("sim_robot", "move_base")
        }

    map_arg = "map:=maps/turtlebot3_world.yaml"  # sim_robot.launch has no default map
    default = robots(map_arg)
    assert set(default.values()) == {"turtlebot3_burger"}, default
    waffle = robots(map_arg, "robot:=turtlebot3_waffle")
    assert set(waffle.values()) == {"turtlebot3_waffle"}, waffle


def test_rviz_config_shows_map_plan_robot_and_waypoints():
    config = yaml.safe_load(RVIZ.read_text())
    displays = config["Visualization Manager"]["Displays"]
    topics = {d.get("Topic") or d.get("Marker Topic") for d in displays}
    assert {
        "/map",
        "/move_base/NavfnROS/plan",
        "/move_base/local_costmap/footprint",
        "/navseq/waypoints",
    } <= topics
    assert config["Visualization Manager"]["Global Options"]["Fixed Frame"] == "map"


def test_roslaunch_sim_launch_from_the_venv_serves_move_base(ros_master: RosMaster, tmp_path: Path):
    roslaunch(ros_master, "sim.launch", f"speed:={SPEED}")
    ros_master.wait_for_action_server("/move_base", timeout=60)
    client = start_client(ros_master, tmp_path, [goal(-1.5, -1.0, math.pi)])
    assert client.wait(timeout=60) == 0, client.output()
    assert reports(client)[0]["state"] == SUCCEEDED


def test_multi_robot_launch_drives_two_namespaced_robots_at_once(
    ros_master: RosMaster, tmp_path: Path
):
    launch = roslaunch(ros_master, "multi_robot.launch", f"speed:={SPEED}")
    for robot in ("robot1", "robot2"):
        ros_master.wait_for_action_server(f"/{robot}/move_base", timeout=60)
    # robot1 starts at (-2, -0.5), robot2 at (2, 0.5) facing it: each crosses to the
    # other's side of the arena, at the same time.
    first = start_client(
        ros_master,
        tmp_path / "1",
        [goal(-1.5, -1.6), goal(0.5, -1.6)],
        namespace="robot1",
        label="robot1",
    )
    second = start_client(
        ros_master,
        tmp_path / "2",
        [goal(1.5, 1.6), goal(-0.5, 1.6)],
        namespace="robot2",
        label="robot2",
    )
    for client, goals in (
        (first, [(-1.5, -1.6), (0.5, -1.6)]),
        (second, [(1.5, 1.6), (-0.5, 1.6)]),
    ):
        assert client.wait(timeout=120) == 0, client.output()
        results = reports(client)
        assert [r["state"] for r in results] == [SUCCEEDED, SUCCEEDED], results
        for (x, y), result in zip(goals, results, strict=True):
            assert math.dist(result["pose"][:2], (x, y)) < 0.1, result
    # robot2 follows robot1's /clock: it must not republish its TF at an unchanged stamp
    # (every TF listener, here each robot watching the other, would warn each time).
    assert "TF_REPEATED_DATA" not in launch.output(), launch.output()[-4000:]


def test_demo_launch_completes_the_example_mission_and_ends_quietly(ros_master: RosMaster):
    demo = roslaunch(ros_master, "demo.launch", f"speed:={SPEED}")
    assert demo.wait(timeout=240) == 0, demo.output()[-4000:]
    output = demo.output()
    assert "mission succeeded" in output, output[-4000:]
    # The node ends the launch as Ctrl-C would: no red banner for a mission that finished.
    assert "ending the launch (~end_launch)" in output, output[-4000:]
    assert "REQUIRED process" not in output and "has died" not in output, output[-4000:]


def test_navseq_launch_with_only_the_tutorial_params_completes_on_the_sim(
    ros_master: RosMaster,
):
    roslaunch(ros_master, "sim.launch", f"speed:={SPEED}")
    ros_master.wait_for_action_server("/move_base", timeout=60)
    points = [(-1.5, -1.6, 0.0), (0.5, -1.6, 90.0), (1.6, 0.5, 180.0)]
    p_seq = ",".join(f"{v:g}" for x, y, _ in points for v in (x, y, 0.0))
    yea_seq = ",".join(f"{yaw:g}" for *_, yaw in points)
    sequencer = ros_master.start(
        [
            "roslaunch",
            "navseq",
            "navseq.launch",
            f"p_seq:=[{p_seq}]",
            f"yea_seq:=[{yea_seq}]",
            "required:=true",
        ],
        label="navseq_launch",
    )
    sequencer.wait(timeout=180)
    assert "mission succeeded" in sequencer.output(), sequencer.output()[-4000:]
