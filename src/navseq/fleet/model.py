"""A fleet as plain data: its robots, the mission they share, and who may take what."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.mission.robot import RobotProfile


@dataclass(frozen=True)
class FleetRobot:
    """One robot of a fleet.

    ``namespace`` is its navigation stack's (ROS) namespace, and names its part of a
    run folder with ``name``. ``max_time_s`` bounds the time its share of the mission
    may take (None: no bound). ``where`` is where the file lists it, for messages.
    """

    name: str
    namespace: str
    start: Pose2D
    profile: RobotProfile
    max_time_s: float | None = None
    where: str | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Fleet:
    """Robots and the mission they share.

    ``allowed`` maps a waypoint's index in ``mission`` to the names of the robots that
    may take it; a waypoint not in it may be taken by any robot. ``map`` is the map to
    plan and run on (the fleet file's ``map:``, else the mission's).
    """

    robots: tuple[FleetRobot, ...]
    mission: Mission
    map: Path | None = None
    allowed: Mapping[int, tuple[str, ...]] = field(default_factory=lambda: MappingProxyType({}))
    source: str = field(default="<memory>", compare=False)
    mission_path: Path | None = field(default=None, compare=False)  # None: inline

    def robot_names(self) -> tuple[str, ...]:
        return tuple(robot.name for robot in self.robots)

    def may_take(self, robot: str, index: int) -> bool:
        """Whether the fleet file lets ``robot`` take waypoint ``index``."""
        names = self.allowed.get(index)
        return names is None or robot in names


__all__ = ["Fleet", "FleetRobot"]
