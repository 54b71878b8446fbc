"""``navseq validate MISSION [--map MAP]``: every problem of a mission, all at once.

The mission file itself (syntax, values, names) and, when a map is known (``--map``
or the mission's ``map:`` key), the pre-flight check of every waypoint against that
map, in one list: waypoints that read well are checked against the map even when
others in the file have problems. Exit 0 when there is nothing to report, 2 otherwise.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.commands.common import add_robot_option, parse_pose
from navseq.errors import NavseqError

if TYPE_CHECKING:
    from navseq.mission.model import Mission


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("mission", type=Path, metavar="MISSION", help="mission file to check")
    parser.add_argument(
        "--map",
        type=Path,
        metavar="MAP",
        help="map_server YAML to check the waypoints against (default: the mission's map:)",
    )
    parser.add_argument(
        "--start",
        type=parse_pose,
        metavar="X,Y,YAW",
        help="start pose to check (metres, metres, degrees; default: the mission's start:)",
    )
    add_robot_option(parser)


def run(args: argparse.Namespace) -> int:
    from navseq.commands.common import require_file
    from navseq.errors import MissionErrors
    from navseq.mission import inspect_mission_file
    from navseq.mission.robot_format import robot_from_option

    # Every problem of every input, in one list: a bad --map or --robot does not hide
    # the mission's problems, nor the other way round.
    option_errors: list[NavseqError] = []
    if args.map is not None:
        try:
            require_file(args.map, "--map")
        except NavseqError as error:
            option_errors.append(error)
    if args.robot is not None:
        try:
            robot_from_option(args.robot)
        except NavseqError as error:
            option_errors.append(error)
    mission, problems = inspect_mission_file(args.mission)
    errors = list(problems.errors)
    if option_errors:
        errors += option_errors  # the map cannot be checked without them
    elif mission is None and problems.salvage is not None:
        # Check the waypoints that did read against the map as well, so that one run
        # of validate lists everything to fix.
        errors += _map_problems(args, problems.salvage.mission, problems.salvage.numbers)
    elif mission is not None:
        errors += _map_problems(args, mission)
    elif args.map is not None:  # no waypoints to check, but the map can still be read
        errors += _map_problems(args, None)
    if errors:
        raise MissionErrors(errors)
    assert mission is not None
    count = len(mission.waypoints)
    loops = "forever" if mission.loops is None else str(mission.loops)
    map_path = _map_path(args, mission)
    checked = f"checked against map {map_path}" if map_path is not None else "no map to check"
    if map_path is not None:
        from navseq.commands.common import choose_robot

        checked += f" for robot {choose_robot(args.robot, mission).name}"
    print(
        f"{args.mission}: OK — {count} waypoint{'s' if count != 1 else ''}, "
        f"loops {loops}, {checked}",
        file=sys.stdout,
    )
    return 0


def _map_path(args: argparse.Namespace, mission: Mission | None) -> Path | None:
    if args.map is not None:
        return Path(args.map)
    return mission.map if mission is not None else None


def _map_problems(
    args: argparse.Namespace, mission: Mission | None, numbers: Sequence[int] | None = None
) -> list[NavseqError]:
    """The pre-flight problems of ``mission`` on the map given or named, if any.

    Without a mission (a file that did not read at all) only the map itself is checked.
    """
    from navseq.commands.common import choose_robot, costmap_for_map, preflight_errors

    map_path = _map_path(args, mission)
    if map_path is None:
        return []
    robot = choose_robot(args.robot, mission)
    try:
        costmap = costmap_for_map(map_path, robot)
    except NavseqError as error:  # an unreadable map is one more problem to list
        return [error]
    if mission is None:
        return []
    start = args.start if args.start is not None else mission.start
    return preflight_errors(mission, costmap, start, numbers, robot)
