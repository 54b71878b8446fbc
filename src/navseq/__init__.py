"""navseq: send a sequence of navigation goals to a robot and see the mission through.

The public API (see ``docs/api.md``)::

    import navseq

    mission = navseq.load_mission("examples/turtlebot3_world.yaml")
    problems = navseq.check_mission(mission)          # [] when every waypoint is fine
    result = navseq.simulate(mission, on_event=print)
    print(result.success, result.duration_s, result.distance_m)

Build missions in code with :class:`Mission`, :class:`Waypoint` (``yaw_deg=`` or
``yaw_rad=``, never a bare yaw) and :class:`Policy`; run them on the embedded
simulator (:func:`simulate`, :func:`sim_navigator`) or any navigator
(:func:`run_mission`, :class:`MissionRun` for an event loop of your own). Units are in
the names: ``_deg``, ``_rad``, ``_s`` seconds, ``_m`` metres.

The names are imported on first use (PEP 562), so that ``import navseq`` -- which
every ``navseq`` command does -- stays cheap.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

#: Public name -> the module that defines it.
_EXPORTS = {
    "AttemptResult": "navseq.executor.result",
    "FailureAction": "navseq.mission.model",
    "Mission": "navseq.mission.model",
    "MissionErrors": "navseq.errors",
    "MissionInterrupted": "navseq.executor.runner",
    "MissionResult": "navseq.executor.result",
    "MissionRun": "navseq.api",
    "NavseqError": "navseq.errors",
    "Policy": "navseq.mission.model",
    "Pose2D": "navseq.geometry",
    "Problem": "navseq.api",
    "RobotProfile": "navseq.mission.robot",
    "Waypoint": "navseq.mission.model",
    "WaypointResult": "navseq.executor.result",
    "check_mission": "navseq.api",
    "event_record": "navseq.sinks.json_events",
    "events": "navseq.executor",
    "load_mission": "navseq.api",
    "order_waypoints": "navseq.api",
    "run_mission": "navseq.api",
    "sim_navigator": "navseq.api",
    "simulate": "navseq.api",
    "validate_file": "navseq.api",
}

__all__ = [
    "AttemptResult",
    "FailureAction",
    "Mission",
    "MissionErrors",
    "MissionInterrupted",
    "MissionResult",
    "MissionRun",
    "NavseqError",
    "Policy",
    "Pose2D",
    "Problem",
    "RobotProfile",
    "Waypoint",
    "WaypointResult",
    "__version__",
    "check_mission",
    "event_record",
    "events",
    "load_mission",
    "order_waypoints",
    "run_mission",
    "sim_navigator",
    "simulate",
    "validate_file",
]

if TYPE_CHECKING:
    from navseq.api import (
        MissionRun,
        Problem,
        check_mission,
        load_mission,
        order_waypoints,
        run_mission,
        sim_navigator,
        simulate,
        validate_file,
    )
    from navseq.errors import MissionErrors, NavseqError
    from navseq.executor import events
    from navseq.executor.result import AttemptResult, MissionResult, WaypointResult
    from navseq.executor.runner import MissionInterrupted
    from navseq.geometry import Pose2D
    from navseq.mission.model import FailureAction, Mission, Policy, Waypoint
    from navseq.mission.robot import RobotProfile
    from navseq.sinks.json_events import event_record


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'navseq' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
