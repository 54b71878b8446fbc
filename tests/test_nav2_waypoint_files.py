"""Nav2 users' waypoint files: the RViz panel's save file and echoed PoseArray / Path.

The panel's file is written as nav2_rviz_plugins' Nav2Panel::handleGoalSaver writes it
(yaml-cpp's block style, orientation w first); echoes as ``ros2 topic echo`` prints them.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cli_support import TURTLEBOT3_MAP, assert_clean_error, navseq
from navseq.errors import NavseqError
from navseq.mission import load_mission, validate_mission_file
from navseq.mission.nav2_waypoints_format import dump_nav2_panel

# As the panel saves it (Jazzy): yaml-cpp block lists, orientation [w, x, y, z].
PANEL_FILE = """\
waypoints:
  waypoint0:
    pose:
      - 0.5
      - -1.5
      - 0
    orientation:
      - 1
      - 0
      - 0
      - 0
  waypoint1:
    pose:
      - 1.7
      - 0.5
      - 0
    orientation:
      - 0.70710678118654757
      - 0
      - 0
      - 0.70710678118654746
  waypoint2:
    pose:
      - -1.2
      - 0.4
      - 0
    orientation:
      - 6.123233995736766e-17
      - 0
      - 0
      - 1
"""

POSE = """\
- position:
    x: {x}
    y: {y}
    z: 0.0
  orientation:
    x: 0.0
    y: 0.0
    z: {qz}
    w: {qw}
"""


def pose_array(frame: str, poses: list[tuple[float, float, float, float]]) -> str:
    body = "".join(POSE.format(x=x, y=y, qz=qz, qw=qw) for x, y, qz, qw in poses)
    return (
        f"header:\n  stamp:\n    sec: 1700000000\n    nanosec: 250000000\n"
        f"  frame_id: {frame}\nposes:\n{body}"
    )


def path_message(frame: str, poses: list[tuple[float, float, float, float]]) -> str:
    """A nav_msgs/Path as ros2 topic echo prints it: each pose a PoseStamped."""
    items = "".join(
        f"- header:\n    stamp:\n      sec: 0\n      nanosec: 0\n    frame_id: {frame}\n"
        f"  pose:\n    position:\n      x: {x}\n      y: {y}\n      z: 0.0\n"
        f"    orientation:\n      x: 0.0\n      y: 0.0\n      z: {qz}\n      w: {qw}\n"
        for x, y, qz, qw in poses
    )
    return f"header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: {frame}\nposes:\n{items}"


def poses_of(path: Path) -> list[tuple[float, float, float]]:
    mission = load_mission(path)
    return [(w.x, w.y, round(w.yaw_deg, 6)) for w in mission.waypoints]


def test_the_panels_file_reads_in_file_order_in_map_with_w_first(tmp_path: Path) -> None:
    path = tmp_path / "wp.yaml.yaml"  # the panel appends .yaml to the name chosen
    path.write_text(PANEL_FILE)
    assert poses_of(path) == [(0.5, -1.5, 0.0), (1.7, 0.5, 90.0), (-1.2, 0.4, 180.0)]
    assert load_mission(path).frame == "map"


def test_the_panels_format_written_reads_back_the_same(tmp_path: Path) -> None:
    source = tmp_path / "panel.yaml"
    source.write_text(PANEL_FILE)
    again = tmp_path / "again.yaml"
    again.write_text(dump_nav2_panel(load_mission(source)))
    assert poses_of(again) == poses_of(source)


def test_a_bad_panel_entry_is_refused_with_its_line(tmp_path: Path) -> None:
    path = tmp_path / "panel.yaml"
    path.write_text(PANEL_FILE.replace("      - -1.5\n      - 0\n", "      - -1.5\n", 1))
    errors = validate_mission_file(path)
    assert [str(e) for e in errors] == [
        f"{path}:4, waypoint 1 (waypoint0), field pose: must be a list of 3 numbers [x, y, z]"
    ]


def test_a_pose_array_echo_reads_its_frame(tmp_path: Path) -> None:
    path = tmp_path / "poses.yaml"
    path.write_text(pose_array("odom", [(1.0, 2.0, 0.0, 1.0), (3.0, -1.0, 1.0, 0.0)]) + "---\n")
    assert poses_of(path) == [(1.0, 2.0, 0.0), (3.0, -1.0, 180.0)]
    assert load_mission(path).frame == "odom"


def test_an_echo_of_several_messages_gives_the_last(tmp_path: Path) -> None:
    first = path_message("map", [(9.0, 9.0, 0.0, 1.0)])
    last = path_message("map", [(0.5, 0.5, math.sin(math.pi / 4), math.cos(math.pi / 4))])
    path = tmp_path / "plan.yaml"
    path.write_text(f"{first}---\n{last}---\n")
    assert poses_of(path) == [(0.5, 0.5, 90.0)]


def test_a_bad_value_in_the_last_echoed_message_names_its_file_line(tmp_path: Path) -> None:
    first = pose_array("map", [(1.0, 1.0, 0.0, 1.0)])
    path = tmp_path / "poses.yaml"
    path.write_text(
        f"{first}---\n" + pose_array("map", [(1.0, 1.0, 0.0, 1.0)]).replace("x: 1.0", "x: far", 1)
    )
    lines = path.read_text().splitlines()
    line = next(i for i, text in enumerate(lines, 1) if "far" in text)
    with pytest.raises(NavseqError) as error:
        load_mission(path)
    assert str(error.value).startswith(f"{path}:{line}, waypoint 1, field x: must be a number")


def test_convert_writes_the_panels_format_and_says_what_it_left_out(tmp_path: Path) -> None:
    (tmp_path / "m.yaml").write_text(
        "waypoints:\n  - {x: 0.5, y: -1.5, yaw: 90, name: dock}\n  - {x: 1.0, y: 0.0}\n"
    )
    result = navseq("convert", "m.yaml", "wp.yaml", "--to", "nav2-panel", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "waypoint names" in result.stderr
    assert poses_of(tmp_path / "wp.yaml") == [(0.5, -1.5, 90.0), (1.0, 0.0, 0.0)]
    again = navseq("convert", "wp.yaml", "wp.yaml", "--to", "nav2-panel", cwd=tmp_path)
    assert again.returncode != 0
    assert_clean_error(again)
    assert "not overwriting" in again.stderr


def test_run_drives_a_panel_file_on_the_simulator(tmp_path: Path) -> None:
    (tmp_path / "wp.yaml").write_text(
        "waypoints:\n  waypoint0:\n    pose: [-1.6, -0.5, 0.0]\n"
        "    orientation: [1.0, 0.0, 0.0, 0.0]\n"
    )
    result = navseq(
        "run",
        "wp.yaml",
        "--map",
        TURTLEBOT3_MAP,
        "--start",
        "-2,-0.5,0",
        "--out",
        "out",
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stdout + result.stderr
