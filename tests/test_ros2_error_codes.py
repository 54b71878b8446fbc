"""Nav2's error codes by name (navseq.ros2.error_codes).

The table builder and the renderers are tested in process with fake ``Result`` classes
shaped like rosidl's (constants and fields' defaults as class attributes). The real
nav2_msgs is read in a ROS 2 subprocess (tests never import ROS 2 in pytest's process):
the installed release's names, and the simulator stand-in's codes against it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import types
from pathlib import Path
from typing import Any

import pytest

from navseq.ros2.error_codes import (
    CodeName,
    actions_of,
    build_table,
    describe,
    describe_result,
    name_of,
)
from ros2_support import ros2_environment, ros2_prefix

REPO = Path(__file__).resolve().parents[1]


class FollowPath:
    class Result:
        NONE = 0
        UNKNOWN = 100
        PATIENCE_EXCEEDED = 104
        ERROR_CODE__DEFAULT = 0
        # rosidl's fields' defaults are no codes, whatever their value.
        NUM_RETRIES__DEFAULT = 3
        SUCCESS__DEFAULT = True
        SLOT_TYPES = ("uint16",)
        _TYPE_SUPPORT = 7
        lower_case = 105
        Mixed_Case = 106


class ComputePathToPose:
    class Result:
        NONE = 0
        GOAL_OCCUPIED = 206


class FollowWaypoints:
    class Result:
        NONE = 0
        TASK_EXECUTOR_FAILED = 601


class FollowGPSWaypoints:
    class Result:
        NONE = 0
        TASK_EXECUTOR_FAILED = 601


class FollowObject:
    class Result:
        FAILED_TO_DETECT_OBJECT = 902


class DockRobot:
    class Result:
        DOCK_NOT_VALID = 902


class NavigateToPose:
    class Result:  # Jazzy: the navigator declares only NONE
        NONE = 0


class Wait:
    class Result:  # no constants at all
        pass


def fake_action_module() -> types.ModuleType:
    """A ``nav2_msgs.action`` as rosidl makes it: the actions, and around them the
    messages, submodules and helpers that are not actions."""
    module = types.ModuleType("fake_nav2_msgs.action")
    actions: list[type] = [
        FollowPath,
        ComputePathToPose,
        FollowWaypoints,
        FollowGPSWaypoints,
        FollowObject,
        DockRobot,
        NavigateToPose,
        Wait,
    ]
    for action in actions:
        setattr(module, action.__name__, action)
    others = {
        "FollowPath_Result": FollowPath.Result,  # a message class: no Result of its own
        "_follow_path": types.ModuleType("_follow_path"),
        "_Hidden": FollowPath,  # private
        "NotAClass": types.SimpleNamespace(Result=FollowPath.Result()),  # Result no class
    }
    for name, value in others.items():
        setattr(module, name, value)
    return module


def fake_table() -> dict[int, tuple[CodeName, ...]]:
    return build_table(actions_of(fake_action_module()))


def test_actions_are_the_public_attributes_with_a_result_class() -> None:
    names = [name for name, _ in actions_of(fake_action_module())]
    assert names == [
        "ComputePathToPose",
        "DockRobot",
        "FollowGPSWaypoints",
        "FollowObject",
        "FollowPath",
        "FollowWaypoints",
        "NavigateToPose",
        "Wait",
    ]


def test_the_table_holds_every_upper_case_int_constant_but_none_and_field_defaults() -> None:
    assert fake_table() == {
        100: (CodeName("FollowPath", "UNKNOWN"),),
        104: (CodeName("FollowPath", "PATIENCE_EXCEEDED"),),
        206: (CodeName("ComputePathToPose", "GOAL_OCCUPIED"),),
        601: (
            CodeName("FollowGPSWaypoints", "TASK_EXECUTOR_FAILED"),
            CodeName("FollowWaypoints", "TASK_EXECUTOR_FAILED"),
        ),
        902: (
            CodeName("DockRobot", "DOCK_NOT_VALID"),
            CodeName("FollowObject", "FAILED_TO_DETECT_OBJECT"),
        ),
    }


def test_a_code_is_named_by_the_action_that_declares_it() -> None:
    table = fake_table()
    assert describe(104, table) == "FollowPath PATIENCE_EXCEEDED"
    assert describe(206, table) == "ComputePathToPose GOAL_OCCUPIED"


def test_a_shared_code_keeps_every_name() -> None:
    table = fake_table()
    assert describe(601, table) == "FollowGPSWaypoints/FollowWaypoints TASK_EXECUTOR_FAILED"
    assert describe(902, table) == (
        "DockRobot DOCK_NOT_VALID or FollowObject FAILED_TO_DETECT_OBJECT"
    )
    shared = [
        CodeName("UndockRobot", "DOCK_NOT_VALID"),
        CodeName("FollowObject", "FAILED_TO_DETECT_OBJECT"),
        CodeName("DockRobot", "DOCK_NOT_VALID"),
    ]
    assert name_of(shared) == (
        "DockRobot/UndockRobot DOCK_NOT_VALID or FollowObject FAILED_TO_DETECT_OBJECT"
    )


def test_a_code_the_release_does_not_declare_has_no_name() -> None:
    table = fake_table()
    assert describe(9001, table) is None
    assert describe(105, table) is None  # lower_case = 105 is no constant
    assert describe(3, table) is None  # NUM_RETRIES__DEFAULT is a field's default
    assert describe(0, table) is None  # NONE is success


@pytest.mark.parametrize(
    ("code", "message", "text"),
    [
        (
            104,
            "Failed to make progress",
            "Failed to make progress (FollowPath PATIENCE_EXCEEDED, error_code 104)",
        ),
        (104, "", "FollowPath PATIENCE_EXCEEDED (error_code 104)"),
        (104, "  \n", "FollowPath PATIENCE_EXCEEDED (error_code 104)"),
        (9001, "Behavior tree failed", "Behavior tree failed (error_code 9001)"),
        (9001, "", "error_code 9001"),
        (0, "", ""),  # Humble's results: neither field
        (0, "navigator said so ", "navigator said so"),
    ],
)
def test_a_result_reads_nav2s_message_then_the_code_by_name_and_number(
    code: int, message: str, text: str
) -> None:
    assert describe_result(code, message, fake_table()) == text


def test_nav2s_message_comes_first_verbatim_even_when_it_looks_like_a_name() -> None:
    message = "GOAL_OCCUPIED (error_code 1): (-1.1, 0.0)"
    text = describe_result(206, message, fake_table())
    assert text == f"{message} (ComputePathToPose GOAL_OCCUPIED, error_code 206)"


# --- the installed nav2_msgs, in a ROS 2 process ---------------------------------------

# Every stand-in code (navseq.ros2.standin.ErrorCode) and the nav2_msgs constant it is.
STANDIN_CODES = {
    "CONTROLLER_UNKNOWN": ("FollowPath", "UNKNOWN"),
    "FAILED_TO_MAKE_PROGRESS": ("FollowPath", "FAILED_TO_MAKE_PROGRESS"),
    "NO_VALID_CONTROL": ("FollowPath", "NO_VALID_CONTROL"),
    "PLANNER_UNKNOWN": ("ComputePathToPose", "UNKNOWN"),
    "START_OUTSIDE_MAP": ("ComputePathToPose", "START_OUTSIDE_MAP"),
    "GOAL_OUTSIDE_MAP": ("ComputePathToPose", "GOAL_OUTSIDE_MAP"),
    "START_OCCUPIED": ("ComputePathToPose", "START_OCCUPIED"),
    "GOAL_OCCUPIED": ("ComputePathToPose", "GOAL_OCCUPIED"),
    "NO_VALID_PATH": ("ComputePathToPose", "NO_VALID_PATH"),
    "INVALID_PATH": ("FollowPath", "INVALID_PATH"),
}

INSTALLED = r"""
import json, sys
import nav2_msgs.action as actions
from navseq.ros2.error_codes import describe, installed_table
from navseq.ros2.messages import result_text
from navseq.ros2.standin import ErrorCode

wanted = json.loads(sys.argv[1])
print(json.dumps({
    "names": {code: describe(int(code)) for code in ("104", "206", "105", "65000")},
    "texts": [
        result_text(104, "Failed to make progress"),
        result_text(206, ""),
        result_text(0, ""),
    ],
    "table_size": len(installed_table()),
    "standin": {member.name: int(member) for member in ErrorCode},
    "nav2": {
        name: getattr(getattr(actions, action).Result, constant)
        for name, (action, constant) in wanted.items()
    },
    "none": actions.FollowPath.Result.NONE,
}))
"""


def run_with_installed_nav2() -> dict[str, Any]:
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    # This checkout's navseq, whichever one the venv has installed.
    env["PYTHONPATH"] = os.pathsep.join([str(REPO / "src"), env["PYTHONPATH"]])
    done = subprocess.run(
        [sys.executable, "-c", INSTALLED, json.dumps(STANDIN_CODES)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        cwd=REPO,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.fixture(scope="module")
def installed() -> dict[str, Any]:
    return run_with_installed_nav2()


@pytest.mark.ros2
def test_the_installed_nav2_msgs_names_the_servers_codes(installed: dict[str, Any]) -> None:
    assert installed["names"] == {
        "104": "FollowPath PATIENCE_EXCEEDED",
        "206": "ComputePathToPose GOAL_OCCUPIED",
        "105": "FollowPath FAILED_TO_MAKE_PROGRESS",
        "65000": None,
    }
    assert installed["texts"] == [
        "Failed to make progress (FollowPath PATIENCE_EXCEEDED, error_code 104)",
        "ComputePathToPose GOAL_OCCUPIED (error_code 206)",
        "",
    ]
    assert installed["table_size"] > 40  # every action's range, not one action's


@pytest.mark.ros2
def test_the_standins_error_codes_are_nav2_msgs_constants(installed: dict[str, Any]) -> None:
    standin = installed["standin"]
    # A stand-in code added without saying which nav2_msgs constant it is fails here.
    assert set(standin) == {"NONE", *STANDIN_CODES}
    assert standin["NONE"] == installed["none"] == 0
    assert {name: standin[name] for name in STANDIN_CODES} == installed["nav2"]
