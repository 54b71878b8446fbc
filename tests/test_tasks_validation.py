"""Tasks at waypoints in mission files: every kind read, every mistake named with its
file:line, all at once, and ``navseq validate`` exits 2 without a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from cli_support import assert_clean_error, navseq
from navseq.mission import load_mission, validate_mission_file
from navseq.mission.tasks import (
    CallTask,
    InputTask,
    PublishTask,
    RunTask,
    SnapshotTask,
    WaitForTask,
    WaitTask,
)
from navseq.mission.writer import dump_mission_yaml

GOOD = """\
navseq: 1
defaults:
  tasks:
    - wait: 2
waypoints:
  - {x: 1, y: 0}
  - x: 2
    y: 0
    tasks:
      - wait: 1.5
      - wait_for: {topic: /door, type: std_msgs/msg/Bool, field: data, equals: true}
        timeout: 30
      - input: {prompt: Load the tray}
      - snapshot: {topic: /camera/image, type: sensor_msgs/Image}
      - call: {service: ~/confirm}
      - publish: {topic: arm/goal, type: std_msgs/String, message: {data: up}}
      - run: {argv: [echo, hi], cwd: /tmp, env: {MODE: fast}}
        timeout: null
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "mission.yaml"
    path.write_text(text)
    return path


def test_every_kind_reads_into_its_typed_task(tmp_path: Path) -> None:
    mission = load_mission(write(tmp_path, GOOD))
    assert mission.policy_for(0).tasks == (WaitTask(2.0),)
    tasks = mission.policy_for(1).tasks  # the waypoint's list replaces the defaults'
    assert [type(t) for t in tasks] == [
        WaitTask,
        WaitForTask,
        InputTask,
        SnapshotTask,
        CallTask,
        PublishTask,
        RunTask,
    ]
    wait_for, call, run = tasks[1], tasks[4], tasks[6]
    assert isinstance(wait_for, WaitForTask) and isinstance(call, CallTask)
    assert isinstance(run, RunTask)
    assert (wait_for.type, wait_for.relation, wait_for.value) == ("std_msgs/Bool", "equals", True)
    assert wait_for.timeout_s == 30
    assert (call.type, call.success_field, call.timeout_s) == ("std_srvs/Trigger", "success", 60)
    assert run.argv == ("echo", "hi") and dict(run.env) == {"MODE": "fast"}
    assert run.timeout_s is None
    assert tasks[2].timeout_s is None  # an operator may take a while


def test_tasks_survive_convert_to_navseq_yaml(tmp_path: Path) -> None:
    mission = load_mission(write(tmp_path, GOOD))
    again = tmp_path / "again.yaml"
    again.write_text(dump_mission_yaml(mission))
    converted = load_mission(again)
    assert converted.waypoints == mission.waypoints
    assert converted.defaults == mission.defaults


BAD = """\
navseq: 1
waypoints:
  - x: 1
    y: 0
    tasks:
      - wait: 0
      - run: {argv: []}
        timeout: -1
      - wait_for: {topic: "/door 1", type: std_msgs/Bool, field: data, equals: 1, above: 3}
      - call: {service: /x, type: std_srvs/msg/Trigger}
      - publish: {topic: /y, type: Bool}
      - snapshot: {topic: /cam}
      - input: {prompt: hi, colour: red}
      - teleport: {x: 1}
      - wait: 1
        run: {argv: [a]}
      - wait_for: {topic: /a, type: std_msgs/Bool, field: 2data, below: low}
      - run: {argv: [a], env: {1BAD: x}}
  - {x: 2, y: 0, pass_through: 0.5, tasks: [{wait: 1}]}
"""

EXPECTED = [
    ("mission.yaml:6", "task 1 (wait): must be > 0 s"),
    ("mission.yaml:7", "task 2 (run), field argv: must list the program"),
    ("mission.yaml:8", "task 2 (run), field timeout: must be > 0 s"),
    ("mission.yaml:9", "give exactly one of equals, above, below (got equals, above)"),
    ("mission.yaml:9", "'/door 1' is not a valid ROS name"),
    ("mission.yaml:10", "'std_srvs/msg/Trigger' is not a service type"),
    ("mission.yaml:11", "'Bool' is not a message type"),
    ("mission.yaml:12", "task 6 (snapshot), field type: 'type' is missing"),
    ("mission.yaml:13", "task 7 (input), field colour: unknown key"),
    ("mission.yaml:14", "task 8: names no task kind"),
    ("mission.yaml:15", "task 9: gives wait and run; one task per list item"),
    ("mission.yaml:17", "'2data' is not a message field"),
    ("mission.yaml:17", "field below: must be a number"),
    ("mission.yaml:18", "'1BAD' is not an environment variable name"),
    ("mission.yaml:19", "waypoint 2: has tasks but passes through"),
]


def test_every_problem_is_named_with_its_line_all_at_once(tmp_path: Path) -> None:
    errors = [str(e) for e in validate_mission_file(write(tmp_path, BAD))]
    for place, words in EXPECTED:
        assert any(place in e and words in e for e in errors), (place, words, errors)


def test_validate_exits_2_listing_them_without_a_traceback(tmp_path: Path) -> None:
    result = navseq("validate", write(tmp_path, BAD), cwd=tmp_path)
    assert_clean_error(result)
    for place, words in EXPECTED:
        assert any(place in line and words in line for line in result.stderr.splitlines()), (
            place,
            words,
        )


@pytest.mark.parametrize(
    ("task", "words"),
    [
        ("{call: {service: /a//b}}", "not a valid ROS name"),
        ("{call: {service: /a__b}}", "not a valid ROS name"),
        ("{publish: {topic: /a, type: std_msgs/srv/String}}", "not a message type"),
        ("{wait_for: {topic: /a, type: std_msgs/Bool, field: data}}", "exactly one of"),
        ("{run: {argv: echo}}", "must be a list"),
        ("{wait: 5, timeout: 0}", "field timeout: must be > 0 s"),
        ("{input: {prompt: ''}}", "must be non-empty text"),
        ("[wait, 5]", "must be a mapping like"),
    ],
)
def test_one_mistake_one_message(tmp_path: Path, task: str, words: str) -> None:
    text = f"navseq: 1\nwaypoints:\n  - {{x: 1, y: 0, tasks: [{task}]}}\n"
    errors = [str(e) for e in validate_mission_file(write(tmp_path, text))]
    assert len(errors) == 1 and "mission.yaml:3" in errors[0] and words in errors[0], errors


def test_accepted_ros_names_and_types(tmp_path: Path) -> None:
    text = """\
navseq: 1
waypoints:
  - x: 1
    y: 0
    tasks:
      - call: {service: ~/confirm, type: my_pkg/srv/Do, request: {n: 1}, success_field: ok}
      - snapshot: {topic: _private/scan, type: sensor_msgs/msg/LaserScan}
      - wait_for:
          {topic: robot1/battery, type: sensor_msgs/BatteryState, field: "cells[0]", above: 3.3}
"""
    tasks = load_mission(write(tmp_path, text)).policy_for(0).tasks
    call = tasks[0]
    assert isinstance(call, CallTask)
    assert (call.type, call.success_field, dict(call.request)) == ("my_pkg/Do", "ok", {"n": 1})
    assert isinstance(tasks[1], SnapshotTask) and tasks[1].type == "sensor_msgs/LaserScan"
