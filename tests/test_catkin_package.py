"""The repository is a catkin package: package.xml, CMakeLists.txt, setup.py, nodes/.

Fast checks read the package files and run catkin's own setup.py interrogation; the
slow test builds a real catkin workspace (``catkin_make`` with a link to this repo in
``src/``), installs it, and asks ``rosrun`` and ``roslaunch`` where the nodes are.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ros_support import REPO_ROOT

catkin_pkg = pytest.importorskip("catkin_pkg.package", reason="catkin_pkg not installed")

NODES = REPO_ROOT / "nodes"
INTERROGATE = Path("/usr/share/catkin/cmake/interrogate_setup_dot_py.py")
SYSTEM_PYTHON = "/usr/bin/python3"
MESSAGE_PACKAGES = {
    "actionlib",
    "actionlib_msgs",
    "move_base_msgs",
    "geometry_msgs",
    "nav_msgs",
    "std_srvs",
    "visualization_msgs",
    "tf2_ros",
    "rospy",
}


def node_scripts() -> list[Path]:
    return sorted(path for path in NODES.iterdir() if path.is_file())


def test_package_xml_is_valid_format_3_with_the_pip_version():
    package = catkin_pkg.parse_package(REPO_ROOT / "package.xml")
    package.validate()
    assert package.name == "navseq"
    assert package.package_format == 3
    pyproject = (REPO_ROOT / "pyproject.toml").read_text()
    pip_version = re.search(r'^version = "([^"]+)"', pyproject, re.M)
    assert pip_version and package.version == pip_version.group(1)
    exec_depends = {dep.name for dep in package.exec_depends}
    assert exec_depends >= MESSAGE_PACKAGES
    assert {"python3-numpy", "python3-scipy", "python3-yaml"} <= exec_depends


def test_every_node_script_is_an_executable_relay_to_a_main_and_is_installed():
    cmake = (REPO_ROOT / "CMakeLists.txt").read_text()
    install_block = re.search(r"catkin_install_python\((.*?)\)", cmake, re.S)
    assert install_block, "CMakeLists.txt must install the nodes with catkin_install_python"
    scripts = node_scripts()
    assert {p.name for p in scripts} >= {"sim_robot_node", "sim_nav_node", "navseq_node"}
    for script in scripts:
        text = script.read_text()
        assert text.startswith("#!/usr/bin/env python3\n"), script
        assert os.access(script, os.X_OK), f"{script} is not executable"
        module = re.search(r"^from (navseq\.ros1\.\w+) import main$", text, re.M)
        assert module, f"{script} should only import and call navseq.ros1.<module>.main"
        assert f"nodes/{script.name}" in install_block.group(1), f"{script} not installed"


def test_catkin_reads_the_python_package_from_setup_py(tmp_path: Path):
    if not INTERROGATE.exists():
        pytest.skip("catkin (Debian package) not installed")
    out = tmp_path / "interrogation.cmake"
    subprocess.run(
        [SYSTEM_PYTHON, INTERROGATE, "navseq", REPO_ROOT / "setup.py", out],
        check=True,
        capture_output=True,
        cwd=tmp_path,
    )
    text = out.read_text()
    assert 'set(navseq_SETUP_PY_VERSION "0.1.0")' in text
    assert 'set(navseq_SETUP_PY_PACKAGES "navseq")' in text
    assert 'set(navseq_SETUP_PY_PACKAGE_DIRS "src/navseq")' in text


def _workspace_env(workspace: Path, devel_or_install: str) -> dict[str, str]:
    """The environment after ``source <space>/setup.bash``."""
    dump = subprocess.run(
        ["bash", "-c", f"source {workspace / devel_or_install / 'setup.bash'} && env -0"],
        check=True,
        capture_output=True,
        env={k: v for k, v in os.environ.items() if not k.startswith("ROS_")},
    ).stdout.decode()
    return dict(item.split("=", 1) for item in dump.split("\0") if "=" in item)


@pytest.mark.slow
def test_catkin_make_builds_a_workspace_where_rosrun_and_roslaunch_find_the_nodes(
    tmp_path: Path,
):
    if not shutil.which("catkin_make"):
        pytest.skip("catkin_make not installed (Debian package catkin)")
    workspace = tmp_path / "ws"
    (workspace / "src").mkdir(parents=True)
    (workspace / "src" / "navseq").symlink_to(REPO_ROOT)
    build_env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
    for target in ([], ["install"]):
        result = subprocess.run(
            ["catkin_make", "-C", str(workspace), *target, f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}"],
            cwd=workspace,
            capture_output=True,
            text=True,
            env=build_env,
        )
        assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]

    devel = _workspace_env(workspace, "devel")
    rospack = subprocess.run(
        ["rospack", "find", "navseq"], env=devel, capture_output=True, text=True, check=True
    )
    assert Path(rospack.stdout.strip()).resolve() == REPO_ROOT
    for script in node_scripts():
        # catkin's devel-space relay, run by the configured interpreter, wins over nodes/.
        found = subprocess.run(
            ["rosrun", "--prefix", "echo", "navseq", script.name],
            env=devel,
            capture_output=True,
            text=True,
        )
        assert found.returncode == 0, found.stdout + found.stderr
        relay = Path(found.stdout.split()[0])
        assert relay == workspace / "devel" / "lib" / "navseq" / script.name
        assert relay.read_text().startswith(f"#!{SYSTEM_PYTHON}\n")
    args = subprocess.run(
        ["roslaunch", "--args", "/sim_robot", "navseq", "sim.launch"],
        env=devel,
        capture_output=True,
        text=True,
    )
    assert args.returncode == 0, args.stdout + args.stderr
    assert str(workspace / "devel" / "lib" / "navseq" / "sim_robot_node") in args.stdout
    # The navseq package itself comes from the source tree through the devel space.
    imported = subprocess.run(
        [SYSTEM_PYTHON, "-c", "import navseq.errors, navseq; print(navseq.__path__)"],
        env=devel,
        capture_output=True,
        text=True,
    )
    assert imported.returncode == 0, imported.stderr
    assert str(workspace / "src" / "navseq" / "src" / "navseq") in imported.stdout

    # The install space is self-contained: scripts, Python package, launch, maps, RViz.
    install = workspace / "install"
    for script in node_scripts():
        installed = install / "lib" / "navseq" / script.name
        assert os.access(installed, os.X_OK), installed
        assert installed.read_text().startswith("#!/usr/bin/env python3\n")
    python_dir = install / "lib" / "python3" / "dist-packages" / "navseq"
    assert (python_dir / "ros1" / "sim_nav_node.py").is_file()
    assert (python_dir / "sim" / "navserver.py").is_file()
    share = install / "share" / "navseq"
    for relative in ("package.xml", "launch/sim.launch", "maps/turtlebot3_world.yaml"):
        assert (share / relative).is_file(), relative
    installed_env = _workspace_env(workspace, "install")
    rospack = subprocess.run(
        ["rospack", "find", "navseq"], env=installed_env, capture_output=True, text=True
    )
    assert rospack.stdout.strip() == str(share)


def test_pip_metadata_is_untouched_by_the_catkin_setup_py():
    """Outside catkin, setup.py adds nothing but packages and the optional C extension."""
    result = subprocess.run(
        [sys.executable, "setup.py", "--name", "--version"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split()[-2:] == ["navseq", "0.1.0"]
