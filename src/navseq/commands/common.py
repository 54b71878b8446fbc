"""Argument types and helpers shared by several subcommands."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from navseq.errors import NavseqError
from navseq.files import require_file
from navseq.geometry import Pose2D
from navseq.mission.robot_format import choose_robot
from navseq.run.values import (
    format_pose,
    loops_from_text,
    pose_from_text,
    realtime_from_text,
)

T = TypeVar("T")

if TYPE_CHECKING:
    from collections.abc import Sequence

    from navseq.mission.costmap_filters import CostmapFilter
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.route.legs import Legs
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid


def _argument(read: Callable[[str], T], text: str) -> T:
    """``read(text)``, its ValueError as argparse's usage error."""
    try:
        return read(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def parse_pose(text: str) -> Pose2D:
    """``x,y,yaw`` (metres, metres, degrees — like mission files) as a Pose2D in radians."""
    return _argument(pose_from_text, text)


def parse_loops(text: str) -> int | None:
    """A loop count >= 1, or ``forever`` (None)."""
    return _argument(loops_from_text, text)


def parse_waypoint_number(text: str) -> int:
    """A whole number: a 1-based waypoint number, as the summary table prints it.

    Whether the waypoint exists is checked against the mission, whose size says the
    valid range (:class:`navseq.mission.part.PartSpec`).
    """
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a waypoint number (1 for the first), got {text!r}"
        ) from None


def parse_realtime(text: str) -> float:
    """A real-time factor > 0 (``--realtime 2``: twice as fast as real time)."""
    return _argument(realtime_from_text, text)


def preflight_errors(
    mission: Mission,
    costmap: Costmap,
    start: Pose2D | None,
    numbers: Sequence[int] | None = None,
    robot: RobotProfile | None = None,
) -> list[NavseqError]:
    """Every problem of ``mission`` against the map (empty when it is fine to run).

    ``costmap`` must have been built for ``robot`` (:func:`costmap_for_map`).
    """
    from navseq.preflight import check_mission

    return check_mission(mission, costmap, start, numbers=numbers, robot=robot)


def costmap_for_map(map_path: Path, robot: RobotProfile | None = None) -> Costmap:
    """The costmap of a map_server YAML file for ``robot`` (default: the default profile)."""
    from navseq.sim.occupancy import load_map

    return costmap_for_robot(load_map(map_path), robot)


def costmap_for_robot(grid: OccupancyGrid, robot: RobotProfile | None = None) -> Costmap:
    """The grid inflated for ``robot``'s outline and inflation settings."""
    from navseq.mission.robot import DEFAULT_PROFILE
    from navseq.sim.costmap import Costmap
    from navseq.sim.profile import costmap_params_of

    return Costmap.from_grid(grid, costmap_params_of(robot or DEFAULT_PROFILE))


def legs_on_map(
    map_path: Path | None,
    robot: RobotProfile,
    costmaps: Callable[[Path, RobotProfile], Costmap] | None = None,
    filters: Sequence[CostmapFilter] = (),
) -> Legs:
    """The legs a mission's route is made of: planned on ``map_path``'s costmap for
    ``robot`` (with the mission's costmap ``filters``: keepout and speed zones), or
    straight lines when there is no map. ``costmaps`` builds (or recalls) the costmap;
    by default the map is read and inflated here."""
    from navseq.route.legs import LegPlanner, StraightLegs
    from navseq.sim.filters import costmap_with_filters

    if map_path is None:
        return StraightLegs()
    costmap = (costmaps or costmap_for_map)(map_path, robot)
    return LegPlanner(costmap_with_filters(costmap, filters))


def add_robot_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--robot",
        metavar="NAME|FILE",
        help="robot profile: a built-in name (turtlebot3_burger, turtlebot3_waffle, "
        "turtlebot3_waffle_pi) or a YAML file like a mission's robot: section "
        "(default: the mission's robot:, else turtlebot3_burger)",
    )


__all__ = [
    "add_robot_option",
    "choose_robot",
    "costmap_for_map",
    "costmap_for_robot",
    "format_pose",
    "legs_on_map",
    "parse_loops",
    "parse_pose",
    "parse_realtime",
    "parse_waypoint_number",
    "preflight_errors",
    "require_file",
]
