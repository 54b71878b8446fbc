"""``navseq validate MISSION [--map MAP]``: every problem of a mission, all at once.

The mission file itself (syntax, values, names) and, when a map is known (``--map``
or the mission's ``map:`` key), the pre-flight check of every waypoint against that
map, in one list: waypoints that read well are checked against the map even when
others in the file have problems. Exit 0 when there is nothing to report, 2 otherwise.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.commands.common import add_robot_option, parse_pose
from navseq.commands.filter_options import add_filter_options, filters_of
from navseq.commands.task_options import add_task_options, task_options_of
from navseq.errors import NavseqError
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.geometry import Pose2D
    from navseq.mission.costmap_filters import CostmapFilter
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.sim.costmap import Costmap
    from navseq.tasks.options import TaskOptions

#: Gives the costmap of a map file for a robot. A long-lived caller (the studio, which
#: checks a mission on every edit) passes one that keeps costmaps it already built, so
#: an edit costs the pre-flight check, not the map's inflation again.
CostmapSource = Callable[["Path", "RobotProfile"], "Costmap"]


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
    add_task_options(parser)
    add_filter_options(parser)


def run(args: argparse.Namespace) -> int:
    from navseq.commands.common import choose_robot, costmap_for_map, require_file
    from navseq.errors import MissionErrors
    from navseq.mission.robot_format import robot_from_option

    # The pre-flight and the ETA's plans use one costmap: inflating a large map is
    # most of what validate --map costs.
    costmaps = functools.cache(costmap_for_map)
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
    if option_errors:
        # The map cannot be checked without them; the file's own problems still can.
        from navseq.mission import inspect_mission_file

        mission, problems = inspect_mission_file(args.mission)
        errors = [*problems.errors, *option_errors]
    else:
        mission, errors = mission_file_problems(
            args.mission,
            map_path=args.map,
            start=args.start,
            robot=args.robot,
            costmaps=costmaps,
            tasks=task_options_of(args),
            filters=filters_of(args),
        )
    if errors:
        raise MissionErrors(errors)
    assert mission is not None
    count = len(mission.waypoints)
    loops = "forever" if mission.loops is None else str(mission.loops)
    map_path = args.map if args.map is not None else mission.map
    checked = (
        f"checked against map {printable(str(map_path))}"
        if map_path is not None
        else "no map to check"
    )
    if map_path is not None:
        checked += f" for robot {choose_robot(args.robot, mission).name}"
    print(
        f"{printable(str(args.mission))}: OK — {count} waypoint{'s' if count != 1 else ''}, "
        f"loops {loops}, {checked}",
        file=sys.stdout,
    )
    if map_path is not None:
        from navseq.commands.common import legs_on_map
        from navseq.eta.predict import predict_legs
        from navseq.eta.text import prediction_lines

        robot = choose_robot(args.robot, mission)
        start = args.start if args.start is not None else mission.start
        legs = legs_on_map(map_path, robot, costmaps, mission.filters)
        prediction = predict_legs(mission, legs, robot, start)
        for line in prediction_lines(prediction, has_start=start is not None):
            print(line, file=sys.stdout)
    return 0


def mission_file_problems(
    path: Path,
    *,
    map_path: Path | None = None,
    start: Pose2D | None = None,
    robot: str | RobotProfile | None = None,
    costmaps: CostmapSource | None = None,
    tasks: TaskOptions | None = None,
    filters: tuple[CostmapFilter, ...] | None = None,
) -> tuple[Mission | None, list[NavseqError]]:
    """The mission in ``path`` (None if it cannot be read) and every problem found.

    The file's own problems and, when a map is known (``map_path``, else the mission's
    ``map:``), the pre-flight problems of every waypoint that did read, in one list.
    ``robot`` is a profile, or a built-in name or file as ``--robot`` takes (default:
    the mission's ``robot:``). ``costmaps`` builds (or recalls) the costmap of a map for
    a robot; by default the map file is read and inflated on each call. ``tasks``: also
    the tasks a simulator run with these options would refuse (``run`` without
    ``--allow-run``, ROS tasks without ``--simulate-tasks``); None: not checked. ``navseq
    validate``, :func:`navseq.validate_file` and the studio's checks all call this.
    ``filters``: costmap filters in place of the mission's (``--keepout``, ``--speed-mask``).
    """
    from navseq.mission import inspect_mission_file

    mission, problems = inspect_mission_file(path)
    if mission is not None and filters is not None:
        mission = dataclasses.replace(mission, filters=filters)
    errors = list(problems.errors)
    if mission is None and problems.salvage is not None:
        # Check the waypoints that did read against the map as well, so that one run
        # of validate lists everything to fix.
        salvage = problems.salvage
        errors += _map_problems(salvage.mission, map_path, start, robot, salvage.numbers, costmaps)
    elif mission is not None:
        if tasks is not None:
            from navseq.tasks.permissions import task_problems

            errors += task_problems(mission, tasks, "sim", simulated=True)
        errors += _map_problems(mission, map_path, start, robot, costmaps=costmaps)
    elif map_path is not None:  # no waypoints to check, but the map can still be read
        errors += _map_problems(None, map_path, start, robot, costmaps=costmaps)
    return mission, errors


def _map_problems(
    mission: Mission | None,
    map_path: Path | None,
    start: Pose2D | None,
    robot_option: str | RobotProfile | None,
    numbers: Sequence[int] | None = None,
    costmaps: CostmapSource | None = None,
) -> list[NavseqError]:
    """The pre-flight problems of ``mission`` on the map given or named, if any.

    Without a mission (a file that did not read at all) only the map itself is checked.
    """
    from navseq.commands.common import choose_robot, costmap_for_map, preflight_errors

    if map_path is None and mission is not None:
        map_path = mission.map
    if map_path is None:
        return []
    robot = choose_robot(robot_option, mission)
    try:
        costmap = (costmaps or costmap_for_map)(map_path, robot)
    except NavseqError as error:  # an unreadable map is one more problem to list
        return [error]
    if mission is None:
        return []
    from navseq.sim.filters import costmap_with_filters

    try:
        costmap = costmap_with_filters(costmap, mission.filters)
    except NavseqError as error:  # an unreadable mask, likewise
        return [error]
    start = start if start is not None else mission.start
    return preflight_errors(mission, costmap, start, numbers, robot)
