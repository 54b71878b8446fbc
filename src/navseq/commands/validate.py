"""``navseq validate MISSION [--map MAP]``: every problem of a mission, all at once.

First the mission file itself (syntax, values, names); then, when a map is known
(``--map`` or the mission's ``map:`` key), the pre-flight check of every waypoint
against that map. Exit 0 when there is nothing to report, 2 otherwise.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from navseq.commands.common import parse_pose


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


def run(args: argparse.Namespace) -> int:
    from navseq.commands.common import costmap_for_map, preflight_errors, require_file
    from navseq.errors import MissionErrors
    from navseq.mission import load_mission, validate_mission_file

    if args.map is not None:
        require_file(args.map, "--map")
    problems = validate_mission_file(args.mission)
    if problems:
        raise MissionErrors(problems)
    mission = load_mission(args.mission)
    map_path = args.map if args.map is not None else mission.map
    start = args.start if args.start is not None else mission.start
    if map_path is not None:
        problems = preflight_errors(mission, costmap_for_map(map_path), start)
        if problems:
            raise MissionErrors(problems)
    count = len(mission.waypoints)
    loops = "forever" if mission.loops is None else str(mission.loops)
    checked = f"checked against map {map_path}" if map_path is not None else "no map to check"
    print(f"{args.mission}: OK — {count} waypoint{'s' if count != 1 else ''}, "
          f"loops {loops}, {checked}", file=sys.stdout)
    return 0
