"""``navseq plan MISSION [--map MAP] [--order shortest] [--out FILE]``: the mission's route.

Every leg planned on the robot's costmap (the planner the simulator drives with; the
studio draws the same legs), with its length beside the straight line and the time the
robot takes to drive it (:mod:`navseq.eta`: speeds, accelerations, turns, stops); the
route's total, and the mission's expected duration and upper bound. With ``--order shortest`` the
waypoints are put in the order the robot drives in least time, turns at the waypoints
included (:mod:`navseq.route.order`, :mod:`navseq.route.travel`; progress on stderr
when it is a terminal, Ctrl-C ends with exit 130 and nothing written) and
the route is shown in that order; ``--out FILE`` writes the mission so ordered (navseq
YAML, never over an existing file unless ``--force``).

Exit 0 when every leg has a path, 1 when some leg has none (``navseq validate --map``
says why), 2 for bad input.

``--fleet FLEET`` splits the mission among a fleet's robots instead
(:mod:`navseq.commands.plan_fleet`).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.commands.common import add_robot_option
from navseq.commands.filter_options import add_filter_options, filters_of

if TYPE_CHECKING:
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.route.legs import Legs

ORDERS = ("file", "shortest")
#: The ``--json`` output's version (docs/schemas/plan.schema.json).
SCHEMA_VERSION = 2


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "mission",
        type=Path,
        nargs="?",
        metavar="MISSION",
        help="mission file to plan (with --fleet: instead of the fleet file's mission:)",
    )
    parser.add_argument(
        "--fleet",
        type=Path,
        metavar="FLEET",
        help="split the mission among a fleet's robots (docs/fleet.md); --out names a "
        "folder for one mission per robot",
    )
    parser.add_argument(
        "--map",
        type=Path,
        metavar="MAP",
        help="map_server YAML to plan on (default: the mission's map:; without a map, "
        "legs are straight lines)",
    )
    add_robot_option(parser)
    add_filter_options(parser)
    parser.add_argument(
        "--order",
        choices=ORDERS,
        default="file",
        help="file: the waypoints as the file has them (default); shortest: the order that "
        "takes the least time, turns counted (waypoint 1, or the start pose, stays first; a "
        "patrol stays a closed tour)",
    )
    parser.add_argument(
        "--keep-last",
        action="store_true",
        help="with --order shortest: the file's last waypoint stays last (a dock to end at)",
    )
    parser.add_argument(
        "--time-limit",
        type=float,
        default=2.0,
        metavar="S",
        help="seconds the route solver may search for --order shortest (default 2)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        metavar="FILE",
        help="write the mission in the order shown (navseq YAML); with --fleet: a folder",
    )
    parser.add_argument("--force", action="store_true", help="replace FILE if it exists")
    parser.add_argument("--json", action="store_true", help="print the route as JSON")


def run(args: argparse.Namespace) -> int:
    from navseq.commands.common import choose_robot, legs_on_map, require_file
    from navseq.errors import NavseqError
    from navseq.mission import load_mission
    from navseq.route.legs import legs_of

    if args.fleet is not None:
        from navseq.commands import plan_fleet

        return plan_fleet.run(args)
    if args.mission is None:
        raise NavseqError(
            "name the mission file to plan (or a fleet with --fleet)", source="MISSION"
        )
    if args.keep_last and args.order != "shortest":
        raise NavseqError(
            "keeps a waypoint last in a new order: give --order shortest too", source="--keep-last"
        )
    if not (0.0 < args.time_limit <= 3600.0):
        raise NavseqError("must be more than 0 and at most 3600 seconds", source="--time-limit")
    if args.order == "shortest":
        from navseq.extras import require_extra

        require_extra("plan", "--order shortest")  # before any leg is planned
    if args.out is not None and args.out.exists() and not args.force:
        # Refused before any work: nothing the user wrote is replaced unasked.
        raise NavseqError(
            "exists already; not overwriting it (use --force to replace it)",
            source=str(args.out),
        )
    if args.map is not None:
        require_file(args.map, "--map")
    mission = load_mission(args.mission)
    given = filters_of(args)
    if given is not None:
        mission = dataclasses.replace(mission, filters=given)
    robot = choose_robot(args.robot, mission)
    map_path = args.map if args.map is not None else mission.map
    legs = legs_on_map(map_path, robot, filters=mission.filters)
    in_file_order = legs_of(mission, legs)
    order = list(range(len(mission.waypoints)))
    ordered = mission
    if args.order == "shortest":
        from navseq.commands.order_progress import order_progress
        from navseq.route.order import shortest_order

        with order_progress() as progress:  # on stderr, only when it is a terminal
            ordering = shortest_order(
                mission,
                legs,
                args.time_limit,
                keep_last=args.keep_last,
                robot=robot,
                progress=progress,
            )
        order, ordered = list(ordering.order), ordering.apply(mission)
    route = legs_of(ordered, legs) if ordered is not mission else in_file_order
    if args.out is not None:
        from navseq.mission import write_mission

        write_mission(ordered, args.out, overwrite=args.force)
    result = _result(mission, order, route, in_file_order, map_path, robot, args.out)
    result.update(_expected(ordered, route, result["legs"], legs, robot))
    prediction = result.pop("prediction")
    if args.json:
        from navseq.sinks.report import report_json

        print(report_json(result))
    else:
        from navseq.eta.text import prediction_lines

        _print(result, args, prediction_lines(prediction, has_start=ordered.start is not None))
    return 0 if result["every_leg_has_a_path"] else 1


def _result(
    mission: Mission,
    order: list[int],
    route: list[dict[str, Any]],
    in_file_order: list[dict[str, Any]],
    map_path: Path | None,
    robot: RobotProfile,
    out: Path | None,
) -> dict[str, Any]:
    """The route as ``--json`` prints it (docs/schemas/plan.schema.json)."""
    import math

    from navseq.route.legs import route_length

    waypoints = mission.waypoints
    legs = []
    for leg in route:
        goal = waypoints[order[leg["to"]]]
        start = mission.start if leg["from"] == "start" else waypoints[order[int(leg["from"])]]
        assert start is not None
        legs.append(
            {
                "from": "start" if leg["from"] == "start" else order[int(leg["from"])] + 1,
                "to": order[leg["to"]] + 1,
                "to_name": goal.name,
                "length_m": leg["length_m"],
                "straight_m": round(math.hypot(goal.x - start.x, goal.y - start.y), 3),
                "back_to_first": leg["loop"],
            }
        )
    total = route_length(route)
    return {
        "schema_version": SCHEMA_VERSION,
        "mission": str(mission.source),
        "map": _shown(map_path) if map_path is not None else None,
        "robot": robot.name,
        "order": [number + 1 for number in order],
        "legs": legs,
        "length_m": total,
        "length_in_file_order_m": route_length(in_file_order),
        "max_speed_m_s": robot.max_linear_speed,
        "duration_s": round(total / robot.max_linear_speed, 1)
        if total is not None and robot.max_linear_speed > 0
        else None,
        "every_leg_has_a_path": all(leg["length_m"] is not None for leg in route),
        "written": str(out) if out is not None else None,
    }


def _expected(
    mission: Mission,
    route: list[dict[str, Any]],
    shown: list[dict[str, Any]],
    legs: Legs,
    robot: RobotProfile,
) -> dict[str, Any]:
    """The mission's expected duration and upper bound (:mod:`navseq.eta.predict`); each
    leg of ``shown`` (the ``--json`` legs of ``route``) gets its driving time."""
    from navseq.eta.predict import predict_legs

    prediction = predict_legs(mission, legs, robot, mission.start)
    for leg, row in zip(route, shown, strict=True):
        visits = prediction.later_loop if leg["loop"] else prediction.first_loop
        driven = visits[leg["to"]].leg
        row["drive_s"] = round(driven.duration_s, 1) if driven is not None else None
    expected, upper = prediction.expected_s, prediction.upper_s
    return {
        "expected_duration_s": round(expected, 1) if expected is not None else None,
        "upper_bound_s": round(upper, 1) if upper is not None else None,
        "loop_duration_s": round(prediction.loop_expected_s, 1),
        "prediction": prediction,  # for the text; not in --json
    }


def _print(result: dict[str, Any], args: argparse.Namespace, durations: list[str]) -> None:
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    from navseq.sinks.summary import print_table
    from navseq.text import printable

    on = f"on {result['map']}" if result["map"] else "without a map: straight lines"
    console = Console()

    def say(text: str) -> None:
        # Plain text (a name may hold [brackets]); a pipe gets whole lines.
        console.print(text, markup=False, highlight=False, soft_wrap=True)

    say(f"{printable(result['mission'])} {printable(on)}, robot {result['robot']}")
    table = Table()
    for header, justify in (
        ("leg", "left"),
        ("to", "left"),
        ("planned [m]", "right"),
        ("straight [m]", "right"),
        ("driving [s]", "right"),
    ):
        table.add_column(escape(header), justify=justify)  # type: ignore[arg-type]
    for leg in result["legs"]:
        length = leg["length_m"]
        back = " (back to the first)" if leg["back_to_first"] else ""
        table.add_row(
            f"{leg['from']} → {leg['to']}{back}",
            escape(printable(leg["to_name"] or "")),
            "no path" if length is None else f"{length:.2f}",
            f"{leg['straight_m']:.2f}",
            "" if leg.get("drive_s") is None else f"~{leg['drive_s']:.0f}",
        )
    print_table(table, console)
    count = len(result["order"])
    if result["length_m"] is None:
        say(
            f"route: {count} waypoints; some legs have no path "
            f"(navseq validate {printable(str(args.mission))} --map ... says why)"
        )
    else:
        say(f"route: {count} waypoints, {result['length_m']:.2f} m")
    for line in durations:
        say(line)
    if args.order == "shortest":
        before, after = result["length_in_file_order_m"], result["length_m"]
        shown = " ".join(str(number) for number in result["order"])
        if result["order"] == sorted(result["order"]):
            say("shortest order: the file's order already is")
        elif before is not None and after is not None and before > 0:
            say(
                f"shortest order: {shown} — {after:.2f} m instead of {before:.2f} m "
                f"({(after - before) / before:+.1%})"
            )
        else:
            say(f"shortest order: {shown}")
    if result["written"]:
        say(f"wrote {printable(result['written'])}")
    elif args.order == "shortest" and result["order"] != sorted(result["order"]):
        print("navseq plan: give --out FILE to write the mission in this order", file=sys.stderr)


def _shown(path: Path) -> str:
    """``path`` relative to the working folder when it is below it (as the user typed it)."""
    import os

    relative = os.path.relpath(path)
    return str(path) if relative.startswith("..") else relative
