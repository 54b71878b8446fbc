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
from typing import Any, NoReturn

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


_NO_OVERRIDES: Mapping[str, Any] = MappingProxyType({})


@dataclass(frozen=True, init=False)
class Waypoint:
    """One goal of a mission: a position in metres and a heading, with a unit you name.

    The heading is given as ``yaw_deg=`` (degrees, as mission files and the tutorial
    write it) or ``yaw_rad=`` (radians, as ROS messages carry it), never as a bare
    number: ``Waypoint(1.0, 2.0, yaw_deg=90)`` faces +y. It is stored as
    :attr:`yaw_rad`; :attr:`yaw_deg` reads it back in degrees. Everything after ``x``
    and ``y`` is keyword-only, so a third positional number cannot be taken for the
    wrong unit, and ``Waypoint(x, y, yaw=90)`` is a :class:`TypeError` saying so.

    ``overrides`` are per-waypoint :class:`Policy` values (``{"goal_timeout": 30.0}``);
    ``where`` (``"file.yaml:12"``) is where the user wrote it, for messages, and is
    not part of equality.
    """

    x: float  # m
    y: float  # m
    yaw_rad: float = 0.0
    z: float = 0.0  # m
    name: str | None = None
    overrides: Mapping[str, Any] = field(default_factory=lambda: _NO_OVERRIDES)
    where: str | None = field(default=None, compare=False)

    def __init__(
        self,
        x: float,
        y: float,
        *ambiguous: NoReturn,
        yaw_deg: float | None = None,
        yaw_rad: float | None = None,
        z: float = 0.0,
        name: str | None = None,
        overrides: Mapping[str, Any] | None = None,
        where: str | None = None,
        **unknown: NoReturn,
    ) -> None:
        # ``NoReturn`` above: a type checker flags Waypoint(1, 2, 90) and yaw=90 too.
        if ambiguous:
            raise TypeError(
                f"Waypoint(x, y, {ambiguous[0]!r}): a yaw given by position has no unit; "
                "write yaw_deg= (degrees) or yaw_rad= (radians)"
            )
        if "yaw" in unknown:
            raise TypeError(
                "Waypoint(yaw=...) is ambiguous: write yaw_deg= (degrees, as in mission "
                "files) or yaw_rad= (radians)"
            )
        if unknown:
            raise TypeError(f"Waypoint() got unexpected keyword argument(s): {', '.join(unknown)}")
        if yaw_deg is not None and yaw_rad is not None:
            raise TypeError("Waypoint(): give the yaw once, as yaw_deg= or yaw_rad=, not both")
        yaw = math.radians(yaw_deg) if yaw_deg is not None else (yaw_rad or 0.0)
        for name_, value in (
            ("x", x),
            ("y", y),
            ("yaw_rad", yaw),
            ("z", z),
            ("name", name),
            ("overrides", _NO_OVERRIDES if not overrides else MappingProxyType(dict(overrides))),
            ("where", where),
        ):
            object.__setattr__(self, name_, value)

    @property
    def yaw_deg(self) -> float:
        """The heading in degrees."""
        return math.degrees(self.yaw_rad)

    @property
    def pose(self) -> Pose2D:
        """Position and heading as a :class:`~navseq.geometry.Pose2D` (yaw in radians)."""
        return Pose2D(self.x, self.y, self.yaw_rad)

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
    # For a part of a mission file (``--from``/``--to``/``--only``, see
    # navseq.mission.part): each waypoint's 0-based position in the file, so that every
    # message numbers it as the file does. None: the waypoints are the file's, in order.
    numbers: tuple[int, ...] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        if self.numbers is not None and len(self.numbers) != len(self.waypoints):
            raise ValueError(
                f"numbers has {len(self.numbers)} entries for {len(self.waypoints)} waypoints"
            )

    def policy_for(self, index: int) -> Policy:
        return self.defaults.with_overrides(self.waypoints[index].overrides)

    def number(self, index: int) -> int:
        """The 1-based number a person knows waypoint ``index`` by: its number in the file."""
        if self.numbers is not None and 0 <= index < len(self.numbers):
            return self.numbers[index] + 1
        return index + 1

    def waypoint_label(self, index: int) -> str:
        """``waypoint 5 'dock'``: waypoint ``index`` as messages name it (the file's number)."""
        name = self.waypoints[index].name if 0 <= index < len(self.waypoints) else None
        return f"waypoint {self.number(index)}" + (f" '{name}'" if name else "")

    def __len__(self) -> int:
        return len(self.waypoints)
