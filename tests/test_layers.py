"""navseq's core works where there is no ROS at all: only ``navseq.ros1`` imports rospy (and
ROS 1 messages), only ``navseq.ros2`` would import rclpy; neither is imported by the core."""

from __future__ import annotations

import ast
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
           "rclpy", "nav2_msgs", "action_msgs", "rosgraph", "rosgraph_msgs", "std_msgs",
           "lifecycle_msgs", "builtin_interfaces", "tf2_msgs")

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
    "navseq.ros2.error_codes",
    "navseq.sim.options",
    "navseq.mission",
    "navseq.executor.machine",
    "navseq.executor.runner",
    "navseq.executor.control",
    "navseq.geometry",
    "navseq.navigators.registry",
    "navseq.navigators.settings",
    "navseq.run",
    "navseq.run.session",
    "navseq.run.products",
    "navseq.navigators.sim",
    "navseq.navigators.scripted",
    "navseq.navigators.stack_map",
    "navseq.preflight",
    *(f"navseq.tasks.{name}" for name in ("runner", "permissions", "ros_jobs", "snapshots")),
    "navseq.sim.world",
    "navseq.sim.base",
    "navseq.sinks.progress",
    "navseq.journal.writer",
    "navseq.sinks.report",
    "navseq.sinks.picture.draw",
    "navseq.sinks.recording.sink",
    "navseq.sinks.recording.reading",
    *(f"navseq.roscore.{name}" for name in ("clock", "server", "goals", "navigator")),
    *(f"navseq.roscore.{name}" for name in ("client", "stack_profile", "node", "operator")),
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


SRC = REPO / "src" / "navseq"
# Client libraries and the message packages only they give meaning to. geometry_msgs and
# friends exist in ROS 1 and ROS 2 alike, so they count for both.
ROS1_ONLY = {"rospy", "actionlib", "actionlib_msgs", "move_base_msgs", "genpy", "roslib"}
ROS1_ONLY |= {"rosgraph", "roslaunch", "rosbag", "tf", "tf2_ros"}
ROS2_ONLY = {"rclpy", "nav2_msgs", "action_msgs", "rosidl_runtime_py", "lifecycle_msgs"}
ROS2_ONLY |= {"builtin_interfaces", "launch", "launch_ros"}
SHARED_MSGS = {"geometry_msgs", "nav_msgs", "std_msgs", "std_srvs", "visualization_msgs"}
SHARED_MSGS |= {"tf2_msgs", "rosgraph_msgs"}


def imported_roots(path: Path) -> set[str]:
    """Top-level package names a module imports, anywhere in it (also inside functions)."""
    roots = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            roots.add(node.module.split(".")[0])
    return roots


def test_only_navseq_ros1_imports_rospy_and_only_navseq_ros2_rclpy():
    offenders = []
    for path in sorted(SRC.rglob("*.py")):
        package = path.relative_to(SRC).parts[0]
        roots = imported_roots(path)
        allowed = {"ros1": ROS1_ONLY | SHARED_MSGS, "ros2": ROS2_ONLY | SHARED_MSGS}.get(
            package, set()
        )
        wrong = (roots & (ROS1_ONLY | ROS2_ONLY | SHARED_MSGS)) - allowed
        if wrong:
            offenders.append(f"{path.relative_to(SRC)}: {sorted(wrong)}")
    assert offenders == []
    assert "rospy" in imported_roots(SRC / "ros1" / "navigator.py")  # the check sees imports


def _navseq_modules_imported(path: Path) -> set[str]:
    """Every ``navseq...`` module a module names in an import, anywhere in it."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return {name for name in names if name.split(".")[0] == "navseq"}


def test_ros1_and_ros2_never_import_each_other():
    """What ROS 1 and ROS 2 share lives in the ROS-free core (``navseq.roscore`` and the
    modules it uses); each client library's package only uses it."""
    offenders = []
    for own, other in (("ros1", "ros2"), ("ros2", "ros1")):
        for path in sorted((SRC / own).rglob("*.py")):
            wrong = {
                name
                for name in _navseq_modules_imported(path)
                if name.split(".")[:2] == ["navseq", other]
            }
            if wrong:
                offenders.append(f"{path.relative_to(SRC)}: {sorted(wrong)}")
    assert offenders == []
    # The check sees imports: the ROS 1 navigator does use the shared core.
    assert any(
        name.startswith("navseq.roscore")
        for name in _navseq_modules_imported(SRC / "ros1" / "navseq_node.py")
    )


def test_the_old_ros_package_is_gone():
    """``navseq.ros`` became ``navseq.ros1``; nothing external needed an alias."""
    assert not (SRC / "ros").exists()


def _runtime_imports(path: Path, modules: set[str]) -> set[str]:
    """The navseq modules a module imports when it runs (``if TYPE_CHECKING:`` blocks
    aside); ``from package import submodule`` counts as the submodule alone."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    typing_only = {
        id(inner)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for statement in node.body
        for inner in ast.walk(statement)
    }
    found: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            submodules = {f"{node.module}.{alias.name}" for alias in node.names} & modules
            found |= submodules
            if len(submodules) < len(node.names):
                found.add(node.module)
        elif isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
    return found & modules


def test_no_module_imports_itself_through_others():
    """No import circles (e.g. loader -> launch_xml -> rosparam_format -> params -> loader):
    every module can be read, and tested, from its dependencies up."""
    paths = {}
    for path in SRC.rglob("*.py"):
        parts = path.relative_to(SRC.parent).with_suffix("").parts
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    graph = {name: _runtime_imports(path, set(paths)) - {name} for name, path in paths.items()}
    circles = []
    for start in sorted(graph):
        # A path back to `start` through modules after it in sorted order (each circle once).
        stack = [(start, (start,))]
        seen = set()
        while stack:
            name, trail = stack.pop()
            for nxt in sorted(graph[name]):
                if nxt == start:
                    circles.append(" -> ".join((*trail, start)))
                elif nxt > start and nxt not in seen:
                    seen.add(nxt)
                    stack.append((nxt, (*trail, nxt)))
    assert circles == []
