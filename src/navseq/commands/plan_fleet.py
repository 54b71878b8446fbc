"""``navseq plan --fleet FLEET [MISSION] --out DIR``: split a mission among robots.

The fleet file (docs/fleet.md) is read and checked against the map, every problem at
once (exit 2, nothing written); the waypoints are split so that the last robot
finishes soonest (:mod:`navseq.fleet.split`), one mission per robot is written to
``DIR/<robot>.yaml`` (all refused before any is written if one exists, unless
``--force``) and a table says, per robot, its waypoints, distance and time.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from navseq.fleet.planning import FleetPlan


def refuse_single_robot_options(args: argparse.Namespace) -> None:
    """Options of a one-robot plan that mean nothing for a fleet."""
    for flag, given in (
        ("--order", args.order != "file"),
        ("--keep-last", args.keep_last),
        ("--robot", args.robot is not None),
    ):
        if given:
            raise NavseqError(
                "is for one robot's plan; a fleet's robots, their models and their order "
                "come from the fleet file",
                source=flag,
            )


def run(args: argparse.Namespace) -> int:
    """``navseq plan --fleet``; returns the exit status."""
    from navseq.extras import require_extra
    from navseq.fleet.planning import plan_fleet

    refuse_single_robot_options(args)
    if not (0.0 < args.time_limit <= 3600.0):
        raise NavseqError("must be more than 0 and at most 3600 seconds", source="--time-limit")
    require_extra("plan", "--fleet")
    out: Path | None = args.out
    if out is not None and out.exists() and not out.is_dir():
        raise NavseqError("is a file; with --fleet, --out names a folder", source=str(out))
    plan = plan_fleet(args.fleet, args.mission, map_path=args.map, time_limit_s=args.time_limit)
    written: list[Path] = []
    if out is not None:
        written = write_missions(plan, out, force=args.force)
    result = fleet_result(plan, written)
    if args.json:
        from navseq.sinks.report import report_json

        print(report_json(result))
    else:
        print_summary(result)
    return 0 if not plan.split.dropped else 1


def write_missions(plan: FleetPlan, folder: Path, *, force: bool) -> list[Path]:
    """One mission per robot with waypoints, ``folder/<robot>.yaml``: every target is
    checked before the first is written, so a refusal leaves nothing half done."""
    from navseq.mission import write_mission

    missions = [
        (folder / f"{share.robot.name}.yaml", share.mission(plan.fleet))
        for share in plan.split.shares
    ]
    if not force:
        existing = [path for path, mission in missions if mission is not None and path.exists()]
        if existing:
            from navseq.fleet.checks import raise_all

            raise_all(
                [
                    NavseqError("exists already; not overwriting it (use --force)", source=str(p))
                    for p in existing
                ]
            )
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for path, mission in missions:
        if mission is not None:
            write_mission(mission, path, overwrite=force)
            written.append(path)
    return written


def fleet_result(plan: FleetPlan, written: list[Path]) -> dict[str, Any]:
    """The split as ``--json`` prints it."""
    fleet, split = plan.fleet, plan.split
    mission = fleet.mission
    files = {path.stem: str(path) for path in written}
    return {
        "fleet": fleet.source,
        "mission": shown_path(str(mission.source)),
        "map": shown_path(str(fleet.map)) if fleet.map is not None else None,
        "robots": [
            {
                "name": share.robot.name,
                "namespace": share.robot.namespace,
                "robot": share.robot.profile.name,
                "waypoints": [mission.number(i) for i in share.order],
                "distance_m": share.distance_m,
                "time_s": round(share.time_s, 1),
                "max_time_s": share.robot.max_time_s,
                "mission_file": shown_path(files[share.robot.name])
                if share.robot.name in files
                else None,
            }
            for share in split.shares
        ],
        "makespan_s": round(split.makespan_s, 1),
        "left_out": [mission.number(i) for i in split.dropped],
    }


def print_summary(result: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    from navseq.sinks.summary import print_table
    from navseq.text import printable

    console = Console()

    def say(text: str) -> None:
        console.print(text, markup=False, highlight=False, soft_wrap=True)

    on = f"on {result['map']}" if result["map"] else "without a map: straight lines"
    say(f"{printable(result['fleet'])}: {printable(result['mission'])} {printable(on)}")
    table = Table()
    for header, justify in (
        ("robot", "left"),
        ("model", "left"),
        ("waypoints", "right"),
        ("order", "left"),
        ("distance [m]", "right"),
        ("time [s]", "right"),
        ("mission", "left"),
    ):
        table.add_column(escape(header), justify=justify)  # type: ignore[arg-type]
    for row in result["robots"]:
        table.add_row(
            escape(row["name"]),
            escape(printable(row["robot"])),
            str(len(row["waypoints"])),
            _order_text(row["waypoints"]),
            f"{row['distance_m']:.1f}",
            f"{row['time_s']:.0f}",
            escape(printable(row["mission_file"] or ("idle" if not row["waypoints"] else "-"))),
        )
    print_table(table, console)
    say(f"fleet makespan: {result['makespan_s']:.0f} s (the last robot's time at top speed)")
    if result["left_out"]:
        shown = ", ".join(str(n) for n in result["left_out"])
        say(f"left out (no robot can take them within its max_time): waypoints {shown}")


def _order_text(numbers: list[int], limit: int = 40) -> str:
    """The waypoints' numbers in the robot's order, cut short on a long share."""
    text = " ".join(str(number) for number in numbers)
    return text if len(text) <= limit else text[: limit - 1].rsplit(" ", 1)[0] + " …"


def shown_path(path: str) -> str:
    """``path`` relative to the working folder when it is below it (as a user types it)."""
    import os

    relative = os.path.relpath(path)
    return path if relative.startswith("..") else relative


__all__ = ["fleet_result", "print_summary", "run", "write_missions"]
