"""The outcome of a mission run, per waypoint visit, as the report and exit code see it."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from navseq.executor.events import WaypointOutcome


@dataclass
class WaypointResult:
    """One visit of one waypoint (a patrol visits each waypoint once per loop)."""

    index: int  # 0-based position in the mission
    loop: int  # 0-based
    name: str | None
    x: float
    y: float
    yaw: float  # radians
    outcome: WaypointOutcome = WaypointOutcome.NOT_RUN
    attempts: int = 0
    duration: float = 0.0  # s from first goal sent to reached/given up
    distance_driven: float = 0.0  # m
    reason: str = ""
    passed_through: bool = False


@dataclass
class MissionResult:
    success: bool
    reason: str
    visits: list[WaypointResult] = field(default_factory=list)
    duration: float = 0.0
    distance_driven: float = 0.0
    loops_completed: int = 0

    @property
    def exit_code(self) -> int:
        """0 only if every waypoint was reached, 1 otherwise."""
        return 0 if self.success else 1

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        for visit in data["visits"]:
            visit["outcome"] = WaypointOutcome(visit["outcome"]).value
        return data
