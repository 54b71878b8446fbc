"""Behaviour goals (assisted teleop's too) and what Nav2 answers, held against both the stand-in
(``tests/test_ros2_behaviors.py``) and the real behaviour server
(``tests/test_nav2_real.py``): one table, so the two cannot drift apart.

The robot starts at (-2, -0.5) facing +x on the TurtleBot3 arena, 0.65 m in front of the
west wall behind it. Each case is sent with ``tests/ros2_clients.py behavior`` (whose
JSON says ``status``, ``error_code``, and how far the robot ``turned`` and ``advanced``
along its heading); ``check`` holds what a user would notice of the motion. Error codes
are the nav2_msgs constants of each action (Jazzy).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

Seen = dict[str, Any]


@dataclass(frozen=True)
class BehaviorCase:
    name: str
    kind: str
    options: dict[str, Any]
    status: str
    error_code: int
    check: Callable[[Seen], bool] = field(default=lambda seen: True)


def _near(value: float, target: float, slack: float) -> bool:
    return abs(value - target) <= slack


CASES = [
    BehaviorCase(
        "spin turns by the target yaw",
        "spin",
        {"value": 1.57},
        "SUCCEEDED",
        0,
        lambda s: _near(s["turned"], 1.57, 0.15) and s["moved"] < 0.03,
    ),
    BehaviorCase(
        "a negative spin turns clockwise",
        "spin",
        {"value": -math.pi / 2},
        "SUCCEEDED",
        0,
        lambda s: _near(s["turned"], -math.pi / 2, 0.15),
    ),
    BehaviorCase(
        "backup drives back the distance asked",
        "backup",
        # nav2_simple_commander's default distance: the real bringup's robot (radius
        # 0.22 m) counts a footprint within its inscribed radius of the wall as a collision.
        {"value": 0.15, "speed": 0.05},
        "SUCCEEDED",
        0,
        lambda s: _near(s["advanced"], -0.15, 0.05) and abs(s["turned"]) < 0.05,
    ),
    BehaviorCase(
        "drive_on_heading drives ahead the distance asked",
        "drive_on_heading",
        {"value": 0.3, "speed": 0.1},
        "SUCCEEDED",
        0,
        lambda s: _near(s["advanced"], 0.3, 0.06),
    ),
    BehaviorCase(
        "backing into the wall stops short: COLLISION_AHEAD",
        "backup",
        {"value": 1.0, "speed": 0.2},
        "ABORTED",
        714,
        lambda s: -0.05 < -s["advanced"] < 0.5,
    ),
    BehaviorCase(
        "a time allowance that runs out: TIMEOUT",
        "drive_on_heading",
        {"value": 1.0, "speed": 0.05, "allowance": 2},
        "ABORTED",
        721,
        lambda s: 0.0 < s["advanced"] < 0.25,
    ),
    BehaviorCase(
        "a speed against the target's sign: INVALID_INPUT",
        "drive_on_heading",
        {"value": 0.3, "speed": -0.1},
        "ABORTED",
        724,
        lambda s: s["moved"] < 0.01,
    ),
    BehaviorCase(
        "backup sideways: INVALID_INPUT",
        "backup",
        {"value": 0.3, "speed": 0.1, "target_y": 0.2},
        "ABORTED",
        713,
        lambda s: s["moved"] < 0.01,
    ),
    BehaviorCase(
        "wait succeeds", "wait", {"value": 1.0}, "SUCCEEDED", 0, lambda s: s["moved"] < 0.01
    ),
    BehaviorCase(
        "a cancelled spin ends CANCELED",
        "spin",
        {"value": 20.0, "allowance": 60, "cancel_after": 1.5},
        "CANCELED",
        0,
        lambda s: abs(s["turned"]) > 0.1,
    ),
    # assisted_teleop: ``speed`` on cmd_vel_teleop, preempt_teleop after ``value`` wall
    # seconds (0: never), ``allowance`` seconds of time allowance.
    BehaviorCase(
        "assisted teleop drives with the operator's command until preempt_teleop",
        "assisted_teleop",
        {"value": 2.0, "speed": 0.1, "allowance": 30},
        "SUCCEEDED",
        0,
        lambda s: s["advanced"] > 0.1 and abs(s["turned"]) < 0.1,
    ),
    BehaviorCase(
        "assisted teleop toward the wall stops short of it",
        "assisted_teleop",
        {"value": 6.0, "speed": -0.2, "allowance": 30},
        "SUCCEEDED",
        0,
        lambda s: 0.05 < -s["advanced"] < 0.6,
    ),
    BehaviorCase(
        "assisted teleop's time allowance runs out: TIMEOUT",
        "assisted_teleop",
        {"value": 0.0, "speed": 0.0, "allowance": 2},
        "ABORTED",
        731,
        lambda s: s["moved"] < 0.01,
    ),
]
