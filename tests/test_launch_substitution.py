"""Launch files as users write them: args, substitution args and <include>d files give
the waypoints roslaunch would set, and what roslaunch would refuse is one clear error
naming the file and line."""

import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from navseq.errors import NavseqError
from navseq.mission import Mission, load_mission, validate_mission_file


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def package(folder: Path, name: str) -> Path:
    """A fake ROS package: a folder whose package.xml names it."""
    write(
        folder,
        "package.xml",
        f'<?xml version="1.0"?>\n<package format="2">\n'
        f"  <name>{name}</name>\n  <version>0.1.0</version>\n</package>\n",
    )
    return folder


def poses(mission: Mission) -> list[tuple[float, float, float]]:
    return [(w.x, w.y, round(math.degrees(w.yaw_rad), 6)) for w in mission.waypoints]


def only_error(path: Path) -> NavseqError:
    """The single problem of a file (and load_mission raises that same one)."""
    errors = validate_mission_file(path)
    assert len(errors) == 1, [str(e) for e in errors]
    with pytest.raises(NavseqError) as raised:
        load_mission(path)
    assert str(raised.value) == str(errors[0])
    return errors[0]


def node(body: str) -> str:
    return (
        f'<launch>\n  <node pkg="simple_navigation_goals" type="move_base_seq.py" '
        f'name="move_base_seq">\n{body}\n  </node>\n</launch>\n'
    )


@pytest.fixture
def packages(tmp_path, monkeypatch):
    """ROS_PACKAGE_PATH: a workspace with my_pkg (in a folder named otherwise)."""
    workspace = tmp_path / "ws" / "src"
    config = package(workspace / "my_repo" / "my_pkg_folder", "my_pkg")
    write(config, "config/points.yaml", "p_seq: [5, 6, 0]\nyea_seq: [45]\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'nowhere'}:{tmp_path / 'ws'}")
    return config


# --- what resolves ------------------------------------------------------------------


def test_arg_default_and_fixed_value_give_the_waypoints(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="p_seq" default="[-1,-4,0, 1,-4,0]"/>
  <arg name="yaws" value="[90, 0]"/>
  <arg name="node_name" default="move_base_seq"/>
  <node pkg="simple_navigation_goals" type="move_base_seq.py" name="$(arg node_name)">
    <param name="p_seq" value="$(arg p_seq)"/>
    <rosparam param="yea_seq" subst_value="true">$(arg yaws)</rosparam>
  </node>
</launch>""",
    )
    assert poses(load_mission(path)) == [(-1.0, -4.0, 90.0), (1.0, -4.0, 0.0)]


def test_the_launch_file_users_write(tmp_path, packages):
    write(tmp_path, "waypoints.yaml", "goal_timeout: 30\nretries: 2\n")
    write(
        packages,
        "launch/more.launch",
        """<launch>
  <arg name="x"/>
  <group ns="tb3_0/move_base_seq">
    <param name="loops" value="$(arg x)"/>
  </group>
</launch>""",
    )
    path = write(
        tmp_path,
        "robot.launch",
        """<launch>
  <arg name="p_seq" default="[-1,-4,0, 1,-4,0]"/>
  <arg name="robot" default="tb3_0"/>
  <group ns="$(arg robot)">
    <node pkg="simple_navigation_goals" type="move_base_seq.py" name="move_base_seq">
      <rosparam param="p_seq" subst_value="true">$(arg p_seq)</rosparam>
      <param name="yea_seq" value="[90, 0]"/>
      <rosparam file="$(dirname)/waypoints.yaml" command="load"/>
    </node>
  </group>
  <include file="$(find my_pkg)/launch/more.launch"><arg name="x" value="2"/></include>
</launch>""",
    )
    mission = load_mission(path)
    assert poses(mission) == [(-1.0, -4.0, 90.0), (1.0, -4.0, 0.0)]
    assert mission.waypoints[0].where == f"{path}:6"
    assert mission.defaults.goal_timeout_s == 30.0 and mission.defaults.retries == 2
    assert mission.loops == 2


def test_include_gets_the_args_passed_to_it_its_own_defaults_and_its_namespace(tmp_path):
    included = write(
        tmp_path,
        "nodes/seq.launch",
        """<launch>
  <arg name="points"/>
  <arg name="yaws" default="[0, 0]"/>
  <arg name="frame" default="map"/>
  <node pkg="p" type="t" name="seq">
    <param name="p_seq" value="$(arg points)"/>
    <param name="yea_seq" value="$(arg yaws)"/>
    <param name="frame" value="$(arg frame)"/>
  </node>
</launch>""",
    )
    path = write(
        tmp_path,
        "main.launch",
        """<launch>
  <arg name="robot_frame" default="odom"/>
  <include file="nodes/seq.launch" ns="robot1">
    <arg name="points" value="[1,2,0, 3,4,0]"/>
    <arg name="frame" value="$(arg robot_frame)"/>
    <arg name="yaws" value="[9, 9]" if="false"/>
  </include>
</launch>""",
    )
    mission = load_mission(path)
    assert poses(mission) == [(1.0, 2.0, 0.0), (3.0, 4.0, 0.0)]
    assert mission.frame == "odom"
    assert mission.waypoints[0].where == f"{included}:6"


def test_include_in_a_group_lands_in_that_namespace_and_its_mission_is_the_only_one(tmp_path):
    write(tmp_path, "one.launch", node("    <rosparam>{p_seq: [1, 1, 0], yea_seq: [0]}</rosparam>"))
    path = write(
        tmp_path,
        "fleet.launch",
        """<launch>
  <group ns="r1"><include file="one.launch"/></group>
  <group ns="r2"><include file="one.launch"/></group>
</launch>""",
    )
    message = str(only_error(path))
    assert "/r1/move_base_seq" in message and "/r2/move_base_seq" in message


def test_pass_all_args(tmp_path):
    write(
        tmp_path,
        "inner.launch",
        """<launch>
  <arg name="points"/>
  <node pkg="p" type="t" name="seq">
    <param name="p_seq" value="$(arg points)"/>
    <param name="yea_seq" value="[7]"/>
  </node>
</launch>""",
    )
    path = write(
        tmp_path,
        "outer.launch",
        """<launch>
  <arg name="points" default="[1, 2, 0]"/>
  <include file="inner.launch" pass_all_args="true"/>
</launch>""",
    )
    assert poses(load_mission(path)) == [(1.0, 2.0, 7.0)]


def test_find_looks_on_ros_package_path_by_the_name_in_package_xml(tmp_path, monkeypatch):
    first = tmp_path / "first"
    ignored = package(first / "old" / "my_pkg", "my_pkg")
    write(ignored.parent, "CATKIN_IGNORE", "")
    write(ignored, "config/points.yaml", "p_seq: [9, 9, 0]\nyea_seq: [9]\n")
    outer = package(first / "outer", "outer_pkg")
    nested = package(outer / "vendored" / "my_pkg", "my_pkg")  # inside a package: not seen
    write(nested, "config/points.yaml", "p_seq: [8, 8, 0]\nyea_seq: [8]\n")
    real = package(tmp_path / "second" / "src" / "checkout", "my_pkg")
    write(real, "config/points.yaml", "p_seq: [5, 6, 0]\nyea_seq: [45]\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{first}:{tmp_path / 'second'}")
    path = write(
        tmp_path / "launch",
        "seq.launch",
        node('    <rosparam command="load" file="$(find my_pkg)/config/points.yaml"/>'),
    )
    assert poses(load_mission(path)) == [(5.0, 6.0, 45.0)]


def test_mission_param_with_find(tmp_path, packages):
    write(packages, "missions/patrol.yaml", "waypoints:\n  - [1, 2, 90]\n")
    path = write(
        tmp_path,
        "run.launch",
        node('    <param name="mission" value="$(find my_pkg)/missions/patrol.yaml"/>'),
    )
    assert poses(load_mission(path)) == [(1.0, 2.0, 90.0)]


def test_dirname_is_the_folder_of_the_file_being_read(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, "robot/config/points.yaml", "p_seq: [1, 1, 0]\nyea_seq: [30]\n")
    write(
        tmp_path,
        "robot/launch/nodes.launch",
        node('    <rosparam file="$(dirname)/../config/points.yaml"/>'),
    )
    path = write(
        tmp_path,
        "top.launch",
        '<launch><include file="$(dirname)/robot/launch/nodes.launch"/></launch>',
    )
    assert poses(load_mission(Path("top.launch"))) == [(1.0, 1.0, 30.0)]
    assert poses(load_mission(path)) == [(1.0, 1.0, 30.0)]


def test_env_and_optenv(tmp_path, monkeypatch):
    monkeypatch.setenv("NAVSEQ_TEST_POINTS", "[1, 2, 0, 3, 4, 0]")
    monkeypatch.delenv("NAVSEQ_TEST_UNSET", raising=False)
    monkeypatch.setenv("NAVSEQ_TEST_FRAME", "odom")
    path = write(
        tmp_path,
        "seq.launch",
        node("""
    <param name="p_seq" value="$(env NAVSEQ_TEST_POINTS)"/>
    <param name="yea_seq" value="$(optenv NAVSEQ_TEST_UNSET [10, 20])"/>
    <param name="frame" value="$(optenv NAVSEQ_TEST_FRAME map)"/>"""),
    )
    mission = load_mission(path)
    assert poses(mission) == [(1.0, 2.0, 10.0), (3.0, 4.0, 20.0)]
    assert mission.frame == "odom"


def test_if_and_unless_with_args(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="use_dock" default="false"/>
  <arg name="slow" default="1"/>
  <node pkg="p" type="t" name="seq">
    <rosparam param="p_seq">[1, 1, 0]</rosparam>
    <rosparam param="p_seq" if="$(arg use_dock)">[9, 9, 0]</rosparam>
    <rosparam param="yea_seq" unless="$(arg slow)">[90]</rosparam>
    <rosparam param="yea_seq" if="$(arg slow)">[45]</rosparam>
  </node>
</launch>""",
    )
    assert poses(load_mission(path)) == [(1.0, 1.0, 45.0)]


# --- what is reported ---------------------------------------------------------------


def test_undeclared_arg_names_the_line_and_the_arg(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="points" default="[1, 2, 0]"/>
  <node pkg="p" type="t" name="seq">
    <param name="p_seq" value="$(arg points)"/>
    <param name="yea_seq" value="$(arg yaws)"/>
  </node>
</launch>""",
    )
    error = only_error(path)
    assert error.source == f"{path}:5"
    assert "no arg 'yaws' is declared" in error.message


def test_arg_with_neither_default_nor_value_is_an_error_where_it_is_used(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="points"/>
  <node pkg="p" type="t" name="seq">
    <param name="yea_seq" value="[0]"/>
    <rosparam param="p_seq" subst_value="true">
      $(arg points)
    </rosparam>
  </node>
</launch>""",
    )
    error = only_error(path)
    assert error.source == f"{path}:6"
    assert "'points'" in error.message and "neither a default nor a value" in error.message


def test_an_included_file_sees_only_the_args_passed_to_it(tmp_path):
    inner = write(
        tmp_path,
        "inner.launch",
        node(
            '    <param name="p_seq" value="$(arg points)"/>\n'
            '    <param name="yea_seq" value="[0]"/>'
        ),
    )
    path = write(
        tmp_path,
        "outer.launch",
        """<launch>
  <arg name="points" default="[1, 2, 0]"/>
  <include file="inner.launch"/>
</launch>""",
    )
    error = only_error(path)
    assert error.source == f"{inner}:3" and "'points'" in error.message


def test_passing_an_arg_the_included_file_fixes_is_refused(tmp_path):
    inner = write(tmp_path, "inner.launch", '<launch>\n<arg name="x" value="1"/>\n</launch>')
    path = write(
        tmp_path,
        "outer.launch",
        '<launch>\n<include file="inner.launch"><arg name="x" value="2"/></include>\n</launch>',
    )
    error = only_error(path)
    assert error.source == f"{inner}:2" and "cannot set it" in error.message


def test_unset_env_is_an_error(tmp_path, monkeypatch):
    monkeypatch.delenv("NAVSEQ_TEST_UNSET", raising=False)
    path = write(
        tmp_path, "seq.launch", node('    <param name="p_seq" value="$(env NAVSEQ_TEST_UNSET)"/>')
    )
    error = only_error(path)
    assert error.source == f"{path}:3"
    assert "NAVSEQ_TEST_UNSET" in error.message and "optenv" in error.message


def test_unknown_substitution_command_is_an_error(tmp_path):
    path = write(tmp_path, "seq.launch", node('    <param name="p_seq" value="$(args points)"/>'))
    error = only_error(path)
    assert error.source == f"{path}:3" and "$(args points)" in error.message


def test_if_that_is_not_a_boolean_is_an_error(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="use_dock" default="yes"/>
  <group if="$(arg use_dock)"/>
</launch>""",
    )
    error = only_error(path)
    assert error.source == f"{path}:3" and 'if="yes"' in error.message


def test_include_cycle_is_one_problem_not_a_recursion(tmp_path):
    write(tmp_path, "a.launch", '<launch>\n  <include file="b.launch"/>\n</launch>')
    b = write(
        tmp_path, "b.launch", '<launch>\n\n  <include file="$(dirname)/a.launch"/>\n</launch>'
    )
    error = only_error(tmp_path / "a.launch")
    assert error.source == f"{b}:3" and "include cycle" in error.message
    itself = write(tmp_path, "self.launch", '<launch><include file="self.launch"/></launch>')
    assert "include cycle" in only_error(itself).message


def test_deep_chain_of_includes_is_refused_clearly(tmp_path):
    for index in range(40):
        write(
            tmp_path,
            f"l{index}.launch",
            f'<launch><group ns="g"><include file="l{index + 1}.launch"/></group></launch>',
        )
    error = only_error(tmp_path / "l0.launch")
    assert "beyond navseq's limits" in error.message


def test_missing_included_file_names_the_including_line(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        node("    <rosparam>{p_seq: [1, 1, 0], yea_seq: [0]}</rosparam>").replace(
            "</launch>", '  <include file="extras/missing.launch"/>\n</launch>'
        ),
    )
    error = only_error(path)
    assert error.source == f"{path}:5"
    assert "missing.launch" in error.message and "no such file" in error.message


def test_broken_included_file_is_located_in_that_file(tmp_path):
    inner = write(tmp_path, "inner.launch", '<launch>\n  <node name="a">\n</launch>')
    path = write(tmp_path, "outer.launch", '<launch><include file="inner.launch"/></launch>')
    error = only_error(path)
    assert error.source == f"{inner}:3" and "not well-formed" in error.message


def test_rosparam_body_without_subst_value_is_kept_as_text_and_reported(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="points" default="[1, 2, 0]"/>
  <node pkg="p" type="t" name="seq">
    <rosparam param="p_seq">$(arg points)</rosparam>
    <rosparam param="yea_seq">[0]</rosparam>
  </node>
</launch>""",
    )
    error = only_error(path)
    assert error.source == f"{path}:4" and error.subject == "field p_seq"
    assert "$(arg points)" in error.message and 'subst_value="true"' in error.message


def test_eval_and_anon_stay_unresolved_and_are_reported(tmp_path):
    path = write(
        tmp_path,
        "seq.launch",
        node(
            """    <param name="p_seq" value="$(eval [1, 2, 0])"/>\n"""
            """    <param name="yea_seq" value="[0]"/>\n"""
            """    <param name="frame" value="$(anon f)"/>"""
        ),
    )
    errors = validate_mission_file(path)
    assert [(e.source, e.subject) for e in errors] == [
        (f"{path}:3", "field p_seq"),
        (f"{path}:5", "field frame"),
    ]
    assert "$(eval [1, 2, 0])" in errors[0].message and "$(anon f)" in errors[1].message


def test_find_of_a_package_not_on_the_path_is_named_as_not_followed(tmp_path, packages):
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <include file="$(find other_pkg)/launch/nodes.launch"/>
  <rosparam file="$(find my_pkg)/config/missing.yaml"/>
</launch>""",
    )
    message = str(only_error(path))
    assert "could not follow" in message
    assert (
        "$(find other_pkg)/launch/nodes.launch (package 'other_pkg' is not on "
        "ROS_PACKAGE_PATH)" in message
    )
    assert f"{packages}/config/missing.yaml" in message


def test_find_without_ros_package_path_says_so(tmp_path, monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    path = write(
        tmp_path, "seq.launch", node('    <rosparam file="$(find my_pkg)/config/points.yaml"/>')
    )
    assert "ROS_PACKAGE_PATH is not set" in str(only_error(path))


# --- never anything but NavseqError ---------------------------------------------------

LAUNCH_TOKENS = st.sampled_from(
    [
        "<launch>",
        "</launch>",
        "<arg ",
        "<include ",
        "<group ",
        "<node ",
        "<param ",
        "<rosparam ",
        "</rosparam>",
        "</include>",
        "</group>",
        "</node>",
        "/>",
        ">",
        'name="x" ',
        'name="p_seq" ',
        'default="[1, 2, 0]" ',
        'value="$(arg x)" ',
        'value="[0]" ',
        'name="yea_seq" ',
        'file="fuzz.launch" ',
        'file="$(dirname)/o.launch" ',
        'ns="$(arg x)" ',
        'if="$(arg x)" ',
        'unless="0" ',
        'subst_value="true" ',
        'pass_all_args="true" ',
        "$(",
        ")",
        "$(find x)",
        "$(env)",
        "$(optenv A b c)",
        "$(eval",
        "$(anon a)",
        "$(arg)",
        "$(dirname)",
        "[1, 2, 0]",
        '"',
        " ",
        "\n",
    ]
)


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(main=st.lists(LAUNCH_TOKENS, max_size=40), other=st.lists(LAUNCH_TOKENS, max_size=40))
def test_arbitrary_launch_text_with_includes_gives_only_navseq_errors(main, other):
    with tempfile.TemporaryDirectory() as folder:
        write(Path(folder), "o.launch", "".join(other))
        path = write(Path(folder), "fuzz.launch", "".join(main))
        problems = validate_mission_file(path)
        try:
            load_mission(path)
        except NavseqError:
            assert problems
        else:
            assert not problems
