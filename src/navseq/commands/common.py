"""Argument types and helpers shared by several subcommands."""

from __future__ import annotations

import argparse
import math
import stat
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.fields import MAX_COORDINATE, MAX_YAW_DEGREES, normalized_yaw
from navseq.text import printable

if TYPE_CHECKING:
    from collections.abc import Sequence

    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.route.legs import Legs
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid


def parse_pose(text: str) -> Pose2D:
    """``x,y,yaw`` (metres, metres, degrees — like mission files) as a Pose2D in radians."""
    parts = [part.strip() for part in text.split(",")]
    if len(parts) not in (2, 3):
        raise argparse.ArgumentTypeError(
            f"expected x,y,yaw (metres, metres, degrees), got {text!r}"
        )
    try:
        values = [float(part) for part in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected numbers x,y,yaw (metres, metres, degrees), got {text!r}"
        ) from None
    if not all(math.isfinite(value) for value in values):
        raise argparse.ArgumentTypeError(f"x,y,yaw must be finite numbers, got {text!r}")
    # The limits of mission files: beyond them map arithmetic overflows.
    if any(abs(value) > MAX_COORDINATE for value in values[:2]):
        raise argparse.ArgumentTypeError(
            f"x and y must be within ±{MAX_COORDINATE:g} m, got {text!r}"
        )
    yaw_degrees = values[2] if len(values) == 3 else 0.0
    if abs(yaw_degrees) > MAX_YAW_DEGREES:
        raise argparse.ArgumentTypeError(
            f"yaw must be within ±{MAX_YAW_DEGREES:g} degrees, got {text!r}"
        )
    return Pose2D(values[0], values[1], normalized_yaw(math.radians(yaw_degrees)))


def parse_loops(text: str) -> int | None:
    """A loop count >= 1, or ``forever`` (None)."""
    if text.strip().lower() == "forever":
        return None
    try:
        loops = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a whole number >= 1 or 'forever', got {text!r}"
        ) from None
    if loops < 1:
        raise argparse.ArgumentTypeError(f"loops must be >= 1 (or 'forever'), got {loops}")
    return loops


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
    try:
        factor = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a speed factor such as 1 or 0.5, got {text!r} (its FACTOR is optional: "
            "put MISSION before --realtime, or give one, e.g. --realtime 1)"
        ) from None
    if not (math.isfinite(factor) and factor > 0):
        raise argparse.ArgumentTypeError(f"the factor must be a number above 0, got {text!r}")
    return factor


def format_pose(pose: Pose2D) -> str:
    return f"({pose.x:.2f}, {pose.y:.2f}, {math.degrees(pose.yaw):.0f}°)"


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


def legs_on_map(map_path: Path | None, robot: RobotProfile) -> Legs:
    """The legs a mission's route is made of: planned on ``map_path``'s costmap for
    ``robot``, or straight lines when there is no map."""
    from navseq.route.legs import LegPlanner, StraightLegs

    if map_path is None:
        return StraightLegs()
    return LegPlanner(costmap_for_map(map_path, robot))


def add_robot_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--robot",
        metavar="NAME|FILE",
        help="robot profile: a built-in name (turtlebot3_burger, turtlebot3_waffle, "
        "turtlebot3_waffle_pi) or a YAML file like a mission's robot: section "
        "(default: the mission's robot:, else turtlebot3_burger)",
    )


def choose_robot(option: str | RobotProfile | None, mission: Mission | None) -> RobotProfile:
    """The robot to plan and check for: ``--robot`` > the mission's ``robot:`` > default.

    ``--robot`` (a built-in name or a file) is read here, not by argparse, so that a bad
    name or file is one NavseqError (exit 2) like every other input problem. The Python
    API may pass a :class:`RobotProfile` itself.
    """
    from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
    from navseq.mission.robot_format import robot_from_option

    if isinstance(option, RobotProfile):
        return option
    if option is not None:
        return robot_from_option(option)
    if mission is not None and mission.robot is not None:
        return mission.robot
    return DEFAULT_PROFILE


def require_file(path: Path, what: str) -> None:
    """A clear NavseqError unless ``path``, given by the user as ``what``, is a regular file.

    A FIFO or a device would hang or never end when read, so they are refused here,
    before anything opens them.
    """
    shown = printable(str(path))
    try:
        info = path.stat()
    except FileNotFoundError:
        raise NavseqError(f"no such file: {shown}", source=what) from None
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the name
        reason = error.strerror if isinstance(error, OSError) else "not a valid file name"
        raise NavseqError(f"cannot read {shown}: {reason or error}", source=what) from None
    if stat.S_ISDIR(info.st_mode):
        raise NavseqError(f"{shown} is a directory, not a file", source=what)
    if not stat.S_ISREG(info.st_mode):
        raise NavseqError(f"{shown} is not a regular file (a device, pipe or socket?)", source=what)
