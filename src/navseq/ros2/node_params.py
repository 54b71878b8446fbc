"""The ROS 2 ``navseq_node``'s parameters as a mission and node settings, without ROS.

ROS 2 parameters are typed and flat: ``p_seq`` and ``yea_seq`` arrive as double (or
integer) arrays, exactly as the tutorial's launch file gives them; ``mission`` is a
string; ``waypoints``, a list of maps in ROS 1, has no ROS 2 parameter type, so it is a
string holding that YAML list (``"[{x: 1.0, y: 2.0, yaw: 90}, ...]"``). Every
other mission key (``loops``, ``goal_timeout``, ``pass_through`` ...) is as in ROS 1
(:mod:`navseq.mission.params`), and so are the messages. The rest are the node's own
settings (:data:`NODE_PARAMS`).

Nothing here imports rclpy: the node hands over plain values, and the rules are tested
in process.
"""

from __future__ import annotations

import array
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.loader import mission_from_params
from navseq.mission.located import to_plain
from navseq.mission.model import Mission
from navseq.mission.yaml_doc import parse_yaml_value

# The node's own parameters and their defaults. use_sim_time is rclpy's own.
NODE_PARAMS: dict[str, Any] = {
    "action": "navigate_to_pose",
    "server_wait": 30.0,
    "tick": 0.1,
    "keep_alive": False,
    "base_frames": ["base_footprint", "base_link"],
    "odom_topic": "odom",
    "plan_topic": "plan",
    "snapshot_dir": "",  # where snapshot tasks write (its snapshots/); "": refused
}
# Parameters every rclpy node may carry that are not the mission's.
RCLPY_PARAMS = ("use_sim_time", "start_type_description_service")
RCLPY_PREFIXES = ("qos_overrides.",)


@dataclass(frozen=True)
class NodeSettings:
    """The node's own settings, checked."""

    action: str
    server_wait: float  # s of wall time for the navigate_to_pose server
    tick: float  # s between two looks at the mission
    keep_alive: bool  # stay up after the mission, showing its final markers and status
    base_frames: tuple[str, ...]
    odom_topic: str
    plan_topic: str | None  # "" in the parameter: no plan topic
    use_sim_time: bool | None  # None: not given, follow /clock when it is published
    snapshot_dir: Path | None = None  # where snapshot tasks write; None: refused


def plain_value(value: Any) -> Any:
    """A parameter value as plain Python: rclpy gives arrays as ``array.array``."""
    if isinstance(value, array.array | tuple):
        return list(value)
    return value


def read_node_params(given: Mapping[str, Any], node: str) -> tuple[Mission, NodeSettings]:
    """The mission and node settings from the parameters given to the node ``node``.

    ``given`` maps parameter names to plain values (only those given from outside:
    command line, params file, launch file). Raises NavseqError (or MissionErrors, a
    NavseqError listing several problems) naming the parameter.
    """
    values = {name: plain_value(value) for name, value in given.items()}
    prefix = f"param {node} "
    mission_values = {
        name: value
        for name, value in values.items()
        if name not in NODE_PARAMS
        and name not in RCLPY_PARAMS
        and not name.startswith(RCLPY_PREFIXES)
    }
    if isinstance(mission_values.get("waypoints"), str):
        mission_values["waypoints"] = _yaml_list(mission_values["waypoints"], prefix + "waypoints")
    mission = mission_from_params(mission_values, prefix)
    return mission, _settings(values, prefix)


def _yaml_list(text: str, source: str) -> Any:
    """The waypoints string read by the mission files' YAML reader (its limits on
    nesting, size and numbers included), as plain data."""
    try:
        value = to_plain(parse_yaml_value(text, source))
    except NavseqError as error:
        hint = (
            '; give a YAML list of waypoints, e.g. "[{x: 1.0, y: 2.0, yaw: 90}]"'
            if error.message.startswith("is not valid YAML")
            else ""
        )
        raise NavseqError(error.message + hint, source=source, subject=error.subject) from None
    if not isinstance(value, list):
        raise NavseqError(
            "expected a YAML list of waypoints in a string, e.g. "
            f'"[{{x: 1.0, y: 2.0, yaw: 90}}]", got {text[:60]!r}',
            source=source,
        )
    return value


def _settings(values: Mapping[str, Any], prefix: str) -> NodeSettings:
    def get(name: str) -> Any:
        return values.get(name, NODE_PARAMS[name])

    def error(name: str, message: str) -> NavseqError:
        return NavseqError(f"{message}, got {get(name)!r}", source=prefix + name)

    def name_param(name: str, *, empty_ok: bool = False) -> str:
        value = get(name)
        if not isinstance(value, str) or any(c.isspace() for c in value):
            raise error(name, "expected a ROS name")
        if not value and not empty_ok:
            raise error(name, "expected a ROS name")
        return value

    def seconds(name: str) -> float:
        value = get(name)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise error(name, "expected a number of seconds")
        if not (math.isfinite(value) and value > 0):
            raise error(name, "expected a number of seconds > 0")
        return float(value)

    keep_alive = get("keep_alive")
    if not isinstance(keep_alive, bool):
        raise error("keep_alive", "expected true or false")
    base_frames = get("base_frames")
    if (
        not isinstance(base_frames, list)
        or not base_frames
        or not all(isinstance(f, str) and f.strip() for f in base_frames)
    ):
        raise error("base_frames", "expected a list of frame names")
    snapshot_dir = get("snapshot_dir")
    if not isinstance(snapshot_dir, str):
        raise error("snapshot_dir", "expected a folder's path")
    sim_time = values.get("use_sim_time")
    if sim_time is not None and not isinstance(sim_time, bool):
        raise NavseqError(
            f"expected true or false, got {sim_time!r}", source=prefix + "use_sim_time"
        )
    return NodeSettings(
        action=name_param("action"),
        server_wait=seconds("server_wait"),
        tick=seconds("tick"),
        keep_alive=keep_alive,
        base_frames=tuple(f.strip() for f in base_frames),
        odom_topic=name_param("odom_topic"),
        plan_topic=name_param("plan_topic", empty_ok=True) or None,
        use_sim_time=sim_time,
        snapshot_dir=Path(snapshot_dir).expanduser() if snapshot_dir else None,
    )
