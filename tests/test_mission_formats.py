"""Every mission source format gives the poses and settings the user wrote."""

import math
from pathlib import Path

import pytest

from navseq.mission import (
    FailureAction,
    Mission,
    Policy,
    load_mission,
    mission_from_params,
    validate_mission_file,
)

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def poses(mission: Mission) -> list[tuple[float, float, float]]:
    return [(w.x, w.y, round(math.degrees(w.yaw_rad), 6)) for w in mission.waypoints]


# --- the tutorial's formats ----------------------------------------------------------


def test_tutorial_launch_file_gives_its_three_waypoints_with_yaws_in_radians():
    mission = load_mission(EXAMPLES / "tutorial_move_base_seq.launch")
    assert [(w.x, w.y, w.z) for w in mission.waypoints] == [
        (-1.0, -4.0, 0.0),
        (1.0, -4.0, 0.0),
        (1.0, -1.0, 0.0),
    ]
    assert [w.yaw_rad for w in mission.waypoints] == pytest.approx(
        [math.pi / 2, 0.0, math.pi], abs=1e-12
    )
    # The tutorial stops at every point and knows no timeouts: so do navseq's defaults.
    assert mission.defaults == Policy()
    assert mission.frame == "map" and mission.loops == 1


def test_launch_file_with_rosparam_yaml_body_in_a_group(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <group ns="robot1">
    <node pkg="navseq" type="navseq_node" name="navseq">
      <rosparam>
        p_seq: [0.5, -1.6, 0,  1.6, 0.5, 0]
        yea_seq: [60, 150]
        goal_timeout: 45
      </rosparam>
    </node>
  </group>
</launch>
""",
    )
    mission = load_mission(path)
    assert poses(mission) == [(0.5, -1.6, 60.0), (1.6, 0.5, 150.0)]
    assert mission.defaults.goal_timeout_s == 45.0
    assert mission.waypoints[0].where == f"{path}:5"


def test_launch_file_with_param_values(tmp_path):
    path = write(
        tmp_path,
        "seq.xml",
        """<?xml version="1.0"?>
<launch>
  <arg name="unused" default="1"/>
  <node pkg="simple_navigation_goals" type="move_base_seq.py" name="move_base_seq">
    <param name="p_seq" value="[1, 2, 0, 3, 4, 0]"/>
    <param name="yea_seq" value="[0, -90]"/>
    <param name="frame" value="odom"/>
  </node>
  <node pkg="map_server" type="map_server" name="map_server" args="map.yaml"/>
</launch>
""",
    )
    mission = load_mission(path)
    assert poses(mission) == [(1.0, 2.0, 0.0), (3.0, 4.0, -90.0)]
    assert mission.frame == "odom"


def test_launch_file_rosparam_file_is_followed_relative_to_the_launch_file(tmp_path):
    write(tmp_path, "points.yaml", "p_seq: [1, 1, 0]\nyea_seq: [45]\n")
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <node pkg="p" type="t" name="seq">
    <rosparam command="load" file="points.yaml"/>
  </node>
</launch>""",
    )
    assert poses(load_mission(path)) == [(1.0, 1.0, 45.0)]


def test_launch_file_may_name_a_mission_file(tmp_path):
    path = write(
        tmp_path,
        "run.launch",
        f"""<launch>
  <node pkg="navseq" type="navseq_node" name="navseq">
    <param name="mission" value="{EXAMPLES / "patrol.yaml"}"/>
    <param name="loops" value="2"/>
  </node>
</launch>""",
    )
    mission = load_mission(path)
    assert [w.name for w in mission.waypoints] == ["south", "east", "north", "west"]
    assert mission.loops == 2


def test_launch_file_elements_switched_off_by_if_are_ignored(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <node pkg="p" type="t" name="seq">
    <rosparam param="p_seq">[1, 1, 0]</rosparam>
    <rosparam param="yea_seq">[10]</rosparam>
    <rosparam param="yea_seq" if="false">[20]</rosparam>
  </node>
</launch>""",
    )
    assert poses(load_mission(path)) == [(1.0, 1.0, 10.0)]


def test_rosparam_file_nested_under_the_node_name():
    mission = load_mission(EXAMPLES / "tutorial_params.yaml")
    assert mission.source == str(EXAMPLES / "tutorial_params.yaml")
    assert poses(mission) == [
        (-1.6, -0.5, -30.0),
        (0.5, -1.6, 60.0),
        (1.6, 0.5, 150.0),
        (-0.5, 1.6, -120.0),
    ]


def test_rosparam_file_at_top_level(tmp_path):
    path = write(tmp_path, "params.yml", "p_seq: [1, 2, 3]\nyea_seq: [90]\n")
    (waypoint,) = load_mission(path).waypoints
    assert (waypoint.x, waypoint.y, waypoint.z) == (1.0, 2.0, 3.0)
    assert waypoint.yaw_rad == pytest.approx(math.pi / 2)


# --- CSV -----------------------------------------------------------------------------


def test_recorded_csv_turns_quaternions_into_yaws():
    mission = load_mission(EXAMPLES / "recorded.csv")
    assert [(x, y) for x, y, _ in poses(mission)] == [
        (-1.6, -0.5),
        (0.5, -1.6),
        (1.6, 0.5),
        (-0.5, 1.6),
        (-2.0, -0.5),
    ]
    assert [yaw for _, _, yaw in poses(mission)] == pytest.approx(
        [-30.0, 60.0, 150.0, -120.0, 0.0], abs=1e-6
    )


def test_csv_tolerates_a_header_blank_lines_and_comments(tmp_path):
    path = write(
        tmp_path,
        "wp.csv",
        "x,y,z,qx,qy,qz,qw\n\n# kitchen\n"
        "1.5, 2.5, 0, 0, 0, 0.7071067811865476, 0.7071067811865476\n\n"
        "3,4,0,0,0,0,1\n",
    )
    mission = load_mission(path)
    assert poses(mission) == [(1.5, 2.5, 90.0), (3.0, 4.0, 0.0)]
    assert mission.waypoints[1].where == f"{path}:6"


def test_csv_quaternion_need_not_be_normalised(tmp_path):
    path = write(tmp_path, "wp.csv", "0,0,0,0,0,2,2\n")
    assert poses(load_mission(path)) == [(0.0, 0.0, 90.0)]


# --- navseq YAML ---------------------------------------------------------------------


def test_patrol_example_has_every_setting():
    mission = load_mission(EXAMPLES / "patrol.yaml")
    assert mission.loops is None  # forever
    assert mission.map == (EXAMPLES.parent / "maps" / "turtlebot3_world.yaml").resolve()
    assert mission.start is not None and (mission.start.x, mission.start.y) == (-2.0, -0.5)
    assert mission.defaults.pass_through_m == 0.3
    assert mission.defaults.on_failure is FailureAction.SKIP
    assert [w.name for w in mission.waypoints] == ["south", "east", "north", "west"]
    assert mission.policy_for(3).dwell_s == 2.0 and mission.policy_for(0).dwell_s == 0.0


def test_navseq_yaml_orientation_forms_and_overrides(tmp_path):
    path = write(
        tmp_path,
        "m.yaml",
        """
navseq: 1
frame: odom
loops: 3
server_timeout: null
defaults: {goal_timeout: 60, pass_through: 0.3, on_failure: retry}
waypoints:
  - {name: a, x: 1, y: 2, yaw: 90}
  - {name: b, x: 1, y: 2, z: 0.5, yaw_rad: -1.5}
  - {x: 1, y: 2, orientation: {x: 0, y: 0, z: 1, w: 0}, pass_through: null, retries: 2}
  - [4, 5]
  - [4, 5, -45]
  - {x: 1e3, y: -2.5e-1}
""",
    )
    mission = load_mission(path)
    yaws = [w.yaw_rad for w in mission.waypoints]
    assert yaws == pytest.approx([math.pi / 2, -1.5, math.pi, 0.0, -math.pi / 4, 0.0])
    assert mission.waypoints[1].z == 0.5
    assert (mission.waypoints[5].x, mission.waypoints[5].y) == (1000.0, -0.25)
    assert mission.frame == "odom" and mission.loops == 3 and mission.server_timeout is None
    assert mission.policy_for(0).pass_through_m == 0.3
    third = mission.policy_for(2)
    assert third.pass_through_m is None and third.retries == 2 and third.goal_timeout_s == 60.0
    assert third.on_failure is FailureAction.RETRY


def test_navseq_yaml_merge_keys_share_settings(tmp_path):
    path = write(
        tmp_path,
        "m.yaml",
        """
slow: &slow {goal_timeout: 300, dwell: 5}
waypoints:
  - {x: 1, y: 2, <<: *slow}
""",
    )
    # An unknown top-level key is still an error, even when used only as an anchor.
    assert any("slow" in str(e) for e in validate_mission_file(path))
    path = write(
        tmp_path,
        "m2.yaml",
        """
defaults: &d {goal_timeout: 300}
waypoints:
  - {x: 1, y: 2, <<: *d, dwell: 5}
""",
    )
    policy = load_mission(path).policy_for(0)
    assert (policy.goal_timeout_s, policy.dwell_s) == (300.0, 5.0)


def test_map_path_is_resolved_against_the_mission_folder(tmp_path):
    (tmp_path / "sub").mkdir()
    path = write(tmp_path / "sub", "m.yaml", "map: ../maps/arena.yaml\nwaypoints: [[0, 0]]\n")
    assert load_mission(path).map == (tmp_path / "maps" / "arena.yaml").resolve()


def test_format_is_sniffed_when_the_extension_says_nothing(tmp_path):
    launch = (EXAMPLES / "tutorial_move_base_seq.launch").read_text()
    assert len(load_mission(write(tmp_path, "mission.txt", launch))) == 3
    assert len(load_mission(write(tmp_path, "mission", "waypoints: [[1, 2]]\n"))) == 1
    assert len(load_mission(write(tmp_path, "wp.dat", "1,2,0,0,0,0,1\n3,4,0,0,0,0,1\n"))) == 2


# --- ROS parameters ------------------------------------------------------------------


def test_params_with_the_tutorials_lists():
    mission = mission_from_params(
        {"p_seq": [-1, -4, 0, 1, -4, 0, 1, -1, 0], "yea_seq": [90, 0, 180]}
    )
    assert poses(mission) == [(-1.0, -4.0, 90.0), (1.0, -4.0, 0.0), (1.0, -1.0, 180.0)]


def test_params_with_structured_waypoints_and_policies():
    mission = mission_from_params(
        {
            "waypoints": [{"name": "dock", "x": 1.0, "y": 2.0, "yaw": 90}, [3, 4]],
            "frame": "odom",
            "loops": "forever",
            "retries": 3,
            "on_failure": "skip",
        }
    )
    assert poses(mission) == [(1.0, 2.0, 90.0), (3.0, 4.0, 0.0)]
    assert mission.waypoints[0].name == "dock"
    assert mission.frame == "odom" and mission.loops is None
    assert mission.defaults.retries == 3 and mission.defaults.on_failure is FailureAction.SKIP


def test_params_naming_a_mission_file_with_overrides():
    mission = mission_from_params(
        {"mission": str(EXAMPLES / "patrol.yaml"), "loops": 2, "goal_timeout": 10}
    )
    assert mission.loops == 2
    assert mission.defaults.goal_timeout_s == 10.0
    assert mission.defaults.pass_through_m == 0.3  # the file's own default stays
    assert len(mission) == 4


def test_params_of_the_node_itself_can_be_ignored():
    mission = mission_from_params(
        {"p_seq": [1, 2, 0], "yea_seq": [0], "action_name": "mb"}, ignore={"action_name"}
    )
    assert len(mission) == 1
