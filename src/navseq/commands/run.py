"""``navseq run MISSION``: drive a robot (simulated by default) through a mission.

The command is two phases. :func:`prepare` reads and checks everything the user
gave (mission, map, start pose, journal to resume) and runs the pre-flight check;
any problem is a :class:`~navseq.errors.NavseqError` (exit 2) raised before the
robot moves and before anything is written. :func:`execute` then runs the mission
with the journal, the progress display and the recorder listening, and writes the
report and the picture even when the run is interrupted.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.commands.common import format_pose, parse_loops, parse_pose
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile

if TYPE_CHECKING:
    from navseq.executor.result import MissionResult
    from navseq.executor.resume import ResumePoint
    from navseq.geometry import Pose2D
    from navseq.mission.model import Mission
    from navseq.navigators.base import Navigator
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid
    from navseq.sinks.journal import JournalState
    from navseq.sinks.progress import JsonProgress
    from navseq.sinks.recorder import RunRecorder

NAVIGATORS = ("sim", "ros1")
TEST_NAVIGATORS = ("scripted",)  # a deterministic stand-in, for tests of the plumbing


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "mission",
        type=Path,
        nargs="?",
        metavar="MISSION",
        help="mission file (navseq YAML, launch, rosparam YAML, CSV); "
        "optional with --resume (taken from the journal)",
    )
    parser.add_argument(
        "--navigator",
        choices=NAVIGATORS + TEST_NAVIGATORS,
        default="sim",
        metavar="{sim,ros1}",
        help="sim: the embedded simulator (default); ros1: move_base over actionlib",
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
        help="continue the run recorded in this journal.jsonl (reached waypoints are not re-run)",
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
    ros1 = parser.add_argument_group("ros1 navigator")
    ros1.add_argument(
        "--action", default="move_base", help="MoveBaseAction server name (default: move_base)"
    )
    ros1.add_argument("--frame", help="goal frame (default: the mission's frame:, usually map)")
    ros1.add_argument("--ns", default="", help="robot namespace, e.g. robot1 (default: none)")
    # Options of the scripted test navigator, hidden from --help.
    parser.add_argument("--scripted-speed", type=float, default=0.5, help=argparse.SUPPRESS)
    parser.add_argument("--scripted-realtime", type=float, default=None, help=argparse.SUPPRESS)
    parser.add_argument("--scripted-log", type=Path, default=None, help=argparse.SUPPRESS)
    parser.add_argument("--scripted-script", default="", help=argparse.SUPPRESS)


@dataclass
class RunSetup:
    """Everything checked and ready: what to run, on what, and where to write."""

    mission: Mission
    mission_path: Path
    digest: str
    make_navigator: Callable[[], Navigator]
    navigator_info: dict[str, Any]
    start: Pose2D | None = None
    start_source: str | None = None  # where ``start`` came from: "--start", "mission start:"
    robot: RobotProfile = DEFAULT_PROFILE  # goal tolerance of the arrival check, ...
    grid: OccupancyGrid | None = None
    map_path: Path | None = None
    resume: ResumePoint | None = None
    journal: Path | None = None  # the journal to append to when resuming
    history: JournalState | None = None  # what that journal held before resuming
    notes: list[str] = field(default_factory=list)


def _read_resume(
    journal: Path, mission_arg: Path | None
) -> tuple[Path, ResumePoint, JournalState]:
    """The mission file, resume point and contents of a journal (mission unchanged)."""
    from navseq.commands.common import require_file
    from navseq.errors import NavseqError
    from navseq.sinks.journal import mission_digest, read_journal, resume_point

    require_file(journal, "--resume")
    state = read_journal(journal)
    mission_path = mission_arg if mission_arg is not None else Path(state.mission_source)
    if not mission_path.exists():
        raise NavseqError(
            f"the journal's mission file {mission_path} does not exist any more; "
            "give the mission file as MISSION",
            source=str(journal),
        )
    # resume_point refuses a mission whose digest differs from the journal's.
    point = resume_point(state, mission_digest=mission_digest(mission_path))
    return mission_path, point, state


def _map_info(grid: OccupancyGrid, map_path: Path) -> dict[str, Any]:
    return {
        "source": str(map_path),
        "resolution": grid.resolution,
        "width": grid.width,
        "height": grid.height,
        "origin": [grid.origin.x, grid.origin.y, grid.origin.yaw],
    }


def _check_against_map(mission: Mission, costmap: Costmap, start: Pose2D | None) -> None:
    """Pre-flight: every problem of the mission on this map, raised together."""
    from navseq.commands.common import preflight_errors
    from navseq.errors import MissionErrors

    problems = preflight_errors(mission, costmap, start)
    if problems:
        raise MissionErrors(problems)


def _optional_map(args: argparse.Namespace, setup: dict[str, Any]) -> OccupancyGrid | None:
    """The map, if one is known, with the mission checked against it."""
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import load_map

    if setup["map_path"] is None:
        return None
    grid = load_map(setup["map_path"])
    if not args.no_preflight:
        _check_against_map(setup["mission"], Costmap.from_grid(grid), setup["start"])
    return grid


def prepare(args: argparse.Namespace) -> RunSetup:
    """Load and check the user's input; raise NavseqError on any problem."""
    from navseq.commands.common import require_file
    from navseq.errors import NavseqError
    from navseq.mission import load_mission
    from navseq.sinks.journal import mission_digest

    resume = history = None
    if args.resume is not None:
        mission_path, resume, history = _read_resume(args.resume, args.mission)
    elif args.mission is None:
        raise NavseqError("give a MISSION file (or --resume JOURNAL)", source="navseq run")
    else:
        mission_path = args.mission
        require_file(mission_path, "MISSION")
    if args.map is not None:
        require_file(args.map, "--map")
    mission = load_mission(mission_path)
    if "loops" in vars(args):  # given on the command line (None = forever)
        mission = dataclasses.replace(mission, loops=args.loops)
    map_path = args.map if args.map is not None else mission.map
    start = args.start if args.start is not None else mission.start
    start_source = (
        "--start" if args.start is not None else "mission start:" if start is not None else None
    )
    setup_kwargs: dict[str, Any] = {
        "mission": mission,
        "mission_path": mission_path,
        "digest": mission_digest(mission_path),
        "resume": resume,
        "journal": args.resume,
        "history": history,
        "map_path": map_path,
        "start": start,
        "start_source": start_source,
    }
    if args.navigator == "sim":
        return _prepare_sim(args, setup_kwargs)
    if args.navigator == "ros1":
        return _prepare_ros1(args, setup_kwargs)
    return _prepare_scripted(args, setup_kwargs)


def _prepare_sim(args: argparse.Namespace, setup: dict[str, Any]) -> RunSetup:
    from navseq.errors import NavseqError
    from navseq.navigators.sim import SimNavigator
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import load_map
    from navseq.sim.world import SimWorld, default_start

    mission: Mission = setup["mission"]
    map_path: Path | None = setup["map_path"]
    start: Pose2D | None = setup["start"]
    if map_path is None:
        raise NavseqError(
            "the simulator needs a map: give --map MAP.yaml or a map: key in the mission",
            source=mission.source,
        )
    grid = load_map(map_path)
    notes = []
    if start is None:
        start = default_start(grid)
        setup["start"] = start
        setup["start_source"] = "simulator default"
        notes.append(
            f"no start pose given (--start or start:): the robot starts at "
            f"{format_pose(start)}, the roomy point nearest the map origin"
        )
    # One costmap for pre-flight and the simulated navigation server alike.
    costmap = Costmap.from_grid(grid)
    # Pre-flight first: it lists every problem, where building the world would stop at
    # the first (a start pose inside an obstacle).
    if not args.no_preflight:
        _check_against_map(mission, costmap, start)
    world = SimWorld(grid, start, costmap=costmap)
    return RunSetup(
        **setup,
        grid=grid,
        make_navigator=lambda: SimNavigator(world),
        navigator_info={"kind": "sim", "robot": "turtlebot3_burger"},
        notes=notes,
    )


def _prepare_ros1(args: argparse.Namespace, setup: dict[str, Any]) -> RunSetup:
    mission: Mission = setup["mission"]
    frame = args.frame or mission.frame
    grid = _optional_map(args, setup)

    def make_navigator() -> Navigator:
        from navseq.errors import NavseqError

        try:
            from navseq.navigators.ros1 import Ros1Navigator
        except ImportError as error:
            raise NavseqError(
                f"the ros1 navigator needs ROS 1's Python packages (rospy, actionlib, "
                f"move_base_msgs): {error}. Install them (see DEVELOPERS.md) and run navseq "
                "from the project's venv",
                source="--navigator ros1",
            ) from None
        return Ros1Navigator(args.action, frame, namespace=args.ns)

    return RunSetup(
        **setup,
        grid=grid,
        make_navigator=make_navigator,
        navigator_info={"kind": "ros1", "action": args.action, "frame": frame, "ns": args.ns},
    )


def _scripted_behaviours(script: str) -> list[Any]:
    """Test-only: ``succeed,aborted@2,stall@1,hang,falsesuccess`` -> ScriptedNavigator
    behaviours."""
    from navseq.navigators.base import GoalStatus
    from navseq.navigators.scripted import FalseSuccess, Finish, Hang, Stall, Succeed

    behaviours: list[Any] = []
    for token in filter(None, (part.strip() for part in script.split(","))):
        name, _, after = token.partition("@")
        seconds = float(after) if after else 0.0
        if name == "succeed":
            behaviours.append(Succeed())
        elif name == "hang":
            behaviours.append(Hang())
        elif name == "stall":
            behaviours.append(Stall(after=seconds))
        elif name == "falsesuccess":
            behaviours.append(FalseSuccess(after=seconds))
        else:
            behaviours.append(Finish(GoalStatus(name.upper()), after=seconds))
    return behaviours


def _prepare_scripted(args: argparse.Namespace, setup: dict[str, Any]) -> RunSetup:
    from navseq.navigators.scripted import ScriptedNavigator

    start: Pose2D | None = setup["start"]
    grid = _optional_map(args, setup)

    def make_navigator() -> Navigator:
        return ScriptedNavigator(
            _scripted_behaviours(args.scripted_script),
            start=start,
            speed=args.scripted_speed,
            realtime=args.scripted_realtime,
            log_path=args.scripted_log,
        )

    return RunSetup(
        **setup,
        grid=grid,
        make_navigator=make_navigator,
        navigator_info={"kind": "scripted", "speed": args.scripted_speed},
    )


@dataclass
class RunOutcome:
    """How a run ended, with the sinks that watched it."""

    result: MissionResult
    exit_code: int
    interrupted: str | None  # signal name
    navigator: Navigator
    recorder: RunRecorder
    json_lines: JsonProgress | None


def _output_folder(setup: RunSetup, args: argparse.Namespace) -> tuple[Path, bool]:
    """The folder to write into, and whether this run created it."""
    from navseq.commands.output import create_run_folder, default_run_folder

    if args.out is not None:
        existed = args.out.exists()
        return create_run_folder(args.out, fresh=False), not existed
    if setup.journal is not None:  # a resumed run writes beside its journal
        return create_run_folder(setup.journal.parent, fresh=False), False
    return create_run_folder(default_run_folder(setup.mission_path.stem), fresh=True), True


def _discard_unused(journal: Path, folder: Path | None) -> None:
    """Remove a journal that holds only its header (and the folder, if ours and empty)."""
    try:
        if journal.exists() and len(journal.read_bytes().splitlines()) <= 1:
            journal.unlink()
        if folder is not None and not any(folder.iterdir()):
            folder.rmdir()
    except OSError:
        pass  # tidying up only; the original error matters more


def new_recorder(setup: RunSetup) -> RunRecorder:
    """The run's recorder; a resumed run's starts with what its journal recorded.

    So the picture of a resumed run shows the whole mission: the path driven and the
    legs planned before the resume too, in one mission-time colouring.
    """
    from navseq.sinks.recorder import RunRecorder

    if setup.history is None:
        return RunRecorder()
    return RunRecorder.from_journal(setup.history.events)


def _run_with_sinks(setup: RunSetup, args: argparse.Namespace, journal_path: Path) -> RunOutcome:
    from navseq.executor.runner import MissionInterrupted, run_mission
    from navseq.sinks.journal import JournalWriter
    from navseq.sinks.progress import JsonProgress, make_progress

    navigator = setup.make_navigator()
    try:
        if setup.resume is not None:
            journal = JournalWriter.resume(journal_path, setup.resume)
        else:
            # The absolute path, so that --resume works from any directory.
            source = str(setup.mission_path.resolve())
            journal = JournalWriter(journal_path, source, setup.digest)
        recorder = new_recorder(setup)
        progress = make_progress(setup.mission, json_lines=args.json)
        with progress, journal:
            try:
                result = run_mission(
                    setup.mission,
                    navigator,
                    [journal, recorder, progress],
                    resume=setup.resume,
                    robot=setup.robot,
                )
                exit_code, interrupted = result.exit_code, None
            except MissionInterrupted as stop:
                result, exit_code, interrupted = stop.result, stop.exit_code, stop.signal_name
    finally:
        navigator.close()
    json_lines = progress if isinstance(progress, JsonProgress) else None
    return RunOutcome(result, exit_code, interrupted, navigator, recorder, json_lines)


def execute(setup: RunSetup, args: argparse.Namespace) -> int:
    """Run the mission with every sink attached; write report and picture; exit status."""
    from navseq.commands.output import reserve_file

    folder, created = _output_folder(setup, args)
    # Resuming appends to the run's own journal; a new run starts a new one.
    journal_path = setup.journal or reserve_file(folder, "journal.jsonl")
    for note in setup.notes:
        print(f"navseq run: {note}", file=sys.stderr)
    try:
        outcome = _run_with_sinks(setup, args, journal_path)
    except BaseException:
        # No result to report (e.g. no navigation server): leave no empty files behind.
        if setup.journal is None:
            _discard_unused(journal_path, folder if created else None)
        raise
    # Reserved only now, so that a run killed with -9 leaves no empty report behind.
    files = {
        "journal": str(journal_path),
        "report": str(reserve_file(folder, "report.json")),
        "picture": str(reserve_file(folder, "mission.png")),
    }
    _write_outputs(setup, outcome, files)
    _print_end(setup, outcome, files)
    return outcome.exit_code


def _print_end(setup: RunSetup, outcome: RunOutcome, files: dict[str, str]) -> None:
    from rich.console import Console

    from navseq.sinks.progress import summary_table

    result = outcome.result
    if outcome.json_lines is not None:
        outcome.json_lines.emit(
            "RunFinished",
            {"success": result.success, "reason": result.reason,
             "exit_code": outcome.exit_code, "interrupted": outcome.interrupted, **files},
        )
        return
    console = Console()
    console.print(summary_table(setup.mission, result))
    for role, path in files.items():
        console.print(f"{role:>8}: {path}", highlight=False)


def _write_outputs(setup: RunSetup, outcome: RunOutcome, files: dict[str, str]) -> None:
    from navseq.sinks.picture import draw_mission_picture
    from navseq.sinks.report import build_report, write_report

    result = outcome.result
    report = build_report(
        setup.mission,
        result,
        exit_code=outcome.exit_code,
        navigator=setup.navigator_info,
        interrupted=outcome.interrupted,
        mission_digest=setup.digest,
        map_info=_map_info(setup.grid, setup.map_path)
        if setup.grid is not None and setup.map_path is not None
        else None,
        start=setup.start,
        start_source=setup.start_source,
        files=files,
    )
    write_report(report, Path(files["report"]))
    trajectory = picture_trajectory(outcome)
    draw_mission_picture(
        Path(files["picture"]),
        setup.mission,
        result,
        grid=setup.grid,
        # Where the robot really set out from (the planned start if it never said; a
        # resumed run's picture shows the whole mission, so its planned start too).
        start=setup.start
        if setup.resume is not None and setup.start is not None
        else result.start_pose or setup.start,
        plans=outcome.recorder.leg_plans(),
        trajectory=trajectory,
        interrupted=outcome.interrupted,
    )


def picture_trajectory(outcome: RunOutcome) -> list[tuple[float, float, float]]:
    """The driven path to draw, (mission time, x, y), NaN rows between run segments.

    The simulator records every step of this run; other navigators give only what
    their feedback showed (the recorder's progress events). Either way the segments
    before a resume come from the journal, through the recorder.
    """
    recorder = outcome.recorder
    stepped = getattr(outcome.navigator, "trajectory", None)
    if not stepped:
        return recorder.trajectory()
    now = [(recorder.mission_time(t), x, y) for t, x, y in stepped]
    return [*recorder.earlier_trajectory(), *now]


def run(args: argparse.Namespace) -> int:
    setup = prepare(args)
    return execute(setup, args)

