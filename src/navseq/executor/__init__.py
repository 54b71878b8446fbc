"""The executor: one mission run as an explicit state machine (no ROS, no threads).

- :class:`MissionExecutor` (``machine``): the state machine; feed it navigator
  events and ticks, apply the commands it returns. Its states and the one table of
  the changes allowed between them are in ``states``; it keeps its bookkeeping in
  small parts: ``monitor`` (one goal's progress, stall and timeout), ``arrival`` (is
  the robot where a SUCCEEDED says), ``odometer`` (distance driven) and ``visit`` (one
  pass at a waypoint as the result records it, and which pass follows).
- :func:`run_mission` (``runner``): the loop that drives it against a navigator and
  cancels the goal on SIGINT/SIGTERM/exceptions.
- :class:`ResumePoint` (``resume``): where a resumed run continues (from a journal).
- :class:`MissionControl` (``control``): operator requests (skip, pause, resume,
  cancel) from other threads, carried out as executor inputs.
"""

from navseq.executor.commands import CancelGoal, ClearCostmaps, Command, SendGoal
from navseq.executor.control import MissionControl
from navseq.executor.machine import ExecutorState, MissionExecutor, MissionListener
from navseq.executor.result import MissionResult, WaypointResult
from navseq.executor.resume import ResumePoint
from navseq.executor.runner import MissionInterrupted, run_mission

__all__ = [
    "CancelGoal",
    "ClearCostmaps",
    "Command",
    "ExecutorState",
    "MissionControl",
    "MissionExecutor",
    "MissionInterrupted",
    "MissionListener",
    "MissionResult",
    "ResumePoint",
    "SendGoal",
    "WaypointResult",
    "run_mission",
]
