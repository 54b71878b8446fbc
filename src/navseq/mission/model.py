"""The mission as plain data: waypoints, policies and mission-wide settings.

Nothing here reads files or talks to a robot; loaders build these objects and the
executor consumes them.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from navseq.geometry import Pose2D
from navseq.mission.robot import RobotProfile


class FailureAction(str, enum.Enum):
    """What a waypoint failure does once its retries are used up."""

    STOP = "stop"  # end the mission; later waypoints are not attempted
    SKIP = "skip"  # record the waypoint as failed and go on with the next one
    RETRY = "retry"  # try the same waypoint again, without limit


@dataclass(frozen=True)
class Policy:
    """How one waypoint is pursued. Mission-wide defaults, overridable per waypoint.

    Times are seconds, distances metres. ``None`` disables a limit.
    """

    goal_timeout: float | None = None
    stall_timeout: float | None = None
    retries: int = 0
    clear_costmaps_on_retry: bool = False
    on_failure: FailureAction = FailureAction.STOP
    pass_through: float | None = None
    dwell: float = 0.0
    # Arrival check on SUCCEEDED: None takes the robot profile's goal tolerance.
    xy_tolerance: float | None = None  # m
    yaw_tolerance: float | None = None  # rad (files say degrees)

    def with_overrides(self, overrides: Mapping[str, Any]) -> Policy:
        return dataclasses.replace(self, **dict(overrides)) if overrides else self


POLICY_FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(Policy))


@dataclass(frozen=True)
class Waypoint:
    """One goal of a mission. ``yaw`` is radians here (files say degrees)."""

    x: float
    y: float
    yaw: float = 0.0
    z: float = 0.0
    name: str | None = None
    overrides: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    # "file.yaml:12" — where the user wrote it, for messages; not part of equality
    where: str | None = field(default=None, compare=False)

    @property
    def pose(self) -> Pose2D:
        return Pose2D(self.x, self.y, self.yaw)

    @property
    def yaw_degrees(self) -> float:
        return math.degrees(self.yaw)

    def label(self, index: int) -> str:
        """Human name used in messages: ``waypoint 3 'dock'`` (1-based, like the files)."""
        return f"waypoint {index + 1}" + (f" '{self.name}'" if self.name else "")


@dataclass(frozen=True)
class Mission:
    """An ordered list of waypoints plus the settings that govern the whole run."""

    waypoints: tuple[Waypoint, ...]
    defaults: Policy = field(default_factory=Policy)
    frame: str = "map"
    loops: int | None = 1  # None = forever (patrol)
    map: Path | None = None
    start: Pose2D | None = None
    server_timeout: float | None = 60.0  # s to wait for a vanished server; None = forever
    robot: RobotProfile | None = None  # the mission's robot: section; None: not said
    source: str = field(default="<memory>", compare=False)  # where it was read from

    def policy_for(self, index: int) -> Policy:
        return self.defaults.with_overrides(self.waypoints[index].overrides)

    def __len__(self) -> int:
        return len(self.waypoints)
