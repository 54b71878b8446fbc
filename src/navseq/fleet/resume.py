"""``navseq run --fleet FLEET --resume RUN_DIR``: a fleet run continued where it stopped.

The run folder's ``fleet-run.json`` (:mod:`navseq.fleet.manifest`) names the fleet file
the run started with (refused if another or changed one is given) and keeps its split:
every robot goes on with its own share, from its own journal, by the one-robot resume
rules (:mod:`navseq.run.resume`: the active waypoint again, reached and skipped ones
not; a changed mission file or a damaged journal refused). A robot whose share was
complete stays done, parked where its journal last saw it; the others start from
there too. Every robot's problem is said at once (exit 2) before anything moves or is
written; the fleet report and picture then cover both parts of the run.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from navseq.errors import NavseqError, error_text
from navseq.fleet.journals import (
    RobotJournal,
    done_member,
    earlier_counts,
    robot_journal,
    trail_of,
)

if TYPE_CHECKING:
    from navseq.fleet.lockstep import FleetClock
    from navseq.fleet.manifest import FleetManifest
    from navseq.fleet.model import Fleet
    from navseq.fleet.planning import FleetPlan
    from navseq.fleet.run import FleetRun, FleetRunRequest, Member
    from navseq.navigators.settings import NavigatorSettings
    from navseq.sim.fleet_world import FleetWorld


def prepare_fleet_resume(request: FleetRunRequest) -> FleetRun:
    """The fleet run in ``request.resume`` made ready to go on; raises NavseqError /
    MissionErrors (every robot's problem at once) before anything moves."""
    from navseq.fleet.checks import raise_all
    from navseq.fleet.lockstep import FleetClock
    from navseq.fleet.manifest import read_manifest
    from navseq.fleet.planning import FleetPlan
    from navseq.fleet.recording import choose
    from navseq.fleet.run import FleetRun
    from navseq.sim.fleet_world import FleetRobot as SimRobot
    from navseq.sim.fleet_world import FleetWorld
    from navseq.sim.occupancy import load_map

    assert request.resume is not None
    folder = request.resume
    manifest = read_manifest(folder)
    if manifest.navigator == "sim" and request.navigator is not None:
        raise NavseqError(
            f"the run in {folder} ran on the embedded simulator; a resume goes on there: "
            "leave --navigator out",
            source="--navigator",
        )
    fleet = _same_fleet(request, manifest)
    if fleet.map is None:
        raise NavseqError("the simulator needs a map: give --map MAP.yaml", source=str(folder))
    grid = load_map(fleet.map)
    split = manifest.split(fleet)
    plan = FleetPlan(fleet, grid, None, split)
    problems: list[NavseqError] = []
    journals: dict[str, RobotJournal] = {}
    for share in split.shares:
        if share.order:
            try:
                journals[share.robot.name] = robot_journal(folder, share.robot)
            except NavseqError as error:
                problems.append(
                    NavseqError(error_text(error), source=f"robot '{share.robot.name}'")
                )
    raise_all(problems)
    # A recorded run goes on recording, into a new file beside the first (fleet-2.mcap).
    record = choose(request.record, request.record_format, fleet.mission.record, manifest.recording)
    if manifest.navigator != "sim":
        run = _resume_on_stacks(request, manifest.navigator, plan, journals)
        run.record = record
        return run
    poses = {name: found.pose for name, found in journals.items()}
    world = FleetWorld(
        grid,
        [SimRobot(r.name, poses.get(r.name, r.start), r.profile) for r in fleet.robots],
    )
    going_on = [name for name, found in journals.items() if not found.done]
    clock = FleetClock(world, going_on, realtime=request.realtime)
    members = _members(plan, world, clock, folder, journals)
    run = FleetRun(plan, world, clock, folder, members, picture=request.picture)
    run.record = record
    return run


def _same_kind(request: FleetRunRequest, kind: str) -> NavigatorSettings:
    """The settings to resume a run on ``kind``'s stacks with: the ones given (of that
    kind), else the kind's defaults."""
    from navseq.navigators.registry import kind_of, navigator_kind

    given = request.navigator
    if given is None:
        settings: NavigatorSettings = navigator_kind(kind).settings()
        return settings
    if kind_of(given).name != kind:
        raise NavseqError(
            f"the run in {request.resume} ran on --navigator {kind}; a resume goes on with "
            f"it: give --navigator {kind} (or leave --navigator out)",
            source="--navigator",
        )
    return given


def _resume_on_stacks(
    request: FleetRunRequest, kind: str, plan: FleetPlan, journals: dict[str, RobotJournal]
) -> FleetRun:
    """A fleet run on ROS stacks continued: every stack connected again, each robot
    from its journal (it is where its stack says, not where the journal last saw it)."""
    from navseq.fleet.run import FleetRun
    from navseq.fleet.stack_run import (
        close_all,
        connect_all,
        make_coordinator,
        robot_poses,
        stack_members,
    )

    assert request.resume is not None
    settings = _same_kind(request, kind)
    connected = connect_all(plan, settings)
    try:
        poses = robot_poses(connected)
        coordinator = make_coordinator(plan, connected)
        members = stack_members(plan, connected, poses, request.resume, journals)
    except BaseException:
        close_all(connected)
        raise
    run = FleetRun(plan, coordinator, coordinator, request.resume, members, picture=request.picture)
    run.coordinator = coordinator
    run.on_close.append(lambda: close_all(connected))
    return run


def _same_fleet(request: FleetRunRequest, manifest: FleetManifest) -> Fleet:
    """The fleet file the run started with (its digest), read with the run's mission and map."""
    import dataclasses

    from navseq.files import require_file
    from navseq.fleet.fleet_format import inspect_fleet
    from navseq.fleet.manifest import file_digest

    require_file(request.fleet, "FLEET")
    if file_digest(request.fleet) != manifest.fleet_sha256:
        raise NavseqError(
            f"is not the fleet file the run in {request.resume} started with "
            f"({manifest.fleet}, unchanged); a resume continues that run's split: give that "
            "file as it was, or start a new run without --resume",
            source=str(request.fleet),
        )
    mission = request.mission or manifest.mission
    if mission is not None and manifest.mission is not None and _differ(mission, manifest.mission):
        raise NavseqError(
            f"the run started with the mission {manifest.mission}; leave MISSION out with "
            "--resume, or give that file",
            source=str(mission),
        )
    if mission is not None:
        require_file(mission, "MISSION")
    fleet, problems = inspect_fleet(request.fleet, mission)
    problems.raise_if_any()
    assert fleet is not None
    map_path = request.map or manifest.map
    if map_path is not None:
        require_file(map_path, "--map")
        fleet = dataclasses.replace(fleet, map=map_path)
    missing = sorted(set(manifest.shares) ^ set(fleet.robot_names()))
    if missing:  # only a hand-edited fleet-run.json gets here: the digest matched
        raise NavseqError(
            f"the run's robots and the fleet file's differ ({', '.join(missing)})",
            source=str(request.fleet),
        )
    return fleet


def _differ(given: Path, recorded: Path) -> bool:
    try:
        return given.resolve() != recorded.resolve()
    except OSError:
        return True


def _members(
    plan: FleetPlan,
    world: FleetWorld,
    clock: FleetClock,
    folder: Path,
    journals: dict[str, RobotJournal],
) -> list[Member]:
    """A resumed session per robot still at work; done and idle robots as they were."""
    from navseq.errors import MissionErrors
    from navseq.fleet.checks import raise_all
    from navseq.fleet.lockstep import MemberNavigator
    from navseq.fleet.run import Member
    from navseq.run.request import Outputs, RunRequest, UseNavigator
    from navseq.run.session import prepare

    members: list[Member] = []
    problems: list[NavseqError] = []
    for share in plan.split.shares:
        robot = share.robot
        found = journals.get(robot.name)
        if found is None:
            members.append(Member(robot, None, None, 0, state="idle"))
            continue
        if found.done:
            members.append(done_member(found, len(share.order)))
            continue
        navigator = MemberNavigator(world, robot.name, clock)
        try:
            session = prepare(
                RunRequest(
                    mission=found.mission,
                    navigator=UseNavigator(
                        navigator,
                        {"kind": "sim", "robot": robot.profile.name, "fleet_robot": robot.name},
                        grid=plan.grid,
                    ),
                    start=found.pose,
                    # The fleet records its robots in one file (FleetRun.record).
                    outputs=Outputs(folder=found.journal.parent, picture=False, record=False),
                    resume=found.journal,
                )
            )
        except MissionErrors as errors:  # pre-flight's, each said with the robot's name
            problems.extend(
                NavseqError(error_text(error), source=f"robot '{robot.name}'")
                for error in errors.errors
            )
            continue
        except NavseqError as error:
            problems.append(NavseqError(error_text(error), source=f"robot '{robot.name}'"))
            continue
        member = Member(robot, session, navigator, len(share.order))
        member.counts.update(earlier_counts(found))
        member.earlier_trail = trail_of(found.state)
        members.append(member)
    raise_all(problems)
    return members


__all__ = ["prepare_fleet_resume"]
