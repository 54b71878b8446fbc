"""navseq's core works where there is no ROS at all: only the ROS adapters import rospy."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# Runs before navseq in a fresh interpreter: any attempt to import ROS fails the way
# it does on a machine without ROS installed.
NO_ROS_PRELUDE = textwrap.dedent(
    """
    import importlib.abc, sys

    ROS = ("rospy", "actionlib", "actionlib_msgs", "move_base_msgs", "geometry_msgs",
           "nav_msgs", "std_srvs", "tf2_ros", "visualization_msgs", "genpy", "roslib",
           "rclpy", "nav2_msgs", "lifecycle_msgs", "builtin_interfaces", "tf2_msgs")

    class NoRos(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ROS:
                raise ModuleNotFoundError(f"No module named {name!r} (no ROS here)")
            return None

    sys.meta_path.insert(0, NoRos())
    """
)

CORE_MODULES = [
    "navseq.cli",
    "navseq.commands.run",
    "navseq.commands.validate",
    "navseq.commands.convert",
    "navseq.commands.sim",
    "navseq.ros2",
    "navseq.ros2.standin",
    "navseq.ros2.sim_config",
    "navseq.mission",
    "navseq.executor.machine",
    "navseq.executor.runner",
    "navseq.navigators.sim",
    "navseq.navigators.scripted",
    "navseq.preflight",
    "navseq.sim.world",
    "navseq.sim.base",
    "navseq.sinks.progress",
    "navseq.sinks.journal",
    "navseq.sinks.report",
    "navseq.sinks.picture",
]


def run_without_ros(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", NO_ROS_PRELUDE + textwrap.dedent(code), *args],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
    )


def test_core_modules_import_without_ros_and_load_none_of_it():
    done = run_without_ros(
        f"""
        import importlib, json, sys
        for name in {CORE_MODULES!r}:
            importlib.import_module(name)
        print(json.dumps(sorted(m for m in sys.modules if m.split(".")[0] in ROS)))
        """
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == []


def test_the_main_job_runs_without_ros(tmp_path: Path):
    done = run_without_ros(
        """
        import sys
        from navseq.cli import main
        sys.exit(main(sys.argv[1:]))
        """,
        "run",
        "examples/turtlebot3_world.yaml",
        "--out",
        str(tmp_path / "out"),
        "--json",
    )
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["success"] is True
    assert (tmp_path / "out" / "mission.png").stat().st_size > 0


def test_asking_for_ros_without_ros_is_one_clear_error(tmp_path: Path):
    done = run_without_ros(
        """
        import sys
        from navseq.cli import main
        sys.exit(main(sys.argv[1:]))
        """,
        "run",
        "examples/turtlebot3_world.yaml",
        "--navigator",
        "ros1",
        "--out",
        str(tmp_path / "out"),
    )
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "ros" in done.stderr.lower()


def test_only_navseq_ros2_imports_rclpy():
    """ROS 2's client library and messages are imported in navseq.ros2 alone."""
    import ast

    ros2_only = {"rclpy", "nav2_msgs", "lifecycle_msgs", "builtin_interfaces"}
    offenders = []
    for path in sorted((REPO / "src" / "navseq").rglob("*.py")):
        if path.parent.name == "ros2":
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = (
                [alias.name for alias in node.names]
                if isinstance(node, ast.Import)
                else [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else []
            )
            offenders += [
                f"{path.relative_to(REPO)}: {name}"
                for name in names
                if name.split(".")[0] in ros2_only
            ]
    assert offenders == []
