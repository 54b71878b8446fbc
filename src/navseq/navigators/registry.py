"""The navigator kinds a run may use, listed in :data:`NAVIGATORS`.

A kind declares, as data, its name, one-line help, its typed settings (a frozen
dataclass of :mod:`navseq.navigators.settings`, whose fields carry their command-line
options) and the module that creates it. That module provides::

    create(settings: <the kind's settings>, draft: NavigatorDraft) -> NavigatorSetup

which connects to (or builds) the navigation stack and checks what it needs before the
robot moves, raising :class:`~navseq.errors.NavseqError` on any problem. It is imported
only when its kind is chosen, so it may import its client library (rospy, rclpy) at
the top: the settings and options are known from the declarations here alone, without
ROS.

Adding a navigator is therefore one module (adapter + ``create``), one settings class
and one entry in :data:`NAVIGATORS`; neither the executor nor the run service changes.
An option several kinds share (``--frame``, ``--ns``) is a field of each kind's
settings, and each kind applies its own default.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, cast

from navseq.mission.recovery import RECOVERY_KINDS
from navseq.navigators.plain_recoveries import PLAIN_KINDS
from navseq.navigators.settings import (
    Nav2NavigatorSettings,
    NavigatorSettings,
    Ros1NavigatorSettings,
    ScriptedNavigatorSettings,
    SettingField,
    SimNavigatorSettings,
    setting_fields,
)

if TYPE_CHECKING:
    from navseq.executor.machine import MissionListener
    from navseq.geometry import Pose2D
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.navigators.base import Navigator
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid
    from navseq.tasks.ros_port import RosTypes


@dataclass
class NavigatorDraft:
    """What the run has read and checked, for a kind to build its navigator on.

    A kind may settle what the user left open: the start pose (the simulator picks
    one), the robot profile (read from the running stack).
    """

    mission: Mission
    map_path: Path | None
    start: Pose2D | None
    start_source: str | None
    robot: RobotProfile
    preflight: bool = True  # False with --no-preflight
    # The waypoints' numbers in the file when the run is a part of it (--from/--to/--only),
    # so that pre-flight names them as the user numbers them.
    numbers: Sequence[int] | None = None
    # The simulator's pace against the wall clock (None: as fast as it goes).
    realtime: float | None = None
    # True when the user named the robot (or the mission did): a kind reads none from the
    # stack then.
    robot_given: bool = False

    def check_against(self, costmap: Costmap, context: str = "") -> None:
        """Pre-flight on this costmap: every problem of the mission, raised together
        (``context`` heads the list, see :class:`~navseq.errors.MissionErrors`)."""
        if not self.preflight:
            return
        from navseq.errors import MissionErrors
        from navseq.preflight import check_mission

        problems = check_mission(
            self.mission, costmap, self.start, numbers=self.numbers, robot=self.robot
        )
        if problems:
            raise MissionErrors(problems, context)

    def check_map(self, grid: OccupancyGrid, context: str = "") -> None:
        """Pre-flight on ``grid`` inflated for the draft's robot, as it stands now (a kind
        settles the robot first); nothing at all with ``--no-preflight``."""
        if not self.preflight:
            return
        from navseq.sim.costmap import Costmap
        from navseq.sim.filters import with_filters
        from navseq.sim.profile import costmap_params_of

        if grid.filters is None:  # a stack's map: the mission's keepout zones still apply
            grid = with_filters(grid, self.mission.filters)
        self.check_against(Costmap.from_grid(grid, costmap_params_of(self.robot)), context)

    def optional_map(self) -> OccupancyGrid | None:
        """The map, if one is known, with the mission checked against it."""
        if self.map_path is None:
            return None
        from navseq.sim.filters import load_filtered_map

        grid = load_filtered_map(self.map_path, self.mission.filters)
        self.check_map(grid)
        return grid


@dataclass
class NavigatorSetup:
    """A kind's answer: how to make the navigator, and what the run should know of it."""

    make_navigator: Callable[[], Navigator]
    info: dict[str, Any]  # the report's "navigator" section; "kind" at least
    grid: OccupancyGrid | None = None  # the map the run is drawn on, if any
    notes: list[str] = field(default_factory=list)  # one line each, for stderr
    listeners: list[MissionListener] = field(default_factory=list)  # ROS topics ...


class KindModule(Protocol):
    def create(self, settings: Any, draft: NavigatorDraft) -> NavigatorSetup: ...


@dataclass(frozen=True)
class NavigatorKind:
    """One ``--navigator NAME``. ``requires`` names what its module needs, for the error
    a missing dependency becomes; ``hidden`` kinds (test doubles) stay out of ``--help``.
    ``places_robot`` is False for a real robot's stack: the robot is where it is, so a
    start pose is refused; ``paced`` is True for the simulator, the only kind whose time
    a run may pace (``realtime``). ``ros``: the kind drives a ROS stack, so a mission's
    ROS tasks run there (on the navigator's node), and are only rehearsed
    (``--simulate-tasks``) on the kinds without; ``task_types`` is then the module whose
    ``ros_types()`` says which message types the running ROS can load (checked before
    the run). ``recoveries``: the recovery kinds (a retry's ``recovery:`` list) it can
    run; a mission naming another is refused before the robot moves."""

    name: str
    help: str
    module: str
    settings: type[Any] = SimNavigatorSettings
    requires: str = ""
    hidden: bool = False
    places_robot: bool = True
    paced: bool = False
    ros: bool = False
    task_types: str = ""
    recoveries: frozenset[str] = frozenset(RECOVERY_KINDS)

    def ros_types(self) -> RosTypes:
        """The running ROS's message types, for the check before the run. Where the
        client library does not import, every type passes here: :meth:`create` then
        says what is missing."""
        try:
            module = importlib.import_module(self.task_types)
        except ImportError:
            return _AnyType()
        types: RosTypes = module.ros_types()
        return types

    def create(self, settings: NavigatorSettings, draft: NavigatorDraft) -> NavigatorSetup:
        from navseq.errors import NavseqError

        if not isinstance(settings, self.settings):
            raise TypeError(
                f"the {self.name} navigator takes {self.settings.__name__}, "
                f"not {type(settings).__name__}"
            )
        try:
            module = cast(KindModule, importlib.import_module(self.module))
        except ImportError as error:
            needs = f" needs {self.requires}" if self.requires else " cannot be loaded"
            raise NavseqError(
                f"the {self.name} navigator{needs}: {error}. Install them (see "
                "DEVELOPERS.md) and run navseq from the project's venv",
                source=f"--navigator {self.name}",
            ) from None
        return module.create(settings, draft)

    def options(self) -> tuple[SettingField, ...]:
        """The settings' fields with their command-line options."""
        return tuple(setting_fields(self.settings))

    def option_defaults(self) -> dict[str, Any]:
        return {option.name: option.info.default for option in self.options()}

    def journaled(self) -> tuple[str, ...]:
        """The fields a run of this kind records in its journal."""
        return tuple(option.name for option in self.options() if option.info.journaled)


class _AnyType:
    """Types where ROS is not there to ask: none is refused (the kind refuses the run)."""

    def type_problem(self, type_name: str, *, service: bool = False) -> str | None:
        return None

    def fields_problem(
        self, type_name: str, fields: Mapping[str, Any], *, service: bool = False
    ) -> str | None:
        return None


NAVIGATORS: tuple[NavigatorKind, ...] = (
    NavigatorKind(
        "sim",
        "the embedded simulator (default)",
        "navseq.navigators.sim",
        SimNavigatorSettings,
        paced=True,
    ),
    NavigatorKind(
        "ros1",
        "move_base over actionlib",
        "navseq.ros1.run_setup",
        Ros1NavigatorSettings,
        requires="ROS 1's Python packages (rospy, actionlib, move_base_msgs)",
        places_robot=False,
        ros=True,
        task_types="navseq.ros1.task_port",
        # move_base has no action per behaviour: wait and clear_costmaps only.
        recoveries=PLAIN_KINDS,
    ),
    NavigatorKind(
        "nav2",
        "ROS 2 Nav2's navigate_to_pose over rclpy",
        "navseq.ros2.run_setup",
        Nav2NavigatorSettings,
        requires="ROS 2's Python packages (rclpy, nav2_msgs): source ROS 2 first "
        "(e.g. source /opt/ros/jazzy/setup.bash), then start navseq from that shell",
        places_robot=False,
        ros=True,
        task_types="navseq.ros2.task_port",
    ),
    # A deterministic stand-in for the plumbing's tests; its options are hidden too.
    NavigatorKind(
        "scripted",
        "scripted test double",
        "navseq.navigators.scripted",
        ScriptedNavigatorSettings,
        hidden=True,
    ),
)


def navigator_kind(name: str) -> NavigatorKind:
    for kind in NAVIGATORS:
        if kind.name == name:
            return kind
    raise KeyError(name)


def kind_of(settings: NavigatorSettings) -> NavigatorKind:
    """The kind whose settings class ``settings`` is (KeyError: none is)."""
    for kind in NAVIGATORS:
        if type(settings) is kind.settings:
            return kind
    raise KeyError(type(settings).__name__)


def create(settings: NavigatorSettings, draft: NavigatorDraft) -> NavigatorSetup:
    """The navigator of the kind ``settings`` belong to, made ready for ``draft``."""
    return kind_of(settings).create(settings, draft)


def settings_from(kind: NavigatorKind, values: dict[str, Any]) -> NavigatorSettings:
    """``kind``'s settings from ``values`` (field name -> value); names it lacks are left."""
    names = {option.name for option in kind.options()}
    return cast(
        NavigatorSettings,
        kind.settings(**{name: value for name, value in values.items() if name in names}),
    )


def journaled_options() -> tuple[str, ...]:
    """Every field any kind journals: what a resume may take from a journal."""
    names: dict[str, None] = {}
    for kind in NAVIGATORS:
        names.update(dict.fromkeys(kind.journaled()))
    return tuple(names)


@dataclass(frozen=True)
class SharedOption:
    """One command-line option and the kinds whose settings have it."""

    name: str
    declared: SettingField
    kinds: tuple[str, ...]
    hidden: bool


def command_line_options() -> list[SharedOption]:
    """Every kind's options, each once, with the kinds that use it, in declaration order."""
    found: dict[str, SharedOption] = {}
    for kind in NAVIGATORS:
        for option in kind.options():
            hidden = kind.hidden or option.info.hidden
            known = found.get(option.name)
            if known is None:
                found[option.name] = SharedOption(option.name, option, (kind.name,), hidden)
            else:
                found[option.name] = SharedOption(
                    option.name, known.declared, (*known.kinds, kind.name), known.hidden and hidden
                )
    return list(found.values())


__all__ = [
    "NAVIGATORS",
    "NavigatorDraft",
    "NavigatorKind",
    "NavigatorSetup",
    "SharedOption",
    "command_line_options",
    "create",
    "journaled_options",
    "kind_of",
    "navigator_kind",
    "settings_from",
]
