"""``navseq sim --ros2``: its options, and one clear error where ROS 2 is missing."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ros2_support import ros2_environment, ros2_prefix
from test_layers import run_without_ros

REPO = Path(__file__).resolve().parents[1]
MAP = REPO / "maps" / "turtlebot3_world.yaml"
CLI = "import sys\nfrom navseq.cli import main\nsys.exit(main(sys.argv[1:]))\n"


def test_without_ros2_navseq_sim_says_to_source_it_and_exits_2():
    done = run_without_ros(CLI, "sim", "--ros2", "--map", str(MAP))
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "source ROS 2 first" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--speed", "0"], "--speed: must be > 0"),
        (["--speed", "nan"], "--speed: must be > 0"),
        (["--ns", "1robot"], "is not a ROS 2 namespace"),
        (["--map", "no/such/map.yaml"], "no such file"),
        (["--robot", "roomba"], "neither a built-in robot"),
        (["--replan-period", "-1"], "--replan-period: must be >= 0 s, got -1"),
    ],
)
def test_bad_options_are_one_clear_error_even_without_ros2(options, message):
    done = run_without_ros(CLI, "sim", "--ros2", "--map", str(MAP), *options)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.ros2
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_navseq_sim_ros2_serves_until_a_signal_and_exits_0(signum):
    prefix = ros2_prefix()
    assert prefix is not None
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "navseq",
            "sim",
            "--ros2",
            "--map",
            str(MAP),
            "--start",
            "-2,-0.5,0",
            "--ns",
            "r2",
        ],
        env=ros2_environment(prefix),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None
    ready = process.stdout.readline()
    assert "ready: /r2/navigate_to_pose" in ready
    assert "robot at (-2.00, -0.50)" in ready
    time.sleep(1.0)
    process.send_signal(signum)
    _, err = process.communicate(timeout=20)
    assert process.returncode == 0, err
    assert "Traceback" not in err
