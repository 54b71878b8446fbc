"""A fleet run on ROS navigation stacks: one namespaced stack per robot, one process.

``navseq run --fleet FLEET --navigator nav2`` (or ``ros1``): the fleet is planned and
checked as for the embedded simulator (:mod:`navseq.fleet.planning`), then every
robot's stack is connected in the robot's namespace (the fleet file's ``namespace:``,
else its name) before anything moves or is written — a namespace no server answers in
is said with every other robot's problem at once. Each robot's share runs as a
one-robot run (its executor, journal and report) in a thread of its own, on its own
navigator, put in a :class:`~navseq.fleet.coordinator.CoordinatedNavigator`; one
:class:`~navseq.fleet.coordinator.FleetCoordinator` watches them all and gives way
among them. The run folder is the embedded fleet run's: a folder per robot, the fleet
report and picture, ``fleet-run.json`` (with the navigator kind, for ``--resume``).

The kinds are a registry (:data:`STACK_KINDS`): a kind's module has
``connect(settings, namespace) -> (navigator, report info)``; this module imports no
ROS itself.
"""

from __future__ import annotations

import contextlib
import importlib
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError, error_text

if TYPE_CHECKING:
    from navseq.fleet.coordinator import CoordinatedNavigator, FleetCoordinator
    from navseq.fleet.journals import RobotJournal
    from navseq.fleet.model import FleetRobot
    from navseq.fleet.planning import FleetPlan
    from navseq.fleet.run import FleetRun, FleetRunRequest, Member
    from navseq.geometry import Pose2D
    from navseq.navigators.settings import NavigatorSettings

#: The navigator kinds a fleet runs on, one namespaced stack per robot: kind -> module
#: with ``connect(settings, namespace)``.
STACK_KINDS = {"nav2": "navseq.ros2.fleet_member", "ros1": "navseq.ros1.fleet_member"}
POSE_WAIT = 5.0  # wall s for every robot's pose before the run starts
START_GAP = 0.5  # m between a robot's pose and its fleet start pose worth a note


@dataclass
class Connected:
    """A robot's stack, connected: its navigator (for the coordinator) and report info."""

    robot: FleetRobot
    navigator: CoordinatedNavigator
    info: dict[str, Any]


def kind_name(settings: NavigatorSettings) -> str:
    """The kind of ``settings`` (``nav2``, ``ros1``)."""
    from navseq.navigators.registry import kind_of

    return kind_of(settings).name


def connect_all(plan: FleetPlan, settings: NavigatorSettings) -> list[Connected]:
    """Every robot's stack connected in its namespace; NavseqError with every robot's
    problem at once (the ones connected are closed again), before anything moves."""
    from navseq.fleet.checks import raise_all
    from navseq.fleet.coordinator import CoordinatedNavigator
    from navseq.navigators.registry import navigator_kind

    kind = navigator_kind(kind_name(settings))
    try:
        module: Any = importlib.import_module(STACK_KINDS[kind.name])
    except ImportError as error:
        raise NavseqError(
            f"the {kind.name} navigator needs {kind.requires}: {error}",
            source=f"--navigator {kind.name}",
        ) from None
    connected: list[Connected] = []
    problems: list[NavseqError] = []
    for robot in plan.fleet.robots:
        try:
            navigator, info = module.connect(settings, robot.namespace)
        except NavseqError as error:
            problems.append(
                NavseqError(
                    f"namespace '{robot.namespace}' (the fleet file's namespace:, else the "
                    f"robot's name): {error_text(error)}",
                    source=f"robot '{robot.name}'",
                )
            )
            continue
        info["robot"] = robot.profile.name
        info["fleet_robot"] = robot.name
        connected.append(Connected(robot, CoordinatedNavigator(navigator, robot.name), info))
    if problems:
        close_all(connected)
    raise_all(problems)
    return connected


def close_all(connected: list[Connected]) -> None:
    """Close every robot's stack connection (each cancels its goal first)."""
    for item in connected:
        with contextlib.suppress(Exception):  # the others are closed all the same
            item.navigator.inner.close()


def robot_poses(connected: list[Connected], wait: float = POSE_WAIT) -> dict[str, Pose2D]:
    """Where each robot's stack says it is, waited for up to ``wait`` wall seconds."""
    poses: dict[str, Pose2D] = {}
    deadline = time.monotonic() + wait
    while True:
        for item in connected:
            if item.robot.name not in poses:
                pose = item.navigator.robot_pose()
                if pose is not None:
                    poses[item.robot.name] = pose
        if len(poses) == len(connected) or time.monotonic() >= deadline:
            return poses
        time.sleep(0.05)


def start_notes(connected: list[Connected], poses: dict[str, Pose2D]) -> list[str]:
    """A robot not where the fleet file starts it (the split was planned from there)."""
    notes = []
    for item in connected:
        pose, start = poses.get(item.robot.name), item.robot.start
        if pose is None:
            notes.append(
                f"{item.robot.name}: no pose from its stack within {POSE_WAIT:g} s; the "
                "coordinator waits for it before it gives way among the robots"
            )
        elif math.hypot(pose.x - start.x, pose.y - start.y) > START_GAP:
            notes.append(
                f"{item.robot.name}: at ({pose.x:.2f}, {pose.y:.2f}), "
                f"{math.hypot(pose.x - start.x, pose.y - start.y):.1f} m from its start in the "
                "fleet file, from which its share was planned"
            )
    return notes


def make_coordinator(plan: FleetPlan, connected: list[Connected]) -> FleetCoordinator:
    from navseq.fleet.coordinator import CoordinatedRobot, FleetCoordinator

    grid = plan.grid
    assert grid is not None
    return FleetCoordinator(
        grid, [CoordinatedRobot(c.robot.name, c.navigator, c.robot.profile) for c in connected]
    )


def prepare_stack_fleet_run(request: FleetRunRequest) -> FleetRun:
    """Plan, check, connect every robot's stack and make ready; raises NavseqError /
    MissionErrors (every problem at once) before anything moves or is written."""
    from navseq.fleet.manifest import manifest_of, write_manifest
    from navseq.fleet.planning import plan_fleet
    from navseq.fleet.recording import choose
    from navseq.fleet.run import FleetRun
    from navseq.run.folder import create_run_folder, default_run_folder

    assert request.navigator is not None and request.resume is None
    plan = plan_fleet(
        request.fleet,
        request.mission,
        map_path=request.map,
        time_limit_s=request.time_limit_s,
        need_map=True,
    )
    record = choose(
        request.record,
        request.record_format,
        plan.fleet.mission.record,
        topics=request.record_topics,
        kind=kind_name(request.navigator),
    )
    connected = connect_all(plan, request.navigator)
    try:
        poses = robot_poses(connected)
        notes = start_notes(connected, poses)
        coordinator = make_coordinator(plan, connected)
        fresh = request.folder is None
        made_here = fresh or not request.folder.exists()  # type: ignore[union-attr]
        folder = create_run_folder(
            request.folder or default_run_folder(request.fleet.stem), fresh=fresh
        )
        try:
            members = stack_members(plan, connected, poses, folder, None)
            manifest = manifest_of(request.fleet, request.mission, request.map, plan.split)
            manifest = manifest.with_navigator(kind_name(request.navigator))
            write_manifest(folder, manifest.with_recording(record))
        except BaseException:
            if made_here:
                import shutil

                shutil.rmtree(folder, ignore_errors=True)
            raise
    except BaseException:
        close_all(connected)
        raise
    run = FleetRun(plan, coordinator, coordinator, folder, members, picture=request.picture)
    run.coordinator = coordinator
    run.record = record
    run.on_close.append(lambda: close_all(connected))
    run.notes.extend(notes)
    return run


def stack_members(
    plan: FleetPlan,
    connected: list[Connected],
    poses: dict[str, Pose2D],
    folder: Path,
    journals: dict[str, RobotJournal] | None,
) -> list[Member]:
    """A session per robot with waypoints (``journals``: a resume's, each robot from its
    own); pre-flight problems of all robots at once."""
    from navseq.errors import MissionErrors
    from navseq.fleet.checks import raise_all
    from navseq.fleet.run import Member
    from navseq.mission import write_mission
    from navseq.run.folder import reserve_file
    from navseq.run.request import Outputs, RunRequest, UseNavigator
    from navseq.run.session import prepare

    by_name = {item.robot.name: item for item in connected}
    members: list[Member] = []
    problems: list[NavseqError] = []
    for share in plan.split.shares:
        robot = share.robot
        item = by_name[robot.name]
        navigator = item.navigator
        found = journals.get(robot.name) if journals is not None else None
        if (journals is not None and found is None) or not share.order:
            members.append(Member(robot, None, navigator, 0, state="idle"))
            continue
        if found is not None and found.done:
            from navseq.fleet.journals import done_member

            member = done_member(found, len(share.order))
            member.navigator = navigator
            members.append(member)
            continue
        own = folder / robot.name
        if found is None:
            own.mkdir(exist_ok=True)
            mission_path = reserve_file(own, "mission.yaml")
            mission = share.mission(plan.fleet)
            assert mission is not None
            write_mission(mission, mission_path, overwrite=True)  # ours, reserved just now
        else:
            mission_path = found.mission
        try:
            session = prepare(
                RunRequest(
                    mission=mission_path,
                    navigator=UseNavigator(navigator, item.info, grid=plan.grid),
                    start=poses.get(robot.name, robot.start),
                    # The fleet records its robots in one file (FleetRun.record).
                    outputs=Outputs(folder=own, picture=False, record=False),
                    resume=found.journal if found is not None else None,
                )
            )
        except MissionErrors as errors:
            problems.extend(
                NavseqError(error_text(error), source=f"robot '{robot.name}'")
                for error in errors.errors
            )
            continue
        except NavseqError as error:
            problems.append(NavseqError(error_text(error), source=f"robot '{robot.name}'"))
            continue
        member = Member(robot, session, navigator, len(share.order))
        if found is not None:
            from navseq.fleet.journals import earlier_counts, trail_of

            member.counts.update(earlier_counts(found))
            member.earlier_trail = trail_of(found.state)
        members.append(member)
    raise_all(problems)
    return members


__all__ = [
    "STACK_KINDS",
    "Connected",
    "close_all",
    "connect_all",
    "prepare_stack_fleet_run",
    "stack_members",
]
