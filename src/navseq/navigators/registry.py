"""The navigator kinds ``navseq run --navigator`` offers, listed in :data:`NAVIGATORS`.

A kind declares, as data, its name, one-line help, its command-line options and the
module that creates it. That module provides::

    create(args: argparse.Namespace, draft: NavigatorDraft) -> NavigatorSetup

which connects to (or builds) the navigation stack and checks what it needs before the
robot moves, raising :class:`~navseq.errors.NavseqError` on any problem. It is imported
only when its kind is chosen, so it may import its client library (rospy, rclpy) at
the top: the parser is built from the declarations here alone, without ROS.

Adding a navigator is therefore one module (adapter + ``create``) plus one entry in
:data:`NAVIGATORS`; neither the executor nor ``navseq run`` changes. An option several
kinds share (``--frame``, ``--ns``) is declared by each and added to the parser once,
under the first kind that declares it; each kind applies its own default.
"""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, cast

from navseq.navigators.stack_map import MAP_WAIT

if TYPE_CHECKING:
    from navseq.executor.machine import MissionListener
    from navseq.geometry import Pose2D
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.navigators.base import Navigator
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid


@dataclass(frozen=True)
class NavigatorOption:
    """One command-line option of a navigator kind.

    ``default`` is applied after a resume had its say: a ``journaled`` option is
    recorded in the run's journal, and ``navseq run --resume`` continues with the
    recorded value unless the command line gives the option again.
    """

    flag: str
    help: str
    default: Any = None
    type: Callable[[str], Any] | None = None
    metavar: str | None = None
    journaled: bool = True

    @property
    def dest(self) -> str:
        return self.flag.lstrip("-").replace("-", "_")


@dataclass
class NavigatorDraft:
    """What ``navseq run`` has read and checked, for a kind to build its navigator on.

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

    def check_against(self, costmap: Costmap, context: str = "") -> None:
        """Pre-flight on this costmap: every problem of the mission, raised together
        (``context`` heads the list, see :class:`~navseq.errors.MissionErrors`)."""
        if not self.preflight:
            return
        from navseq.commands.common import preflight_errors
        from navseq.errors import MissionErrors

        problems = preflight_errors(
            self.mission, costmap, self.start, self.numbers, robot=self.robot
        )
        if problems:
            raise MissionErrors(problems, context)

    def check_map(self, grid: OccupancyGrid, context: str = "") -> None:
        """Pre-flight on ``grid`` inflated for the draft's robot, as it stands now (a kind
        settles the robot first); nothing at all with ``--no-preflight``."""
        if not self.preflight:
            return
        from navseq.commands.common import costmap_for_robot

        self.check_against(costmap_for_robot(grid, self.robot), context)

    def optional_map(self) -> OccupancyGrid | None:
        """The map, if one is known, with the mission checked against it."""
        if self.map_path is None:
            return None
        from navseq.sim.occupancy import load_map

        grid = load_map(self.map_path)
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
    def create(self, args: argparse.Namespace, draft: NavigatorDraft) -> NavigatorSetup: ...


@dataclass(frozen=True)
class NavigatorKind:
    """One ``--navigator NAME``. ``requires`` names what its module needs, for the error
    a missing dependency becomes; ``hidden`` kinds (test doubles) stay out of ``--help``.
    ``places_robot`` is False for a real robot's stack: the robot is where it is, so
    ``--start`` is refused."""

    name: str
    help: str
    module: str
    options: tuple[NavigatorOption, ...] = ()
    requires: str = ""
    hidden: bool = False
    places_robot: bool = True

    def create(self, args: argparse.Namespace, draft: NavigatorDraft) -> NavigatorSetup:
        from navseq.errors import NavseqError

        try:
            module = cast(KindModule, importlib.import_module(self.module))
        except ImportError as error:
            needs = f" needs {self.requires}" if self.requires else " cannot be loaded"
            raise NavseqError(
                f"the {self.name} navigator{needs}: {error}. Install them (see "
                "DEVELOPERS.md) and run navseq from the project's venv",
                source=f"--navigator {self.name}",
            ) from None
        return module.create(args, draft)

    def option_defaults(self) -> dict[str, Any]:
        return {option.dest: option.default for option in self.options}

    def journaled(self) -> tuple[str, ...]:
        """The destinations of the options a run of this kind records in its journal."""
        return tuple(option.dest for option in self.options if option.journaled)


NAVIGATORS: tuple[NavigatorKind, ...] = (
    NavigatorKind(
        "sim",
        "the embedded simulator (default)",
        "navseq.navigators.sim",
    ),
    NavigatorKind(
        "ros1",
        "move_base over actionlib",
        "navseq.ros1.run_setup",
        options=(
            NavigatorOption(
                "--action",
                "action server name (default: move_base; nav2: navigate_to_pose)",
                "move_base",
            ),
            NavigatorOption("--frame", "goal frame (default: the mission's frame:, usually map)"),
            NavigatorOption("--ns", "robot namespace, e.g. robot1 (default: none)", ""),
            NavigatorOption(
                "--settle",
                "wall seconds between a goal's result and the next goal, against "
                "move_base's SUCCEEDED race (navigation #949); 0: off (default 0.05)",
                0.05,
                type=float,
                metavar="S",
            ),
            NavigatorOption(
                "--map-wait",
                "without --map (or the mission's map:), pre-flight checks the waypoints on "
                "the stack's own map (NS/map, else /map) and the picture is drawn on it: "
                "wall seconds to wait for it; none by then: pre-flight is skipped, said on "
                f"stderr. 0: do not read it (default {MAP_WAIT:g}; also nav2)",
                MAP_WAIT,
                type=float,
                metavar="S",
                journaled=False,
            ),
        ),
        requires="ROS 1's Python packages (rospy, actionlib, move_base_msgs)",
        places_robot=False,
    ),
    NavigatorKind(
        "nav2",
        "ROS 2 Nav2's navigate_to_pose over rclpy",
        "navseq.ros2.run_setup",
        options=(
            NavigatorOption("--action", "", "navigate_to_pose"),  # declared by ros1
            NavigatorOption("--frame", ""),
            NavigatorOption("--ns", "", ""),
            NavigatorOption(
                "--server-timeout",
                "wall seconds to wait for the navigate_to_pose server before giving up "
                "(exit 2, nothing moved; default 30). The mission's server_timeout: is how "
                "long to wait for a server that vanishes during the run",
                30.0,
                type=float,
                metavar="S",
                journaled=False,
            ),
            NavigatorOption(
                "--use-sim-time",
                "auto, true or false: run on ROS time from /clock (auto: when /clock is "
                "published; default auto)",
                "auto",
                metavar="auto|true|false",
            ),
            NavigatorOption("--map-wait", "", MAP_WAIT, type=float, journaled=False),
        ),
        requires="ROS 2's Python packages (rclpy, nav2_msgs): source ROS 2 first "
        "(e.g. source /opt/ros/jazzy/setup.bash), then start navseq from that shell",
        places_robot=False,
    ),
    # A deterministic stand-in for the plumbing's tests; its options are hidden too.
    NavigatorKind(
        "scripted",
        "scripted test double",
        "navseq.navigators.scripted",
        options=(
            NavigatorOption("--scripted-speed", "", 0.5, type=float, journaled=False),
            NavigatorOption("--scripted-realtime", "", None, type=float, journaled=False),
            NavigatorOption("--scripted-log", "", None, type=Path, journaled=False),
            NavigatorOption("--scripted-script", "", "", journaled=False),
        ),
        hidden=True,
    ),
)


def navigator_kind(name: str) -> NavigatorKind:
    for kind in NAVIGATORS:
        if kind.name == name:
            return kind
    raise KeyError(name)


def journaled_options() -> tuple[str, ...]:
    """Every option any kind journals: what a resume may take from a journal."""
    names: dict[str, None] = {}
    for kind in NAVIGATORS:
        names.update(dict.fromkeys(kind.journaled()))
    return tuple(names)


def add_navigator_choice(parser: argparse.ArgumentParser, default: str | None) -> None:
    """``--navigator``: the visible kinds in ``--help``, hidden ones accepted too."""
    visible = [kind for kind in NAVIGATORS if not kind.hidden]
    parser.add_argument(
        "--navigator",
        choices=[kind.name for kind in NAVIGATORS],
        default=default,
        metavar="{" + ",".join(kind.name for kind in visible) + "}",
        help="; ".join(f"{kind.name}: {kind.help}" for kind in visible),
    )


def add_navigator_options(parser: argparse.ArgumentParser) -> None:
    """Every kind's options, in one argument group per visible kind.

    Journaled options default to None on the parser, so that a resume can tell an
    option given again from one left out; :meth:`NavigatorKind.option_defaults` fills
    them in once the kind is known.
    """
    added: set[str] = set()
    for kind in NAVIGATORS:
        group = None if kind.hidden else parser.add_argument_group(f"{kind.name} navigator")
        for option in kind.options:
            if option.dest in added:
                continue  # shared with a kind listed earlier
            added.add(option.dest)
            kwargs: dict[str, Any] = {
                "default": None if option.journaled else option.default,
                "help": argparse.SUPPRESS if kind.hidden else option.help,
            }
            if option.type is not None:
                kwargs["type"] = option.type
            if option.metavar is not None:
                kwargs["metavar"] = option.metavar
            (group if group is not None else parser).add_argument(option.flag, **kwargs)
