"""Missions written back out: the ``robot:`` section (mission writer) and the tutorial's
launch file (``p_seq`` / ``yea_seq``, :mod:`navseq.mission.tutorial_export`)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from navseq.errors import NavseqError
from navseq.mission import load_mission, write_mission
from navseq.mission.tutorial_export import tutorial_launch_text, write_tutorial_launch

REPO = Path(__file__).resolve().parents[1]


def written_and_read(tmp_path: Path, text: str) -> tuple[object, object, str]:
    source = tmp_path / "in.yaml"
    source.write_text(text, encoding="utf-8")
    mission = load_mission(source)
    out = tmp_path / "out.yaml"
    write_mission(mission, out)
    return mission, load_mission(out), out.read_text(encoding="utf-8")


def test_a_modified_robot_section_survives_a_write_and_a_read(tmp_path: Path) -> None:
    mission, again, text = written_and_read(
        tmp_path,
        "navseq: 1\n"
        "robot:\n"
        "  base: turtlebot3_waffle\n"
        "  radius: 0.2\n"
        "  max_angular_speed: 90\n"
        "  yaw_goal_tolerance: 10\n"
        "  inflation_radius: 0.7\n"
        "waypoints:\n"
        "  - {x: 1, y: 2, yaw: 30}\n",
    )
    assert again == mission  # the robot included (every field but where it was read)
    assert again.robot == mission.robot  # type: ignore[attr-defined]
    assert again.robot.name == "turtlebot3_waffle (modified)"  # type: ignore[attr-defined]
    # In the file's units: degrees where the reader takes degrees.
    assert "max_angular_speed: 90\n" in text and "yaw_goal_tolerance: 10\n" in text
    # 3.2 rad/s² (the waffle's) has no short decimal in deg/s²; it still reads back exactly.
    assert again.robot.max_angular_accel == 3.2  # type: ignore[attr-defined]


def test_a_builtin_robot_is_written_by_its_name(tmp_path: Path) -> None:
    mission, again, text = written_and_read(
        tmp_path, "navseq: 1\nrobot: turtlebot3_waffle_pi\nwaypoints: [{x: 1, y: 2, yaw: 3}]\n"
    )
    assert "robot: turtlebot3_waffle_pi\n" in text
    assert again == mission


def test_a_custom_footprint_and_name_round_trip(tmp_path: Path) -> None:
    mission, again, text = written_and_read(
        tmp_path,
        "navseq: 1\nrobot:\n  name: cart\n"
        "  footprint: [[-0.3, -0.2], [-0.3, 0.2], [0.25, 0.2], [0.25, -0.2]]\n"
        "  max_linear_speed: 0.5\n  clearance_margin: 0.05\n"
        "waypoints: [{x: 0, y: 0, yaw: 0}]\n",
    )
    assert again == mission
    assert "    - [-0.3, -0.2]\n" in text  # one point a line
    assert again.robot.footprint[2] == (0.25, 0.2)  # type: ignore[attr-defined]


def test_the_tutorial_launch_file_reads_back_as_the_same_poses(tmp_path: Path) -> None:
    mission = load_mission(REPO / "examples/turtlebot3_world.yaml")
    target = tmp_path / "move_base_seq.launch"
    launch = write_tutorial_launch(mission, target)
    again = load_mission(target)
    assert [(w.x, w.y, w.z) for w in again.waypoints] == [
        (w.x, w.y, w.z) for w in mission.waypoints
    ]
    assert [w.yaw_deg for w in again.waypoints] == pytest.approx(
        [w.yaw_deg for w in mission.waypoints], abs=1e-9
    )
    text = target.read_text(encoding="utf-8")
    assert '<rosparam param="p_seq">[-0.55, -1.75, 0.0, 1.75, -0.55, 0.0,' in text
    assert '<rosparam param="yea_seq">[0, 90, 180, 180, -90, -45, 0]</rosparam>' in text
    assert 'pkg="simple_navigation_goals" type="move_base_seq.py"' in text
    # What the tutorial's format cannot hold is said, in the file and to the caller.
    assert "waypoint names" in launch.left_out and "start" in launch.left_out
    assert any(item.startswith("per-waypoint pass_through") for item in launch.left_out)
    assert "no place for" in text


def test_the_tutorials_own_launch_file_round_trips_with_nothing_left_out(tmp_path: Path) -> None:
    mission = load_mission(REPO / "examples/tutorial_move_base_seq.launch")
    launch = tutorial_launch_text(mission)
    assert launch.left_out == ()
    assert "<!--" not in launch.text
    target = tmp_path / "again.launch"
    target.write_text(launch.text, encoding="utf-8")
    assert load_mission(target).waypoints == mission.waypoints


def test_odd_yaws_and_coordinates_are_kept_exactly(tmp_path: Path) -> None:
    from navseq.mission.model import Mission, Waypoint

    mission = Mission(
        (
            Waypoint(0.1 + 0.2, -1e-7, yaw_rad=1.0),  # radians from a quaternion
            Waypoint(12345.678, 2.5, yaw_deg=-179.5, z=0.25),
        )
    )
    target = tmp_path / "odd.launch"
    write_tutorial_launch(mission, target)
    again = load_mission(target).waypoints
    assert (again[0].x, again[0].y) == (0.1 + 0.2, -1e-7)
    assert again[0].yaw_rad == pytest.approx(1.0, abs=math.radians(1e-6))
    assert (again[1].x, again[1].z, again[1].yaw_deg) == (12345.678, 0.25, -179.5)


def test_the_launch_writer_refuses_to_overwrite_or_write_nothing(tmp_path: Path) -> None:
    from navseq.mission.model import Mission, Waypoint

    target = tmp_path / "taken.launch"
    target.write_text("<launch/>\n", encoding="utf-8")
    with pytest.raises(NavseqError, match="exists already"):
        write_tutorial_launch(Mission((Waypoint(1.0, 2.0),)), target)
    assert target.read_text(encoding="utf-8") == "<launch/>\n"
    write_tutorial_launch(Mission((Waypoint(1.0, 2.0),)), target, overwrite=True)
    assert load_mission(target).waypoints[0].x == 1.0
    with pytest.raises(NavseqError, match="no waypoints"):
        write_tutorial_launch(Mission(()), tmp_path / "empty.launch")


def test_navseq_convert_writes_the_launch_file_for_a_launch_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from navseq.cli import main

    target = tmp_path / "tour.launch"
    assert main(["convert", str(REPO / "examples/turtlebot3_world.yaml"), str(target)]) == 0
    assert len(load_mission(target).waypoints) == 7
    assert "p_seq" in target.read_text(encoding="utf-8")
    assert "no place for: waypoint names" in capsys.readouterr().err
    assert main(["convert", str(REPO / "examples/turtlebot3_world.yaml"), str(target)]) == 2
