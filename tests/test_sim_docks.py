"""The docks file of ``navseq sim --ros2 --docks`` (Nav2's docks formats), without ROS:
both of Nav2's forms read, and every mistake one clear error naming file:line."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.sim.docks import Dock, read_docks_file
from navseq.sim.options import checked_config
from test_layers import run_without_ros

REPO = Path(__file__).resolve().parents[1]
MAP = REPO / "maps" / "turtlebot3_world.yaml"
CLI = "import sys\nfrom navseq.cli import main\nsys.exit(main(sys.argv[1:]))\n"


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "docks.yaml"
    path.write_text(text)
    return path


def test_the_example_docks_file_reads_as_nav2s_parameters_form() -> None:
    docks = read_docks_file(REPO / "examples" / "turtlebot3_docks.yaml")
    assert docks == (
        Dock("home_dock", "simple_charging_dock", "map", Pose2D(-0.5, -0.5, 0.0)),
        Dock("north_dock", "simple_charging_dock", "map", Pose2D(-0.5, 0.5, 0.0)),
    )


def test_the_dock_database_form_and_a_params_file_read_the_same(tmp_path: Path) -> None:
    database = write(
        tmp_path, "docks:\n  charger:\n    type: simple_charging_dock\n    pose: [1, 2, 1.57]\n"
    )
    expected = (Dock("charger", "simple_charging_dock", "map", Pose2D(1.0, 2.0, 1.57)),)
    assert read_docks_file(database) == expected
    params = tmp_path / "nav2_params.yaml"
    params.write_text(
        "docking_server:\n  ros__parameters:\n    dock_plugins: ['simple_charging_dock']\n"
        "    docks: ['charger']\n    charger:\n      frame: map\n      pose: [1.0, 2.0, 1.57]\n"
    )
    assert read_docks_file(params) == expected


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("docks: [a]\n", "docks.yaml:1: dock 'a' is listed in docks: but has no section"),
        ("docks: [a]\na: {pose: [1, 2]}\n", "docks.yaml:2, dock 'a': pose must be three numbers"),
        ("docks: [a]\na: {pose: [1, 2, x]}\n", "pose must be three numbers"),
        (
            "docks: [a]\na:\n  type: magnet\n  pose: [0, 0, 0]\n",
            "docks.yaml:3, dock 'a': type 'magnet'",
        ),
        ("docks: [a]\na: {frame: odom, pose: [0, 0, 0]}\n", "frame 'odom'"),
        ("docks: [a]\na: {pose: [0, 0, 0], colour: red}\n", "unknown field 'colour'"),
        ("docks: {}\n", "docks: is empty"),
        ("charger: {pose: [0, 0, 0]}\n", "has no docks:"),
        ("docks: 3\n", "must be a list of dock names or a mapping"),
    ],
)
def test_a_mistake_is_one_error_naming_file_and_line(
    tmp_path: Path, text: str, message: str
) -> None:
    with pytest.raises(NavseqError) as caught:
        read_docks_file(write(tmp_path, text))
    assert message in str(caught.value)


def test_docks_are_part_of_the_ros2_simulators_checked_settings(tmp_path: Path) -> None:
    config = checked_config(map_yaml=MAP, docks=REPO / "examples" / "turtlebot3_docks.yaml")
    assert [dock.name for dock in config.docks] == ["home_dock", "north_dock"]
    assert math.isclose(config.docks[0].pose.x, -0.5)
    with pytest.raises(NavseqError, match="--docks: docking is Nav2's"):
        checked_config(map_yaml=MAP, docks=REPO / "examples" / "turtlebot3_docks.yaml", ros1=True)


def test_navseq_sim_refuses_a_bad_docks_file_before_any_ros(tmp_path: Path) -> None:
    bad = write(tmp_path, "docks: [a]\na: {pose: [1, 2]}\n")
    done = run_without_ros(CLI, "sim", "--ros2", "--map", str(MAP), "--docks", str(bad))
    assert done.returncode == 2, done.stderr
    assert "docks.yaml:2, dock 'a': pose must be three numbers" in done.stderr
    assert "Traceback" not in done.stderr
    missing = run_without_ros(CLI, "sim", "--ros2", "--map", str(MAP), "--docks", "no/docks.yaml")
    assert missing.returncode == 2 and "no such file" in missing.stderr
