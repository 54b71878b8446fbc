"""``navseq run --fleet FLEET``: a fleet's robots together on the embedded simulator.

The fleet is planned and checked (every problem at once, exit 2, nothing moved), its
robots run in one process on one clock (:mod:`navseq.fleet.run`), a live table shows
each robot's current waypoint and state, and the run folder gets one folder per robot
(its mission, journal and report) plus the fleet's report and picture. Exit 0 when
every robot reached all its waypoints, 1 otherwise, 130/143 when interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from rich.table import Table

    from navseq.fleet.run import FleetRun, Member
    from navseq.navigators.settings import NavigatorSettings
    from navseq.sinks.json_events import JsonProgress

#: Options of a one-robot run that a fleet run takes from the fleet file, or lacks yet.
_FLEET_REFUSES = {
    "start": ("--start", "each robot's start: comes from the fleet file"),
    "robot": ("--robot", "each robot's model (robot:) comes from the fleet file"),
    "from_waypoint": ("--from", "the fleet's split chooses each robot's waypoints"),
    "to_waypoint": ("--to", "the fleet's split chooses each robot's waypoints"),
    "only": ("--only", "the fleet's split chooses each robot's waypoints"),
}


#: Options of a kind that the fleet file settles for every robot.
_STACK_REFUSES = {
    "ns": ("--ns", "each robot's namespace comes from the fleet file (namespace:, else its name)"),
    "from_ll": ("--from-ll", "a fleet's waypoints are converted with the mission's datum"),
    "map_wait": ("--map-wait", "a fleet runs on its map file (map:), not on a stack's map"),
}


def refuse_options(args: argparse.Namespace) -> None:
    """What a fleet run cannot honour, refused before anything is read."""
    from navseq.fleet.stack_run import STACK_KINDS

    navigator = getattr(args, "navigator", None)
    if navigator not in (None, "sim", *STACK_KINDS):
        raise NavseqError(
            f"runs on the embedded simulator or on ROS stacks ({', '.join(STACK_KINDS)}), "
            f"not on --navigator {navigator}",
            source="--fleet",
        )
    if navigator in STACK_KINDS:
        for dest, (flag, why) in _STACK_REFUSES.items():
            if getattr(args, dest, None) is not None:
                raise NavseqError(f"{why}; leave {flag} out with --fleet", source=flag)
        if getattr(args, "realtime", None) is not None:
            raise NavseqError(
                f"paces the embedded simulator; --navigator {navigator} keeps its own time. "
                "Leave --realtime out",
                source="--realtime",
            )
    for dest, (flag, why) in _FLEET_REFUSES.items():
        if getattr(args, dest, None) not in (None, False, ()):
            raise NavseqError(f"{why}; leave {flag} out with --fleet", source=flag)
    if getattr(args, "resume", None) is not None and getattr(args, "out", None) is not None:
        raise NavseqError(
            "a resumed fleet run writes into its own run folder (--resume RUN_DIR); "
            "leave --out out",
            source="--out",
        )
    if hasattr(args, "loops"):
        raise NavseqError(
            "a fleet runs each robot's share once; leave --loops out", source="--loops"
        )


def run(args: argparse.Namespace) -> int:
    from navseq.fleet.resume import prepare_fleet_resume
    from navseq.fleet.run import FleetRunRequest, prepare_fleet_run
    from navseq.fleet.stack_run import prepare_stack_fleet_run

    refuse_options(args)
    from navseq.extras import require_extra

    require_extra("plan", "--fleet")
    request = FleetRunRequest(
        fleet=args.fleet,
        mission=args.mission,
        map=args.map,
        folder=args.out,
        realtime=args.realtime,
        picture=not args.no_picture,
        resume=_run_folder(args.resume),
        navigator=_stack_settings(args),
        record=args.record,
        record_format=args.record_format,
        record_topics=args.record_topics,
    )
    lock = None
    if request.resume is not None and request.resume.is_dir():
        from navseq.run.runlock import RunLock

        # One resume of a fleet run at a time: two would both drive (and report) it.
        lock = RunLock(request.resume).acquire()
    try:
        # A resume continues the run's own split, each robot from its journal.
        prepared = (
            prepare_fleet_resume
            if request.resume is not None
            else prepare_stack_fleet_run
            if request.navigator is not None
            else prepare_fleet_run
        )
        fleet_run = prepared(request)
        for note in fleet_run.notes:
            print(f"navseq run: {note}", file=sys.stderr)
        for member in fleet_run.members:
            if member.session is not None:
                for note in member.session.notes:
                    print(f"navseq run: {member.robot.name}: {note}", file=sys.stderr)
        json_lines = _json_lines(fleet_run) if args.json else None
        status, report = _execute(
            fleet_run, getattr(args, "exits_after_command", False), json_lines
        )
    finally:
        if lock is not None:
            lock.release()
    if json_lines is not None:
        _json_finished(fleet_run, json_lines)
    _print_summary(fleet_run, report, json_lines is not None)
    return status


def _stack_settings(args: argparse.Namespace) -> NavigatorSettings | None:
    """``--navigator nav2|ros1`` and its options as the kind's settings (None: the
    embedded simulator)."""
    from navseq.fleet.stack_run import STACK_KINDS
    from navseq.navigators.registry import command_line_options, navigator_kind, settings_from

    name = getattr(args, "navigator", None)
    if name not in STACK_KINDS:
        return None
    given = {
        option.name: getattr(args, option.name)
        for option in command_line_options()
        if getattr(args, option.name, None) is not None
    }
    return settings_from(navigator_kind(name), given)


def _run_folder(given: Path | None) -> Path | None:
    """``--resume``'s fleet run folder (its ``fleet-run.json`` named is taken as it)."""
    from navseq.fleet.manifest import MANIFEST_NAME

    if given is not None and given.name == MANIFEST_NAME and given.is_file():
        return given.parent
    return given


def _json_lines(fleet_run: FleetRun) -> dict[str, JsonProgress]:
    """``--json``: each robot at work prints its events as ``navseq run --json`` does, each
    record naming the robot, whole lines at a time on the one stdout."""
    import threading

    from navseq.commands.run_outputs import StdoutGuard
    from navseq.sinks.json_events import JsonProgress

    lock = threading.Lock()
    printers = {}
    for member in fleet_run.members:
        if member.session is None:
            continue
        printer = JsonProgress(
            sys.stdout,
            member.session.numbers,
            member.session.eta(),
            robot=member.robot.name,
            lock=lock,
        )
        member.listeners.append(StdoutGuard(printer))
        printers[member.robot.name] = printer
    return printers


def _json_finished(fleet_run: FleetRun, printers: dict[str, JsonProgress]) -> None:
    """Each robot's last record, ``RunFinished``, as a one-robot run ends its lines."""
    from navseq.commands.run_outputs import silence_stdout

    for member in fleet_run.members:
        outcome, printer = member.outcome, printers.get(member.robot.name)
        if outcome is None or printer is None:
            continue  # its error is said on stderr
        try:
            printer.run_finished(
                success=outcome.result.success,
                reason=outcome.result.reason,
                exit_code=outcome.exit_status,
                interrupted=outcome.interrupted,
                files=outcome.files.paths if outcome.files is not None else {},
                clock=outcome.clock,
            )
        except BrokenPipeError:
            silence_stdout()
            return


def _execute(
    fleet_run: FleetRun, exits_after: bool, json_lines: dict[str, JsonProgress] | None = None
) -> tuple[int, dict[str, Any]]:
    """Run the robots with a live table (none with ``--json``); Ctrl-C / SIGTERM / SIGHUP
    stop them all (also where the shell started navseq with SIGINT ignored), then the
    outputs are written and later signals are only counted."""
    from rich.console import Console
    from rich.live import Live

    from navseq.signals import SignalGuard, Terminated

    guard = SignalGuard().arm()
    threads = fleet_run.start()
    console = Console(stderr=True)
    interrupted: str | None = None
    try:
        live = Live(_table(fleet_run), console=console, auto_refresh=False, transient=True)
        with live if json_lines is None else contextlib.nullcontext():
            while any(thread.is_alive() for thread in threads):
                fleet_run.clock.stepped.wait(0.2)
                fleet_run.clock.stepped.clear()
                if json_lines is None:
                    live.update(_table(fleet_run), refresh=True)
    except (KeyboardInterrupt, Terminated) as stop:
        interrupted = stop.signal_name if isinstance(stop, Terminated) else "SIGINT"
    finally:
        guard.defer()
        if interrupted is not None or any(thread.is_alive() for thread in threads):
            fleet_run.stop(interrupted or "an error")
        for thread in threads:
            thread.join()
    errors = [m for m in fleet_run.members if m.error is not None]
    try:
        status, report = fleet_run.finish()
    finally:
        if not exits_after:
            guard.restore()
    for member in errors:
        print(f"navseq run: {member.robot.name}: {member.error}", file=sys.stderr)
    stopped = report.get("coordinator", {}).get("error")
    if stopped:  # the runs went on without it: the report says what happened
        print(f"navseq run: the fleet coordinator stopped: {stopped}", file=sys.stderr)
    return status, report


def _table(fleet_run: FleetRun) -> Table:
    from rich.markup import escape
    from rich.table import Table

    from navseq.text import printable

    totals = {
        key: sum(m.counts[key] for m in fleet_run.members) for key in fleet_run.members[0].counts
    }
    table = Table(
        title=f"fleet at t = {fleet_run.world.now:.0f} s: {totals['reached']} reached, "
        f"{totals['skipped']} skipped, {totals['failed']} failed{_fleet_eta(fleet_run)}",
        title_justify="left",
    )
    for header in ("robot", "waypoint", "state", "reached", "skipped", "failed", "of"):
        table.add_column(header)
    for member in fleet_run.members:
        counts = member.counts
        table.add_row(
            escape(member.robot.name),
            escape(printable(member.current)),
            escape(_state(member)),
            str(counts["reached"]),
            str(counts["skipped"]),
            str(counts["failed"]),
            str(member.waypoints),
        )
    return table


def _state(member: Member) -> str:
    """The member's state, and what the fleet coordinator does with it (ROS stacks)."""
    mode = getattr(member.navigator, "mode", "free")
    shown = {"held": "held back", "aside": "giving way"}
    return member.state if mode not in shown else f"{member.state}, {shown[mode]}"


def _fleet_eta(fleet_run: FleetRun) -> str:
    """``, done in ~40 s``: the latest of the running robots' ETAs (each its run's own)."""
    left = []
    for member in fleet_run.members:
        if member.state in ("done", "ended", "error"):
            continue
        estimator = member.eta
        if estimator is not None and estimator.eta_s is not None:
            left.append(estimator.eta_s)
    return f", done in ~{max(left):.0f} s" if left else ""


def _print_summary(fleet_run: FleetRun, report: dict[str, Any], json_lines: bool) -> None:
    """The robots' table and the fleet's line on stdout; with ``--json``, where stdout is
    for programs, only the fleet's lines, on stderr."""
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    from navseq.commands.plan_fleet import shown_path
    from navseq.sinks.summary import print_table

    console = Console(stderr=json_lines)
    table = Table()
    for header, justify in (
        ("robot", "left"),
        ("reached", "right"),
        ("skipped", "right"),
        ("failed", "right"),
        ("of", "right"),
        ("time [s]", "right"),
        ("driven [m]", "right"),
    ):
        table.add_column(escape(header), justify=justify)  # type: ignore[arg-type]
    for row in report["robots"]:
        table.add_row(
            escape(row["name"]),
            str(row["reached"]),
            str(row["skipped"]),
            str(row["failed"]),
            str(row["waypoints"]),
            "" if row["mission_time_s"] is None else f"{row['mission_time_s']:.0f}",
            "" if row["distance_m"] is None else f"{row['distance_m']:.1f}",
        )
    if not json_lines:
        print_table(table, console)
    console.print(
        f"fleet: {report['reached']} reached, {report['skipped']} skipped, "
        f"{report['failed']} failed; makespan {report['makespan_s']:.0f} s "
        f"(planned {report['planned_makespan_s']:.0f} s)",
        markup=False,
        highlight=False,
        soft_wrap=True,
    )
    console.print(
        f"wrote {shown_path(str(fleet_run.folder))}/ (fleet-report.json, fleet.png, "
        "a folder per robot)",
        markup=False,
        highlight=False,
        soft_wrap=True,
    )


__all__ = ["refuse_options", "run"]
