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
from navseq.mission.costmap_filters import CostmapFilter
from navseq.mission.geodesy import Datum, GeoPoint
from navseq.mission.recovery import Recovery
from navseq.mission.robot import RobotProfile
from navseq.mission.tasks import Task


class FailureAction(str, enum.Enum):
    """What a waypoint failure does once its retries are used up."""

    STOP = "stop"  # end the mission; later waypoints are not attempted
    SKIP = "skip"  # record the waypoint as failed and go on with the next one
    RETRY = "retry"  # try the same waypoint again, without limit


#: A unit-less keyword of Policy() -> what to write instead (the Policy's fields carry
#: their unit in the name, like Waypoint's ``yaw_deg``/``yaw_rad``).
_POLICY_RENAMED = {
    "goal_timeout": "goal_timeout_s= (seconds)",
    "stall_timeout": "stall_timeout_s= (seconds)",
    "pass_through": "pass_through_m= (metres)",
    "dwell": "dwell_s= (seconds)",
    "xy_tolerance": "xy_tolerance_m= (metres)",
    "yaw_tolerance": "yaw_tolerance_deg= (degrees, as in mission files) or yaw_tolerance_rad=",
}


@dataclass(frozen=True, init=False)
class Policy:
    """How one waypoint is pursued. Mission-wide defaults, overridable per waypoint.

    Every quantity names its unit: ``_s`` seconds, ``_m`` metres, and the yaw tolerance
    is given as ``yaw_tolerance_deg=`` (degrees, as mission files write it) or
    ``yaw_tolerance_rad=``, stored as :attr:`yaw_tolerance_rad`. The unit-less names
    (``goal_timeout=``, ``yaw_tolerance=`` ...) are a :class:`TypeError` saying what to
    write. ``None`` disables a limit. Mission files and ROS parameters keep their own
    keys (``goal_timeout``, ``yaw_tolerance`` in degrees ...): :data:`POLICY_KEYS`.
    """

    goal_timeout_s: float | None = None
    stall_timeout_s: float | None = None  # s without progress before the attempt fails
    retries: int = 0
    clear_costmaps_on_retry: bool = False
    # Run in order after a failed attempt, before the next one (navseq.mission.recovery).
    recoveries: tuple[Recovery, ...] = ()
    on_failure: FailureAction = FailureAction.STOP
    pass_through_m: float | None = None  # radius; None: the robot stops at the waypoint
    dwell_s: float = 0.0
    # Arrival check on SUCCEEDED: None takes the robot profile's goal tolerance.
    xy_tolerance_m: float | None = None
    yaw_tolerance_rad: float | None = None
    # Run in order once the waypoint is reached (after the dwell); a waypoint's list
    # replaces the defaults' list as a whole.
    tasks: tuple[Task, ...] = ()

    def __init__(
        self,
        *ambiguous: NoReturn,
        goal_timeout_s: float | None = None,
        stall_timeout_s: float | None = None,
        retries: int = 0,
        clear_costmaps_on_retry: bool = False,
        recoveries: tuple[Recovery, ...] = (),
        on_failure: FailureAction = FailureAction.STOP,
        pass_through_m: float | None = None,
        dwell_s: float = 0.0,
        xy_tolerance_m: float | None = None,
        yaw_tolerance_deg: float | None = None,
        yaw_tolerance_rad: float | None = None,
        tasks: tuple[Task, ...] = (),
        **unknown: NoReturn,
    ) -> None:
        if ambiguous:
            raise TypeError("Policy() takes keywords only, e.g. Policy(goal_timeout_s=60)")
        for name in unknown:
            if name in _POLICY_RENAMED:
                raise TypeError(f"Policy({name}=...) has no unit; write {_POLICY_RENAMED[name]}")
        if unknown:
            raise TypeError(f"Policy() got unexpected keyword argument(s): {', '.join(unknown)}")
        if yaw_tolerance_deg is not None and yaw_tolerance_rad is not None:
            raise TypeError(
                "Policy(): give the yaw tolerance once, as yaw_tolerance_deg= or "
                "yaw_tolerance_rad=, not both"
            )
        if yaw_tolerance_deg is not None:
            yaw_tolerance_rad = math.radians(yaw_tolerance_deg)
        for name_, value in (
            ("goal_timeout_s", goal_timeout_s),
            ("stall_timeout_s", stall_timeout_s),
            ("retries", retries),
            ("clear_costmaps_on_retry", clear_costmaps_on_retry),
            ("recoveries", tuple(recoveries)),
            ("on_failure", on_failure),
            ("pass_through_m", pass_through_m),
            ("dwell_s", dwell_s),
            ("xy_tolerance_m", xy_tolerance_m),
            ("yaw_tolerance_rad", yaw_tolerance_rad),
            ("tasks", tuple(tasks)),
        ):
            object.__setattr__(self, name_, value)

    @property
    def yaw_tolerance_deg(self) -> float | None:
        """The yaw tolerance in degrees (None: the robot profile's)."""
        return None if self.yaw_tolerance_rad is None else math.degrees(self.yaw_tolerance_rad)

    def with_overrides(self, overrides: Mapping[str, Any]) -> Policy:
        """This policy with ``overrides`` (keywords of :class:`Policy`) applied."""
        if not overrides:
            return self
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        if "yaw_tolerance_deg" in overrides:
            del values["yaw_tolerance_rad"]
        return Policy(**{**values, **overrides})


#: Each policy key of mission files and ROS parameters (no unit in the name, as
#: docs/mission-format.md documents them) -> the :class:`Policy` field it sets. The file's
#: ``yaw_tolerance`` is degrees; its reader hands over radians.
POLICY_KEYS: Mapping[str, str] = MappingProxyType(
    {
        "goal_timeout": "goal_timeout_s",
        "stall_timeout": "stall_timeout_s",
        "retries": "retries",
        "clear_costmaps_on_retry": "clear_costmaps_on_retry",
        "recovery": "recoveries",
        "on_failure": "on_failure",
        "pass_through": "pass_through_m",
        "dwell": "dwell_s",
        "xy_tolerance": "xy_tolerance_m",
        "yaw_tolerance": "yaw_tolerance_rad",
    }
)


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

    ``overrides`` are per-waypoint :class:`Policy` values, by its keywords
    (``{"goal_timeout_s": 30.0}``; a wrong key is a TypeError here, not later);
    ``where`` (``"file.yaml:12"``) is where the user wrote it, for messages, and is
    not part of equality. ``geo`` is the GPS position the waypoint was written as (its
    ``x``/``y`` are that position in the map frame, through the mission's ``datum``),
    kept for writing the mission back; not part of equality either.
    """

    x: float  # m
    y: float  # m
    yaw_rad: float = 0.0
    z: float = 0.0  # m
    name: str | None = None
    overrides: Mapping[str, Any] = field(default_factory=lambda: _NO_OVERRIDES)
    where: str | None = field(default=None, compare=False)
    geo: GeoPoint | None = field(default=None, compare=False)

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
        geo: GeoPoint | None = None,
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
        if overrides:
            overrides = _policy_overrides(overrides)
        yaw = math.radians(yaw_deg) if yaw_deg is not None else (yaw_rad or 0.0)
        # One update of the instance's dict, not seven object.__setattr__ calls (frozen):
        # a 100 000-waypoint mission builds this 100 000 times while loading.
        self.__dict__.update(
            x=x,
            y=y,
            yaw_rad=yaw,
            z=z,
            name=name,
            overrides=_NO_OVERRIDES if not overrides else MappingProxyType(dict(overrides)),
            where=where,
            geo=geo,
        )

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


def _policy_overrides(overrides: Mapping[str, Any]) -> dict[str, Any]:
    """``overrides`` checked against :class:`Policy`'s keywords, by its field names.

    ``yaw_tolerance_deg`` becomes ``yaw_tolerance_rad``, so that the stored overrides
    name fields only.
    """
    applied = Policy().with_overrides(overrides)  # a TypeError names a wrong keyword
    return {
        "yaw_tolerance_rad" if key == "yaw_tolerance_deg" else key: (
            applied.yaw_tolerance_rad if key == "yaw_tolerance_deg" else value
        )
        for key, value in overrides.items()
    }


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
    record: bool = False  # record the run as MCAP (navseq run --record), as record: says
    # The map frame's origin on the globe, for waypoints given as latitude/longitude
    # (already converted to x/y when read); None: the mission has no GPS positions.
    datum: Datum | None = None
    # Nav2 costmap-filter masks (keepout, speed zones) over the map, in file order.
    filters: tuple[CostmapFilter, ...] = ()
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
