"""The outcome of a mission run, per waypoint visit, as the report and exit code see it.

The fields keep the names the journal has always used (``duration``,
``distance_driven``); the ``*_s`` / ``*_m`` / ``yaw_deg`` properties say the unit in
the name, as the report and the ``--json`` events do, and are what the public API
documents.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from navseq.executor.events import WaypointOutcome
from navseq.geometry import Pose2D


@dataclass
class AttemptResult:
    """One goal sent for a visit, and how it ended.

    ``status`` is the terminal status the navigation stack reported, in its own
    words (``SUCCEEDED``, ``ABORTED``, ``CANCELED`` ...), or None when navseq ended
    the attempt itself (timeout, stalled, skip, interrupt). ``reason`` is empty for
    the attempt that reached the waypoint, else why it failed; ``text`` is the
    stack's own result text.
    """

    number: int  # 1-based
    reached: bool = False
    status: str | None = None
    reason: str = ""
    text: str = ""
    duration: float = 0.0  # s from the goal sent to its end
    distance_driven: float = 0.0  # m
    # Recovery behaviours the stack ran for this goal (Nav2's number_of_recoveries, as
    # last reported); None where the stack does not count them.
    recoveries: int | None = None

    @property
    def duration_s(self) -> float:
        """Seconds (navigator clock) from the goal sent to its end."""
        return self.duration

    @property
    def distance_m(self) -> float:
        """Metres driven during this attempt."""
        return self.distance_driven


@dataclass
class WaypointResult:
    """One visit of one waypoint (a patrol visits each waypoint once per loop)."""

    index: int  # 0-based position in the mission
    loop: int  # 0-based
    name: str | None
    x: float
    y: float
    yaw_rad: float
    outcome: WaypointOutcome = WaypointOutcome.NOT_RUN
    attempts: int = 0
    duration: float = 0.0  # s from first goal sent to reached/given up
    distance_driven: float = 0.0  # m
    reason: str = ""
    passed_through: bool = False
    attempt_results: list[AttemptResult] = field(default_factory=list)  # in order

    @property
    def yaw_deg(self) -> float:
        """The waypoint's heading in degrees."""
        return math.degrees(self.yaw_rad)

    @property
    def duration_s(self) -> float:
        """Seconds (navigator clock) from the first goal sent to reached / given up."""
        return self.duration

    @property
    def distance_m(self) -> float:
        """Metres driven during this visit, all attempts together."""
        return self.distance_driven

    @property
    def last_failure(self) -> AttemptResult | None:
        """The latest attempt that did not reach the waypoint, if any."""
        return next((a for a in reversed(self.attempt_results) if not a.reached), None)


@dataclass
class MissionResult:
    success: bool
    reason: str
    visits: list[WaypointResult] = field(default_factory=list)
    duration: float = 0.0
    distance_driven: float = 0.0
    loops_completed: int = 0
    start_pose: Pose2D | None = None  # the robot's first known pose of the run

    @property
    def duration_s(self) -> float:
        """Seconds of mission time (navigator clock; simulated time on the simulator)."""
        return self.duration

    @property
    def distance_m(self) -> float:
        """Metres driven during the whole run."""
        return self.distance_driven

    @property
    def exit_code(self) -> int:
        """0 only if every waypoint was reached, 1 otherwise."""
        return 0 if self.success else 1

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        for visit in data["visits"]:
            visit["outcome"] = WaypointOutcome(visit["outcome"]).value
        return data
