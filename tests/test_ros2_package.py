"""The repository is a ROS 2 package too: package.xml conditions, a colcon workspace.

The fast check reads package.xml as each ROS's tools do (conditions evaluated against
``ROS_VERSION``). The slow one builds a colcon workspace (colcon from PyPI, the
``dev`` extra) whose ``src/`` links to this repository against the ROS 2 found by
``ros2_support``, then, with the workspace sourced, runs ``ros2 run navseq sim_node`` +
``ros2 run navseq navseq_node`` and ``ros2 launch navseq sim_navseq.launch.py`` to
the mission's end. The navseq they import is the workspace's installed copy.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from cli_support import REPO
from ros2_support import ros2_environment, ros2_prefix

catkin_pkg = pytest.importorskip("catkin_pkg.package", reason="catkin_pkg not installed")

COLCON = Path(sys.executable).parent / "colcon"
SYSTEM_PYTHON = "/usr/bin/python3"


@pytest.mark.parametrize(
    ("ros_version", "build_type", "present", "absent"),
    [
        ("1", "catkin", {"catkin", "rospy", "actionlib", "move_base_msgs"}, {"rclpy"}),
        (
            "2",
            "ament_cmake",
            {"ament_cmake", "ament_cmake_python", "rclpy", "nav2_msgs"},
            {
                "rospy",
                "catkin",
            },
        ),
    ],
)
def test_package_xml_is_a_catkin_package_for_ros1_and_an_ament_one_for_ros2(
    ros_version: str, build_type: str, present: set[str], absent: set[str]
):
    package = catkin_pkg.parse_package(REPO / "package.xml")
    package.evaluate_conditions({"ROS_VERSION": ros_version, "ROS_PYTHON_VERSION": "3"})
    assert package.get_build_type() == build_type
    depends = {
        dep.name
        for dep in (*package.buildtool_depends, *package.exec_depends)
        if dep.evaluated_condition
    }
    assert present <= depends
    assert not absent & depends
    # Both need the messages they share.
    assert {"geometry_msgs", "nav_msgs", "std_srvs", "visualization_msgs"} <= depends


def _sourced(setup: Path, base: dict[str, str]) -> dict[str, str]:
    """The environment after ``source setup`` in bash."""
    dump = subprocess.run(
        ["bash", "-c", f"source {setup} && env -0"],
        check=True,
        capture_output=True,
        env=base,
    ).stdout.decode()
    return dict(item.split("=", 1) for item in dump.split("\0") if "=" in item)


@pytest.mark.ros2
@pytest.mark.slow
def test_colcon_builds_the_package_and_ros2_run_and_launch_complete_the_mission(
    tmp_path: Path,
):
    if not COLCON.exists():
        pytest.skip("colcon not installed (pip install -e '.[dev]': colcon-common-extensions)")
    prefix = ros2_prefix()
    assert prefix is not None
    base = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "AMENT_"))}
    ros2 = _sourced(prefix / "setup.bash", base)
    assert ros2["ROS_VERSION"] == "2"
    workspace = tmp_path / "ws"
    (workspace / "src").mkdir(parents=True)
    (workspace / "src" / "navseq").symlink_to(REPO)
    build = subprocess.run(
        [COLCON, "build", "--cmake-args", f"-DPython3_EXECUTABLE={SYSTEM_PYTHON}"],
        cwd=workspace,
        env=ros2,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    install = workspace / "install" / "navseq"
    for script in ("navseq_node", "sim_node"):
        assert os.access(install / "lib" / "navseq" / script, os.X_OK), script
    share = install / "share" / "navseq"
    for relative in (
        "package.xml",
        "launch/sim_navseq.launch.py",
        "rviz/navseq_ros2.rviz",
        "maps/turtlebot3_world.yaml",
        "examples/tutorial_params_ros2.yaml",
    ):
        assert (share / relative).is_file(), relative
    site = install / "lib" / "python3.11" / "site-packages" / "navseq"
    assert (site / "ros2" / "navseq_node.py").is_file()

    # The sourced workspace, with the venv's Python first on PATH (the node scripts run
    # `python3`; navseq's Python dependencies are in the venv, not on the system).
    env = _sourced(workspace / "install" / "setup.bash", ros2)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env["PATH"]])
    env = ros2_environment(prefix, base=env)
    env["PYTHONPATH"] = os.pathsep.join([str(site.parent), env["PYTHONPATH"]])
    where = subprocess.run(
        ["python3", "-c", "import navseq.ros2.navseq_node as m; print(m.__file__)"],
        env=env,
        capture_output=True,
        text=True,
    )
    assert where.stdout.strip() == str(site / "ros2" / "navseq_node.py"), where.stderr

    sim = subprocess.Popen(
        [
            "ros2",
            "run",
            "navseq",
            "sim_node",
            "--map",
            str(share / "maps" / "turtlebot3_world.yaml"),
            "--start=-2,-0.5,0",
            "--speed",
            "4",
        ],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # Ctrl-C reaches `ros2 run` and its child as a group
    )
    try:
        node = subprocess.run(
            [
                "ros2",
                "run",
                "navseq",
                "navseq_node",
                "--ros-args",
                "--params-file",
                str(share / "examples" / "tutorial_params_ros2.yaml"),
            ],
            env=env,
            capture_output=True,
            text=True,
            timeout=180,
        )
    finally:
        os.killpg(sim.pid, signal.SIGINT)
        _, sim_log = sim.communicate(timeout=30)
    assert node.returncode == 0, node.stdout + node.stderr + sim_log
    assert "mission succeeded (completed)" in node.stderr

    launched = subprocess.run(
        ["ros2", "launch", "navseq", "sim_navseq.launch.py", "speed:=4"],
        env=env,
        capture_output=True,
        text=True,
        timeout=180,
    )
    output = launched.stdout + launched.stderr
    assert launched.returncode == 0, output
    assert "mission succeeded (completed)" in output
    assert output.count(": reached after ") == 4
    assert "Traceback" not in output


def test_the_ros2_node_scripts_relay_to_navseq_ros2_and_stay_out_of_rosruns_way():
    for script in (REPO / "nodes" / "ros2").iterdir():
        text = script.read_text()
        assert text.startswith("#!/usr/bin/env python3\n"), script
        # ROS 1's rosrun looks for executables by name anywhere in the package: an
        # executable nodes/ros2/navseq_node would make `rosrun navseq navseq_node`
        # ambiguous. install(PROGRAMS) makes the installed copy executable.
        assert not os.access(script, os.X_OK), script
        assert f"from navseq.ros2.{script.name} import main" in text
        assert f"nodes/ros2/{script.name}" in (REPO / "CMakeLists.txt").read_text()
