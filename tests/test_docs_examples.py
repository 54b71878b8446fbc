"""Every shell command of the README and docs/ runs, so the docs cannot drift from the code.

Each markdown file's commands run in order in one scratch folder holding copies of
``examples/`` and ``maps/`` (so a command may use what an earlier one wrote, as a reader
following the page would). How a command runs is decided by the first :data:`RULES`
entry whose pattern it matches:

- ``run``: run it (``navseq`` / ``.venv/bin/navseq`` is this checkout's), compare its
  exit status and, in a ``console`` block, its output with the docs;
- ``interrupt``: a command that runs until stopped (``--loops forever``): run it for a
  few seconds, press Ctrl-C, expect the documented 130;
- ``make``: the Makefile target's own commands (``make -n``) run as above;
- ``collect``: a pytest command: the tests it names must exist (collected, not run:
  they run in this same suite);
- ``ros``: a command that needs a ROS 1 graph, a robot or a catkin workspace: the test
  that runs the same thing against real ROS is named, and must exist.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

from docs_examples import Example, examples_in, output_matches

REPO = Path(__file__).resolve().parents[1]
VENV_BIN = Path(sys.executable).parent
DOC_FILES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
TIMEOUT_S = 240.0
# A command the docs stop with Ctrl-C gets it once its run is under way (its first line
# out: the run folder is there), however long a loaded machine takes to start it, and
# after it has kept running this long.
STARTUP_TIMEOUT_S = 60.0
INTERRUPT_AFTER_S = 1.0


@dataclass(frozen=True)
class Rule:
    """How to check the commands matching ``pattern`` (a regex searched in the command)."""

    pattern: str
    kind: str
    covered_by: str = ""  # tests/FILE.py::TEST for kind "ros"


RULES: tuple[Rule, ...] = (
    Rule(r"^make (test|test-fast|test-pythons|venv)$", "make-ci"),
    Rule(r"^make demo\b", "make"),
    Rule(r"(^|/)pytest\b", "collect"),
    Rule(
        r"colcon build|^sudo apt install ros-|^source install/|~/ws|rosdep install --from-paths"
        r"|^ros2 launch (navseq |launch/)sim_navseq\.launch\.py",
        "ros",
        "tests/test_ros2_package.py::"
        "test_colcon_builds_the_package_and_ros2_run_and_launch_complete_the_mission",
    ),
    Rule(
        r"ros2 run navseq navseq_node|-m navseq\.ros2\.(navseq_node|sim_node --speed)|^PATH=",
        "ros",
        "tests/test_ros2_node.py::"
        "test_the_tutorial_params_alone_complete_with_one_log_line_per_waypoint_event",
    ),
    Rule(
        r"^source /opt/ros/",
        "ros",
        "tests/test_ros2_environment.py::test_a_ros2_process_talks_to_itself_on_a_private_domain",
    ),
    Rule(
        r"--other-robots|^ros2 launch launch/multi_robot\.launch\.py",
        "ros",
        "tests/test_ros2_fleet.py::test_robot1_drives_around_robot2_parked_on_its_straight_path",
    ),
    Rule(
        r"navseq sim --ros2 .*--docks|^ros2 action send_goal /(un)?dock_robot",
        "ros",
        "tests/test_ros2_docking.py::test_ros2_action_send_goal_docks_and_undocks",
    ),
    Rule(
        r"navseq sim --ros2 .*--route-graph|^ros2 action send_goal /compute_route",
        "ros",
        "tests/test_ros2_route_server.py::test_ros2_action_send_goal_computes_a_route",
    ),
    Rule(
        r"^ros2 topic pub .*/controller_selector",
        "ros",
        "tests/test_ros2_bt_topics.py::test_a_selection_published_with_the_ros2_cli_is_taken",
    ),
    Rule(
        r"navseq sim --ros2",
        "ros",
        "tests/test_ros2_cli.py::test_navseq_sim_ros2_serves_until_a_signal_and_exits_0",
    ),
    Rule(
        r"navseq sim --ros1",
        "ros",
        "tests/test_ros1_sim_cli.py::"
        "test_it_starts_a_master_serves_a_mission_and_leaves_nothing_behind",
    ),
    Rule(
        r"-m navseq\.ros2\.sim_node .*stop_on_failure",
        "ros",
        "tests/test_ros2_sim.py::test_follow_waypoints_goes_on_without_stop_on_failure",
    ),
    Rule(
        r"^ros2 launch launch/sim\.launch\.py",
        "ros",
        "tests/test_ros2_sim.py::test_the_launch_file_of_the_docs_starts_a_namespaced_robot",
    ),
    Rule(
        r"^ros2 action send_goal /navigate_to_pose",
        "ros",
        "tests/test_ros2_sim.py::test_the_ros2_cli_command_of_the_docs_drives_it",
    ),
    Rule(
        r"^ros2 action send_goal /follow_waypoints",
        "ros",
        "tests/test_ros2_sim.py::test_follow_waypoints_lists_a_missed_waypoint",
    ),
    Rule(
        r"^ros2 topic echo /odom",
        "ros",
        "tests/test_ros2_sim.py::test_a_client_cancel_ends_canceled_and_the_robot_stops",
    ),
    Rule(
        r"^ros2 service call /bt_navigator/get_state",
        "ros",
        "tests/test_ros2_sim.py::test_nav2_clients_find_it_ready_localized_and_can_clear_costmaps",
    ),
    Rule(
        r"rosrun navseq sim_robot_node .*_robot:=",
        "ros",
        "tests/test_ros_sim_robot_profile.py::"
        "test_a_waffle_is_simulated_with_its_outline_its_speed_and_its_room_to_turn",
    ),
    Rule(
        r"catkin_make|rosdep|^source devel/|^cd ~|^mkdir -p ~",
        "ros",
        "tests/test_catkin_package.py::"
        "test_catkin_make_builds_a_workspace_where_rosrun_and_roslaunch_find_the_nodes",
    ),
    Rule(
        r"^export ",
        "ros",
        "tests/test_launch_files.py::test_roslaunch_sim_launch_from_the_venv_serves_move_base",
    ),
    Rule(
        r"roslaunch navseq demo\.launch",
        "ros",
        "tests/test_launch_files.py::test_demo_launch_completes_the_example_mission_and_ends_quietly",
    ),
    Rule(
        r"roslaunch navseq sim\.launch",
        "ros",
        "tests/test_launch_files.py::test_roslaunch_sim_launch_from_the_venv_serves_move_base",
    ),
    Rule(
        r"roslaunch navseq navseq\.launch",
        "ros",
        "tests/test_launch_files.py::test_navseq_launch_with_only_the_tutorial_params_completes_on_the_sim",
    ),
    Rule(
        r"roslaunch navseq multi_robot\.launch",
        "ros",
        "tests/test_launch_files.py::test_multi_robot_launch_drives_two_namespaced_robots_at_once",
    ),
    Rule(
        r"rosrun navseq navseq_node",
        "ros",
        "tests/test_ros1_node.py::test_node_with_only_the_tutorial_params_completes_the_sequence",
    ),
    Rule(
        r"rosrun navseq sim_nav_node .*_race_window",
        "ros",
        "tests/test_ros_race.py::test_the_race_option_gives_a_client_that_sends_at_once_a_far_succeeded",
    ),
    Rule(
        r"--fleet .*--navigator (nav2|ros1)",
        "ros",
        "tests/test_fleet_ros.py::test_two_robots_swap_the_ends_of_a_one_robot_corridor",
    ),
    Rule(r"--navigator ros1", "ros", "tests/test_cli_ros1.py::test_ros1_run_completes_and_reports"),
    Rule(
        r"--navigator nav2",
        "ros",
        "tests/test_ros2_navigator.py::"
        "test_the_example_mission_completes_with_the_same_visits_as_on_the_simulator",
    ),
    Rule(
        r"navseq record\b",
        "ros",
        "tests/test_ros_record.py::test_every_goal_pose_becomes_a_waypoint_and_survives_ctrl_c",
    ),
    # A patrol runs until stopped, and so does its resume (it continues as journaled).
    Rule(r"--loops forever|--resume navseq-out/patrol-", "interrupt"),
    # The studio serves until Ctrl-C (tests/test_studio_browser.py drives its page).
    Rule(r"(^|/)navseq studio\b", "interrupt"),
    Rule(r"(^|/)navseq\b", "run"),
)


def rule_for(command: str) -> Rule:
    for rule in RULES:
        if re.search(rule.pattern, command):
            return rule
    raise AssertionError(f"no rule says how to test the docs command {command!r}: add one")


def _scratch(tmp_path: Path) -> Path:
    for folder in ("examples", "maps"):
        shutil.copytree(REPO / folder, tmp_path / folder)
    return tmp_path


def _argv(command: str, cwd: Path) -> list[str]:
    argv = shlex.split(command)
    navseq = str(VENV_BIN / "navseq")
    if argv[0] in ("navseq", ".venv/bin/navseq", "$(VENV)/bin/navseq"):
        argv[0] = navseq
    return [_concrete_path(arg, cwd) for arg in argv]


def _concrete_path(arg: str, cwd: Path) -> str:
    """The docs write run folders as `navseq-out/patrol-...`: the newest such folder."""
    match = re.match(r"^navseq-out/([\w.-]+?)-(\.\.\.|\d{8}-\d{6}(-\d+)?)(/.*)?$", arg)
    if not match:
        return arg
    runs = sorted((cwd / "navseq-out").glob(f"{match.group(1)}-*"), key=lambda p: p.stat().st_mtime)
    assert runs, f"the docs name a run folder {arg!r} but no earlier command made one"
    return str(runs[-1]) + (match.group(4) or "")


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env["PATH"] = f"{VENV_BIN}{os.pathsep}{env.get('PATH', '')}"
    env.pop("COLUMNS", None)
    return env


def _run(example: Example, command: str, cwd: Path) -> None:
    done = subprocess.run(
        _argv(command, cwd),
        cwd=cwd,
        env=_environment(),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=TIMEOUT_S,
    )
    output = done.stdout.splitlines()
    assert done.returncode == example.expected_status, (
        f"{example.where}: `{example.command}` exited {done.returncode}, the docs say "
        f"{example.expected_status}:\n{done.stdout[-3000:]}"
    )
    if example.expected_output is not None:
        assert output_matches(example.expected_output, output), (
            f"{example.where}: `{example.command}` printed\n{done.stdout}\n"
            "which does not match the docs:\n" + "\n".join(example.expected_output)
        )


def _interrupt(example: Example, cwd: Path) -> None:
    process = subprocess.Popen(
        _argv(example.command, cwd),
        cwd=cwd,
        env=_environment(),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    lines: list[str] = []
    started = threading.Event()

    def read() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            lines.append(line)
            started.set()
        started.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        started.wait(STARTUP_TIMEOUT_S)
        time.sleep(INTERRUPT_AFTER_S)
        assert process.poll() is None, (
            f"{example.where}: `{example.command}` ended by itself:\n{''.join(lines)[-3000:]}"
        )
        process.send_signal(signal.SIGINT)
        process.wait(timeout=60)
        reader.join(timeout=10)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    output = "".join(lines)
    assert process.returncode == 130, (
        f"{example.where}: Ctrl-C gave {process.returncode}:\n{output[-3000:]}"
    )


def _make(example: Example, cwd: Path) -> None:
    target = example.command.split()[1]
    dry = subprocess.run(["make", "-n", target], cwd=REPO, capture_output=True, text=True)
    commands = [
        line
        for line in dry.stdout.splitlines()
        if "/bin/navseq " in line and not line.startswith("scripts/")
    ]
    assert commands, f"{example.where}: `make -n {target}` runs no navseq command:\n{dry.stdout}"
    for command in commands:
        _run(example, command.replace(".venv/bin/navseq", "navseq"), cwd)


def _make_ci(example: Example, cwd: Path) -> None:
    # `make test` is what CI runs (this very suite), then `make test-pythons`; `make venv`
    # is `make test`'s first step and `make test-fast` a part of it (no ROS, no browser).
    ci = (REPO / ".ci" / "run").read_text()
    assert re.search(r"^make test$", ci, re.MULTILINE), ".ci/run must run the README's test command"
    target = example.command.split()[1]
    if target not in ("venv", "test-fast"):
        assert re.search(rf"^make {target}$", ci, re.MULTILINE), f".ci/run must run {target}"
    assert re.search(rf"^{target}:", (REPO / "Makefile").read_text(), re.MULTILINE)


def _collect(example: Example, cwd: Path) -> None:
    argv = [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"]
    argv += [arg for arg in shlex.split(example.command)[1:]]
    done = subprocess.run(argv, cwd=REPO, capture_output=True, text=True, timeout=TIMEOUT_S)
    assert done.returncode == 0, (
        f"{example.where}: `{example.command}` does not collect:\n"
        f"{done.stdout[-2000:]}{done.stderr[-2000:]}"
    )


def _covered(rule: Rule, example: Example) -> None:
    test_file, test_name = rule.covered_by.split("::")
    source = (REPO / test_file).read_text()
    assert re.search(rf"^def {test_name}\(", source, re.MULTILINE), (
        f"{example.where}: `{example.command}` is said to be tested by {rule.covered_by}, "
        "which does not exist"
    )


CHECKS: dict[str, Callable[[Rule, Example, Path], None]] = {
    "run": lambda rule, example, cwd: _run(example, example.command, cwd),
    "interrupt": lambda rule, example, cwd: _interrupt(example, cwd),
    "make": lambda rule, example, cwd: _make(example, cwd),
    "make-ci": lambda rule, example, cwd: _make_ci(example, cwd),
    "collect": lambda rule, example, cwd: _collect(example, cwd),
    "ros": lambda rule, example, cwd: _covered(rule, example),
}


@pytest.mark.slow
@pytest.mark.parametrize("doc", DOC_FILES, ids=lambda path: path.name)
def test_every_shell_command_of_the_docs_does_what_the_docs_say(doc: Path, tmp_path: Path) -> None:
    cwd = _scratch(tmp_path)
    for example in examples_in(doc):
        rule = rule_for(example.command)
        CHECKS[rule.kind](rule, example, cwd)


def test_the_docs_have_shell_examples_and_each_has_a_rule() -> None:
    found = [example for doc in DOC_FILES for example in examples_in(doc)]
    assert len(found) >= 20, [example.command for example in found]
    for example in found:
        rule_for(example.command)
