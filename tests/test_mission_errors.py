"""Every kind of mistake in a mission gives one readable NavseqError that names the
place (file:line or parameter), the waypoint and the field — never a traceback."""

import os
from pathlib import Path

import pytest

from navseq.errors import MissionErrors, NavseqError
from navseq.mission import load_mission, mission_from_params, validate_mission_file
from navseq.mission.reading import read_mission_text


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def only_error(path: Path) -> str:
    """The single error message of a file (and load_mission raises that same error)."""
    errors = validate_mission_file(path)
    assert len(errors) == 1, [str(e) for e in errors]
    with pytest.raises(NavseqError) as raised:
        load_mission(path)
    assert str(raised.value) == str(errors[0])
    return str(errors[0])


TUTORIAL = """<launch>
  <node pkg="simple_navigation_goals" type="move_base_seq.py" name="move_base_seq">
      <rosparam param="p_seq">{p_seq}</rosparam>
      <rosparam param="yea_seq">{yea_seq}</rosparam>
  </node>
</launch>
"""


@pytest.mark.parametrize(
    ("p_seq", "yea_seq", "expected"),
    [
        ("[1,2,0,3,4]", "[0,0]", [":3", "p_seq", "5 numbers", "not a multiple of 3"]),
        ("[1,2,0,3,4,0]", "[90]", [":4", "yea_seq", "1 yaw", "2 points"]),
        ("[1,2,0,3,4,0]", "[90,0,180]", [":4", "3 yaws", "2 points"]),
        ("[1,abc,0]", "[90]", [":3", "waypoint 1, field y", "p_seq item 2", "text 'abc'"]),
        ("[1,2,0,3,.nan,0]", "[0,0]", [":3", "waypoint 2, field y", "finite", "nan"]),
        ("[1,2,0]", "[.inf]", [":4", "waypoint 1, field yaw", "finite", "inf"]),
        ("[]", "[]", [":3", "p_seq", "empty"]),
        ("5", "[0]", [":3", "p_seq", "must be a list"]),
    ],
)
def test_tutorial_launch_mistakes(tmp_path, p_seq, yea_seq, expected):
    path = write(tmp_path, "seq.launch", TUTORIAL.format(p_seq=p_seq, yea_seq=yea_seq))
    message = only_error(path)
    assert message.startswith(str(path))
    for part in expected:
        assert part in message


def test_missing_yea_seq_is_named(tmp_path):
    path = write(tmp_path, "p.yaml", "move_base_seq:\n  p_seq: [1, 2, 0]\n")
    message = only_error(path)
    assert "yea_seq" in message and "missing" in message and ":2" in message


def test_unresolvable_launch_substitutions_are_reported_not_guessed(tmp_path):
    # $(eval) needs roslaunch's Python evaluator, which navseq does not reimplement.
    path = write(
        tmp_path,
        "seq.launch",
        """<launch>
  <arg name="points" default="[1,2,0]"/>
  <node pkg="p" type="t" name="seq">
    <param name="p_seq" value="$(eval arg('points'))"/>
    <param name="yea_seq" value="[0]"/>
  </node>
</launch>""",
    )
    message = only_error(path)
    assert ":4" in message and "substitution" in message and "p_seq" in message


def test_two_nodes_with_missions_in_one_launch_file(tmp_path):
    body = "<rosparam>{p_seq: [1, 2, 0], yea_seq: [0]}</rosparam>"
    path = write(
        tmp_path,
        "two.launch",
        f'<launch><node pkg="a" type="b" name="one">{body}'
        f'</node><node pkg="a" type="b" name="two">{body}</node></launch>',
    )
    message = only_error(path)
    assert "/one" in message and "/two" in message


def test_broken_yaml_inside_rosparam_is_located_in_the_launch_file(tmp_path):
    path = write(
        tmp_path,
        "body.launch",
        """<launch>
  <node pkg="a" type="b" name="n">
    <rosparam>
      p_seq: [1, 2, 0]
      yea_seq: {0
    </rosparam>
  </node>
</launch>""",
    )
    message = only_error(path)
    assert f"{path}:6" in message and "not valid YAML" in message


def test_launch_without_any_mission(tmp_path):
    path = write(tmp_path, "x.launch", '<launch><node pkg="a" type="b" name="c"/></launch>')
    assert "p_seq" in only_error(path)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('<launch><node name="a"></launch>', [":1", "not well-formed XML", "mismatched"]),
        ("<robot name='r'/>", ["not a roslaunch file", "<robot>"]),
        ('<?xml version="1.0"?>\n<!DOCTYPE l [<!ENTITY a "aaaa">]>\n<launch/>', [":2", "DTD"]),
    ],
)
def test_broken_or_foreign_xml(tmp_path, text, expected):
    message = only_error(write(tmp_path, "x.launch", text))
    for part in expected:
        assert part in message


NAVSEQ_CASES = [
    # (yaml text, substrings of the one error)
    (
        "waypoints:\n  - {x: 1, y: 2}\n  - {x: 1, y: two}\n",
        [":3", "waypoint 2, field y", "must be a number", "'two'"],
    ),
    ("waypoints:\n  - {x: 1, y: .nan}\n", [":2", "waypoint 1, field y", "finite"]),
    ("waypoints:\n  - {x: 1, y: -.inf}\n", [":2", "waypoint 1, field y", "finite"]),
    ("waypoints:\n  - {x: 1, y: 2, yaw: true}\n", ["waypoint 1, field yaw", "true"]),
    ("waypoints:\n  - {x: 1}\n", [":2", "waypoint 1, field y", "missing"]),
    (
        "waypoints:\n  - {name: dock, x: 1, y: 2, goal_timout: 3}\n",
        [":2", "waypoint 1 'dock', field goal_timout", "did you mean 'goal_timeout'"],
    ),
    ("waypoint:\n  - {x: 1, y: 2}\n", [":1", "field waypoint", "did you mean 'waypoints'"]),
    ("waypoints: []\n", [":1", "field waypoints", "empty"]),
    ("frame: map\n", ["no 'waypoints'"]),
    ("", ["empty"]),
    ("just some words\n", ["must be a mapping", "text 'just some words'"]),
    (
        "defaults: {goal_timeout: 0}\nwaypoints: [[0, 0]]\n",
        [":1", "defaults, field goal_timeout", "> 0 s", "got 0"],
    ),
    (
        "defaults: {stall_timeout: -5}\nwaypoints: [[0, 0]]\n",
        ["defaults, field stall_timeout", "> 0 s", "-5"],
    ),
    (
        "defaults:\n  retries: -1\nwaypoints: [[0, 0]]\n",
        [":2", "defaults, field retries", ">= 0", "-1"],
    ),
    ("defaults: {retries: 1.5}\nwaypoints: [[0, 0]]\n", ["field retries", "whole number"]),
    ("waypoints:\n  - {x: 0, y: 0, dwell: -1}\n", [":2", "waypoint 1, field dwell", ">= 0"]),
    (
        "waypoints:\n  - {x: 0, y: 0, pass_through: -0.5}\n",
        ["waypoint 1, field pass_through", ">= 0 m"],
    ),
    (
        "defaults: {on_failure: skipp}\nwaypoints: [[0, 0]]\n",
        ["field on_failure", "stop | skip | retry", "did you mean 'skip'"],
    ),
    (
        "defaults: {clear_costmaps_on_retry: maybe}\nwaypoints: [[0, 0]]\n",
        ["field clear_costmaps_on_retry", "true or false"],
    ),
    ("loops: 0\nwaypoints: [[0, 0]]\n", [":1", "field loops", ">= 1"]),
    ("loops: always\nwaypoints: [[0, 0]]\n", ["field loops", "'forever'"]),
    ("server_timeout: -1\nwaypoints: [[0, 0]]\n", ["field server_timeout", "> 0"]),
    ("navseq: 2\nwaypoints: [[0, 0]]\n", ["field navseq", "version 2"]),
    ("frame: base link\nwaypoints: [[0, 0]]\n", ["field frame", "no spaces"]),
    ("start: {x: 0}\nwaypoints: [[0, 0]]\n", ["start, field y", "missing"]),
    (
        "waypoints:\n  - {x: 0, y: 0, yaw: 5, yaw_rad: 1}\n",
        ["waypoint 1, field yaw_rad", "only one of yaw, yaw_rad"],
    ),
    (
        "waypoints:\n  - {x: 0, y: 0, orientation: {x: 0, y: 0, z: 0, w: 0}}\n",
        ["waypoint 1, field orientation", "length 0"],
    ),
    ("waypoints:\n  - [1, 2, 3, 4]\n", [":2", "waypoint 1", "short form"]),
    ("waypoints:\n  - 7\n", [":2", "waypoint 1", "must be a mapping"]),
    ("waypoints: {x: 1}\n", ["field waypoints", "must be a list"]),
    ("waypoints: [[0, 0]]\nwaypoints: [[1, 1]]\n", [":2", "'waypoints' appears twice"]),
    ("waypoints: [[0, 0]\n", ["not valid YAML"]),
    (
        "waypoints:\n  - !!python/object/apply:os.system [echo hi]\n",
        [":2", "python/object/apply:os.system", "does not accept"],
    ),
    ("waypoints:\n  - {x: 0, y: 0, name: 2024-01-01}\n", [":2", "timestamp"]),
    ("a: 1\n---\nwaypoints: [[0, 0]]\n", ["not valid YAML"]),
]


@pytest.mark.parametrize(("text", "expected"), NAVSEQ_CASES)
def test_navseq_yaml_mistakes(tmp_path, text, expected):
    path = write(tmp_path, "mission.yaml", text)
    message = only_error(path)
    assert message.startswith(str(path))
    for part in expected:
        assert part in message


def test_duplicate_names_name_both_waypoints(tmp_path):
    path = write(
        tmp_path,
        "m.yaml",
        "waypoints:\n  - {name: dock, x: 0, y: 0}\n"
        "  - {name: door, x: 1, y: 0}\n  - {name: dock, x: 2, y: 0}\n",
    )
    message = only_error(path)
    assert ":4" in message and "waypoint 3, field name" in message
    assert "already used by waypoint 1" in message


def test_every_problem_is_reported_at_once(tmp_path):
    path = write(
        tmp_path,
        "m.yaml",
        """defaults: {goal_timeout: -1, retries: -2}
loops: 0
waypoints:
  - {name: a, x: 1, y: nope}
  - {name: a, x: 1, y: 2, dwel: 3}
""",
    )
    errors = validate_mission_file(path)
    texts = [str(e) for e in errors]
    assert len(errors) == 6, texts
    for field in (
        "goal_timeout",
        "retries",
        "loops",
        "waypoint 1 'a', field y",
        "waypoint 2, field name",
        "field dwel",
    ):
        assert any(field in t for t in texts), field
    with pytest.raises(MissionErrors) as raised:
        load_mission(path)
    assert raised.value.errors == errors or [str(e) for e in raised.value.errors] == texts
    assert "6 problems found" in str(raised.value)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1,2,0,0,0,0,1\n3,4,0,0,0\n", [":2", "waypoint 2", "5 values", "x,y,z,qx,qy,qz,qw"]),
        ("1,2,0,0,0,0,1\n3,four,0,0,0,0,1\n", [":2", "waypoint 2, field y", "'four'"]),
        ("1,2,0,0,0,0,nan\n", [":1", "waypoint 1, field qw", "finite"]),
        ("1,2,0,0,0,0,0\n", [":1", "waypoint 1, field orientation", "length 0"]),
        ("x,y,z,qx,qy,qz,qw\n\n", ["no waypoints"]),
        ("1,2,0,0,0,0,1\nx,y,z,qx,qy,qz,qw\n", [":2", "waypoint 2", "only the first line"]),
    ],
)
def test_csv_mistakes(tmp_path, text, expected):
    path = write(tmp_path, "wp.csv", text)
    message = only_error(path)
    for part in expected:
        assert part in message


def test_missing_file(tmp_path):
    assert "no such file" in only_error(tmp_path / "nope.yaml")


def test_directory(tmp_path):
    assert "is a folder" in only_error(tmp_path)


def test_binary_file(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR")
    assert "binary" in only_error(path)


def test_file_that_is_not_utf8_text(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_bytes(b"waypoints:\n  - {name: caf\xe9, x: 1, y: 2}\n")
    message = only_error(path)
    assert ":2" in message and "UTF-8" in message


def test_file_that_is_no_known_format(tmp_path):
    path = write(tmp_path, "notes.txt", "Buy milk.\nCall the robot vendor.\n")
    assert "not a mission file navseq can read" in only_error(path)


def test_huge_file_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "huge.yaml"
    with open(path, "wb") as stream:  # sparse: 11 MiB on paper, nothing on disk
        stream.truncate(11 * 1024 * 1024)
    message = only_error(path)
    assert "MiB" in message and "refuses" in message


def test_size_cap_holds_even_when_the_size_is_not_known_in_advance(tmp_path):
    path = write(tmp_path, "m.yaml", "waypoints: [[0, 0]]\n" * 10)
    with pytest.raises(NavseqError, match="refuses"):
        read_mission_text(path, max_bytes=50)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_named_pipe_is_refused_without_blocking(tmp_path):
    path = tmp_path / "pipe.yaml"
    os.mkfifo(path)
    assert "not a regular file" in only_error(path)


def test_yaml_alias_bomb_is_refused(tmp_path):
    lines = ["a: &a [x, x, x, x, x, x, x, x, x, x]"]
    for level in range(1, 9):
        prev, name = chr(ord("a") + level - 1), chr(ord("a") + level)
        lines.append(f"{name}: &{name} [" + ", ".join([f"*{prev}"] * 10) + "]")
    path = write(tmp_path, "bomb.yaml", "\n".join(lines) + "\n")
    message = only_error(path)
    assert "alias" in message and "refusing" in message


def test_self_referencing_yaml_is_refused(tmp_path):
    message = only_error(write(tmp_path, "loop.yaml", "waypoints: &w [*w]\n"))
    assert ":1" in message and "contains it" in message


# --- ROS parameters ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("params", "expected"),
    [
        ({"p_seq": [1, 2, 0, 3], "yea_seq": [0]}, ["param ~p_seq", "4 numbers"]),
        ({"p_seq": [1, 2, 0, 3, 4, 0], "yea_seq": [0]}, ["param ~yea_seq", "1 yaw", "2 points"]),
        ({"p_seq": [1, "x", 0], "yea_seq": [0]}, ["param ~p_seq", "waypoint 1, field y"]),
        ({"p_seq": [1, 2, 0], "yea_seq": [float("nan")]}, ["param ~yea_seq", "finite"]),
        (
            {"p_seq": [1, 2, 0], "yea_seq": [0], "goal_timout": 5},
            ["param ~goal_timout", "did you mean 'goal_timeout'"],
        ),
        ({"p_seq": [1, 2, 0], "yea_seq": [0], "goal_timeout": 0}, ["param ~goal_timeout", "> 0"]),
        ({}, ["param ~", "exactly one way"]),
        (
            {"p_seq": [1, 2, 0], "yea_seq": [0], "waypoints": [[0, 0]]},
            ["exactly one way", "waypoints"],
        ),
        ({"waypoints": [{"x": 1}]}, ["param ~waypoints", "waypoint 1, field y", "missing"]),
        ({"mission": "/nonexistent/m.yaml"}, ["/nonexistent/m.yaml", "no such file"]),
        ({"p_seq": "[1, 2, 0, 5]", "yea_seq": "[0]"}, ["param ~p_seq", "4 numbers"]),
        ({"mission": "m\x00.yaml"}, ["param ~mission", "NUL"]),
        ({"p_seq": [1, 2, 0], "yea_seq": [0], "map": "m\x00.yaml"}, ["param ~map", "NUL"]),
    ],
)
def test_param_mistakes(params, expected):
    with pytest.raises(NavseqError) as raised:
        mission_from_params(params)
    for part in expected:
        assert part in str(raised.value)


def test_a_launch_file_naming_itself_as_its_mission_does_not_recurse(tmp_path):
    path = write(
        tmp_path,
        "self.launch",
        '<launch><node pkg="a" type="b" name="n">'
        '<param name="mission" value="self.launch"/></node></launch>',
    )
    message = only_error(path)
    assert f"{path}:1, field mission" in message and "cannot itself name another" in message


def test_param_source_prefix_is_used_in_messages():
    with pytest.raises(NavseqError, match=r"param /robot1/navseq/p_seq"):
        mission_from_params({"p_seq": [1], "yea_seq": [0]}, source="param /robot1/navseq/")
