"""``navseq run MISSION``: drive a robot (simulated by default) through a mission.

The command line is parsed into a :class:`~navseq.run.request.RunRequest`
(:func:`request_of`); the run service prepares it (any problem is a
:class:`~navseq.errors.NavseqError`, exit 2, before the robot moves and before anything
is written) and runs it with the progress display listening, in the main thread with
the process's signal handling. What is left here is the terminal: the notes on stderr,
the summary table or the JSON lines, and the exit status.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.commands.common import (
    add_robot_option,
    parse_loops,
    parse_pose,
    parse_realtime,
    parse_waypoint_number,
)
from navseq.commands.filter_options import add_filter_options, filters_of
from navseq.commands.task_options import add_task_options, task_options_of
from navseq.errors import NavseqError
from navseq.navigators import registry
from navseq.navigators.registry import command_line_options, navigator_kind, settings_from
from navseq.run.request import Loops, Outputs, RunRequest
from navseq.run.session import prepare
from navseq.sinks.recording.encoding import FORMATS
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.journal.writer import JournalState
    from navseq.run.outcome import RunOutcome
    from navseq.run.session import Session
    from navseq.signals import SignalGuard
    from navseq.sinks.progress import ProgressSink


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "mission",
        type=Path,
        nargs="?",
        metavar="MISSION",
        help="mission file (navseq YAML, launch, rosparam YAML, CSV); "
        "optional with --resume (taken from the journal)",
    )
    add_navigator_choice(parser, default=None)  # None: sim, or the journal's when resuming
    parser.add_argument(
        "--fleet",
        type=Path,
        metavar="FLEET",
        help="run a fleet's robots together: on the embedded simulator, or with "
        "--navigator nav2|ros1 on one namespaced stack per robot (docs/fleet.md); "
        "MISSION, if given, replaces the fleet file's mission:",
    )
    parser.add_argument(
        "--map", type=Path, metavar="MAP", help="map_server YAML (default: the mission's map:)"
    )
    parser.add_argument(
        "--start",
        type=parse_pose,
        metavar="X,Y,YAW",
        help="simulated robot's start pose, metres, metres, degrees "
        "(default: the mission's start:)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="output folder (default: navseq-out/<mission>-<YYYYmmdd-HHMMSS>)",
    )
    parser.add_argument(
        "--json", action="store_true", help="print one JSON object per event instead of progress"
    )
    parser.add_argument(
        "--resume",
        type=Path,
        metavar="JOURNAL",
        help="continue the run recorded in this journal.jsonl (reached waypoints are not re-run); "
        "with --fleet, the fleet run folder to continue",
    )
    parser.add_argument(
        "--no-preflight",
        action="store_true",
        help="skip checking the waypoints against the map before the robot moves",
    )
    parser.add_argument(
        "--loops",
        type=parse_loops,
        default=argparse.SUPPRESS,  # absent unless given: None already means "forever"
        metavar="N|forever",
        help="run the waypoint list N times, or until interrupted (default: the mission's loops:)",
    )
    parser.add_argument(
        "--from",
        dest="from_waypoint",
        type=parse_waypoint_number,
        metavar="N",
        help="start at waypoint N (1-based, as numbered in the summary table)",
    )
    parser.add_argument(
        "--to",
        dest="to_waypoint",
        type=parse_waypoint_number,
        metavar="N",
        help="end at waypoint N, inclusive (1-based, as numbered in the summary table)",
    )
    parser.add_argument(
        "--only",
        metavar="NAME_OR_NUMBER,...",
        help="run only these waypoints, in the mission's order (names or 1-based numbers)",
    )
    parser.add_argument(
        "--realtime",
        type=parse_realtime,
        nargs="?",
        const=1.0,
        metavar="FACTOR",
        help="pace the simulator at FACTOR times real time (1 when no FACTOR is given), to "
        "watch it or drive RViz; without it the simulator runs as fast as it can",
    )
    parser.add_argument(
        "--no-picture",
        action="store_true",
        default=None,  # None: not given (a resume takes the journal's)
        help="do not draw mission.png",
    )
    parser.add_argument(
        "--record",
        action="store_true",
        default=None,  # None: not given (the mission's record:, or a resume's journal)
        help="record the run as run.mcap in the output folder (map, pose, odometry, /tf, "
        "plans, goals, waypoint markers, events) for Foxglove and ros2 bag; "
        "needs pip install 'navseq[record]'",
    )
    parser.add_argument(
        "--record-format",
        choices=FORMATS,
        default=None,
        help="the recording's message encoding: ros2 (CDR, the default) or ros1",
    )
    parser.add_argument(
        "--record-topics",
        type=parse_topics,
        default=(),
        metavar="TOPIC[,TOPIC...]",
        help="with --record and --navigator ros1 or nav2: also record these topics as the stack "
        "publishes them (any type, e.g. /scan); a topic navseq records itself (/map, /odom, "
        "/tf, /plan ...) is then the stack's own",
    )
    add_task_options(parser)
    add_robot_option(parser)
    add_filter_options(parser)
    # Each navigator kind's options (navseq.navigators.registry), the test double's hidden.
    add_navigator_options(parser)


def parse_topics(text: str) -> tuple[str, ...]:
    """``/scan,/amcl_pose``: the topic names, in order, each once."""
    topics = [topic.strip() for topic in text.split(",") if topic.strip()]
    if not topics or any(any(ch.isspace() for ch in topic) for topic in topics):
        raise argparse.ArgumentTypeError(f"expected topic names separated by commas: {text!r}")
    return tuple(dict.fromkeys(topics))


def add_navigator_choice(parser: argparse.ArgumentParser, default: str | None) -> None:
    """``--navigator``: the visible kinds in ``--help``, hidden ones accepted too."""
    visible = [kind for kind in registry.NAVIGATORS if not kind.hidden]
    parser.add_argument(
        "--navigator",
        choices=[kind.name for kind in registry.NAVIGATORS],
        default=default,
        metavar="{" + ",".join(kind.name for kind in visible) + "}",
        help="; ".join(f"{kind.name}: {kind.help}" for kind in visible),
    )


def add_navigator_options(parser: argparse.ArgumentParser) -> None:
    """Every kind's settings as options, each once, grouped by the kinds that use it.

    An option shared by several kinds (``--frame``: ros1 and nav2) is listed once, in the
    group of those kinds. Every option defaults to None on the parser, so that a resume
    can tell an option given again from one left out; the kind's defaults apply once
    the kind is known (:func:`navseq.navigators.settings.with_defaults`).
    """
    groups: dict[tuple[str, ...], argparse._ArgumentGroup] = {}
    for option in command_line_options():
        info = option.declared.info
        kwargs: dict[str, Any] = {
            "dest": option.name,
            "default": None,
            "help": argparse.SUPPRESS if option.hidden else info.help,
        }
        if info.parse is not None:  # its ValueError: argparse's "invalid float value"
            kwargs["type"] = info.parse
        if info.metavar is not None:
            kwargs["metavar"] = info.metavar
        if option.hidden:
            parser.add_argument(info.flag, **kwargs)
            continue
        visible = tuple(name for name in option.kinds if not navigator_kind(name).hidden)
        group = groups.get(visible)
        if group is None:
            title = _kinds_title(visible)
            group = groups[visible] = parser.add_argument_group(title)
        group.add_argument(info.flag, **kwargs)


def _kinds_title(kinds: tuple[str, ...]) -> str:
    """``ros1 navigator``, ``ros1 and nav2 navigators``, ``sim, ros1 and nav2 navigators``."""
    if len(kinds) == 1:
        return f"{kinds[0]} navigator"
    return f"{', '.join(kinds[:-1])} and {kinds[-1]} navigators"


def request_of(args: argparse.Namespace) -> RunRequest:
    """The run the command line asks for."""
    if args.mission is None and args.resume is None:
        raise NavseqError(
            "no mission given: name the mission file to run (navseq run MISSION), "
            "or the journal of a run to continue (--resume JOURNAL)"
        )
    given = {
        option.name: getattr(args, option.name)
        for option in command_line_options()
        if getattr(args, option.name, None) is not None
    }
    navigator = None
    if args.navigator is not None:
        navigator = settings_from(navigator_kind(args.navigator), given)
    loops: Loops | None = None
    if "loops" in vars(args):  # given on the command line (None = forever)
        loops = "forever" if args.loops is None else int(args.loops)
    return RunRequest(
        mission=args.mission,
        navigator=navigator,
        navigator_options={} if navigator is not None else given,
        map=args.map,
        start=args.start,
        robot=args.robot,
        loops=loops,
        first=args.from_waypoint,
        last=args.to_waypoint,
        only=args.only,
        preflight=not args.no_preflight,
        outputs=Outputs(
            folder=args.out,
            picture=None if args.no_picture is None else not args.no_picture,
            record=args.record,
            record_format=args.record_format,
            record_topics=args.record_topics,
        ),
        resume=args.resume,
        realtime=args.realtime,
        tasks=task_options_of(args),
        filters=filters_of(args),
    )


def real_time_text(clock: Mapping[str, float | None]) -> str:
    """``simulated 62.4 s in 0.9 s: 69x real time``: how fast the simulator ran.

    ``clock`` is :func:`~navseq.sinks.json_events.clock_record`'s, as the report says it.
    """
    simulated, wall, factor = clock["navigator_s"], clock["wall_s"], clock["real_time_factor"]
    assert simulated is not None and wall is not None
    if factor is None:
        return f"simulated {simulated:.1f} s"
    shown = f"{factor:.0f}" if factor >= 10 else f"{factor:.2g}"
    # A short mission simulates in hundredths of a second: "in 0.0 s" would say nothing.
    wall_shown = f"{wall:.1f}" if wall >= 1 else f"{wall:.3f}"
    return f"simulated {simulated:.1f} s in {wall_shown} s: {shown}x real time"


def _say(note: str) -> None:
    print(f"navseq run: {printable(note)}", file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    from navseq.journal.writer import NothingToResume
    from navseq.signals import SignalGuard

    if args.fleet is not None:
        from navseq.commands import run_fleet

        return run_fleet.run(args)
    try:
        session = prepare(request_of(args))
    except NothingToResume as finished:
        # A finished run: all a resume can still do is finish its outputs.
        code = _rebuild_finished(args.resume, finished.state)
        if code is None:
            raise
        return code
    signals = SignalGuard()
    try:
        return _execute(session, args, signals)
    finally:
        if not getattr(args, "exits_after_command", False):
            # In the navseq process itself the guard goes on counting signals until
            # the exit: the status the report states is the one the process returns.
            signals.restore()
        if len(signals.received) > 1:  # the first one is the interruption itself
            print(
                f"navseq run: {', '.join(signals.received)} received; the robot was stopped "
                "and the outputs were finished first",
                file=sys.stderr,
            )


def _execute(session: Session, args: argparse.Namespace, signals: SignalGuard) -> int:
    """Run the session with the progress display; show how it ended; its exit status."""
    from navseq.commands.run_outputs import StdoutGuard
    from navseq.sinks.progress import make_progress

    progress = make_progress(
        session.mission,
        json_lines=args.json,
        robot=session.robot,
        numbers=session.numbers,
        eta=session.eta(),
    )
    outcome = session.run([StdoutGuard(progress)], signals=signals, on_note=_say)
    return _show(session, outcome, progress)


def _show(session: Session, outcome: RunOutcome, progress: ProgressSink) -> int:
    from navseq.commands.run_outputs import print_summary, report_failures, silence_stdout
    from navseq.run.files import RunFiles
    from navseq.sinks.json_events import JsonProgress

    files = outcome.files if outcome.files is not None else RunFiles()
    notes = []
    if session.navigator_info.get("kind") == "sim":
        notes.append(real_time_text(outcome.clock))
    if isinstance(progress, JsonProgress):
        try:
            progress.run_finished(
                success=outcome.result.success,
                reason=outcome.result.reason,
                exit_code=outcome.exit_status,
                interrupted=outcome.interrupted,
                files=files.paths,
                clock=outcome.clock,
            )
        except BrokenPipeError:
            silence_stdout()
        for note in notes:  # stdout is for programs here
            _say(note)
    else:
        print_summary(
            session.mission,
            outcome.result,
            files,
            numbers=session.numbers,
            part=session.part.describe() if session.part is not None else None,
            notes=notes,
        )
    if outcome.error is None or outcome.stopped_by is not None:
        report_failures(files)  # else the closing message says it all, once
    if outcome.error is not None:
        raise outcome.error
    return outcome.exit_status


def _rebuild_finished(journal: Path, state: JournalState | None) -> int | None:
    """Rebuild a finished run's missing report/picture; its exit status, or None if complete."""
    from navseq.commands.report import rebuild_outputs
    from navseq.run.runlock import RunLock

    with RunLock(journal.parent):
        rebuilt = rebuild_outputs(journal, state)
    if not rebuilt.written:
        return None
    for role, path in rebuilt.written.items():
        print(
            f"navseq run: nothing left to run; rebuilt the {role}: {printable(path)}",
            file=sys.stderr,
        )
    return 1 if rebuilt.exit_code is None else rebuilt.exit_code
