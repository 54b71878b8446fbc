"""A fleet run on the embedded simulator: all robots in one process, on one clock.

:func:`prepare_fleet_run` plans the fleet (:mod:`navseq.fleet.planning`: the checks and
the split, every problem at once, nothing moved), builds one
:class:`~navseq.sim.fleet_world.FleetWorld` (robots see and give way to each other),
writes each robot's share as ``RUN/<robot>/mission.yaml`` and prepares one
:class:`~navseq.run.session.Session` per robot on it (pre-flight on the map, journal,
report: exactly a one-robot run's). :meth:`FleetRun.run` runs the sessions in one
thread each, kept in lockstep by :class:`~navseq.fleet.lockstep.FleetClock`, and writes
the fleet's report (``fleet-report.json``) and picture (``fleet.png``: every robot's
trail in its own colour) into ``RUN/``.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError, error_text
from navseq.fleet.model import FleetRobot

if TYPE_CHECKING:
    from navseq.eta.live import EtaEstimator
    from navseq.executor.control import MissionControl
    from navseq.executor.events import MissionEvent
    from navseq.executor.result import WaypointResult
    from navseq.fleet.coordinator import CoordinatedNavigator, FleetCoordinator
    from navseq.fleet.lockstep import FleetClock, MemberNavigator
    from navseq.fleet.planning import FleetPlan
    from navseq.fleet.recording import FleetRecording, FleetRecordingChoice
    from navseq.navigators.settings import NavigatorSettings
    from navseq.run.outcome import RunOutcome
    from navseq.run.session import Session
    from navseq.sim.fleet_world import FleetWorld


@dataclass(frozen=True)
class FleetRunRequest:
    """A fleet run as a face asks for it (``navseq run --fleet``)."""

    fleet: Path
    mission: Path | None = None  # None: the fleet file's mission:
    map: Path | None = None  # None: the fleet file's, else the mission's
    folder: Path | None = None  # None: navseq-out/<fleet>-<time>/
    realtime: float | None = None
    time_limit_s: float = 2.0  # for the split
    picture: bool = True
    resume: Path | None = None  # a fleet run folder to continue (navseq.fleet.resume)
    # None: the embedded simulator; a ROS kind's settings (nav2, ros1): one namespaced
    # stack per robot (navseq.fleet.stack_run), their namespaces from the fleet file.
    navigator: NavigatorSettings | None = None
    # One MCAP for the fleet (navseq.fleet.recording); None: as the mission's record:
    # says (a resume: also as the run it continues did).
    record: bool | None = None
    record_format: str | None = None  # ros2 (the default) or ros1
    # On ROS stacks: each robot's stack's own topics to record, under its namespace.
    record_topics: tuple[str, ...] = ()


@dataclass(frozen=True)
class FinishedShare:
    """A robot whose share a resumed run found complete: its figures from its journal."""

    time_s: float
    distance_m: float
    all_reached: bool
    folder: Path
    visits: tuple[WaypointResult, ...]


@dataclass
class Member:
    """One robot of the run: its share, its session, and how it is doing (for a display)."""

    robot: FleetRobot
    session: Session | None  # None: no waypoint fell to it; it stays parked
    navigator: MemberNavigator | CoordinatedNavigator | None
    waypoints: int
    current: str = ""
    state: str = "waiting"
    counts: dict[str, int] = field(
        default_factory=lambda: {"reached": 0, "skipped": 0, "failed": 0}
    )
    time_s: float = 0.0
    outcome: RunOutcome | None = None
    error: BaseException | None = None
    control: MissionControl = field(default_factory=lambda: _control())
    # The run's ETA, taken on the robot's own thread once its run has made it (a display
    # asking the session first would make a second one that hears no event).
    eta: EtaEstimator | None = None
    # A resumed run's: the share an earlier run completed, and the path driven before.
    finished: FinishedShare | None = None
    earlier_trail: list[tuple[float, float, float]] = field(default_factory=list)
    # More mission listeners for the robot's run (the studio's live view), beside hear;
    # added before the run starts, called on the robot's own thread.
    listeners: list[Callable[[MissionEvent], None]] = field(default_factory=list)

    def hear(self, event: MissionEvent) -> None:
        """A mission listener: the member's state as a live display shows it."""
        from navseq.executor.events import (
            MissionFinished,
            WaypointDwelling,
            WaypointFinished,
            WaypointStarted,
        )

        self.time_s = max(self.time_s, getattr(event, "t", 0.0))
        if self.eta is None and self.session is not None:
            self.eta = self.session.eta()
        mission = self.session.mission if self.session is not None else None
        if isinstance(event, WaypointStarted) and mission is not None:
            self.current = mission.waypoint_label(event.index)
            self.state = "driving" if event.attempt == 1 else f"retry {event.attempt - 1}"
        elif isinstance(event, WaypointDwelling):
            self.state = "dwelling"
        elif isinstance(event, WaypointFinished):
            outcome = event.outcome.value
            if outcome in self.counts:
                self.counts[outcome] += 1
            self.state = outcome
        elif isinstance(event, MissionFinished):
            self.state = "done" if event.success else "ended"
            self.current = ""


@dataclass
class FleetRun:
    """A fleet made ready: its plan, world, clock, folder and members.

    On ROS stacks the coordinator is both ``world`` (its ``now`` and ``collisions``) and
    ``clock`` (``stepped`` after each look, ``leave``)."""

    plan: FleetPlan
    world: FleetWorld | FleetCoordinator
    clock: FleetClock | FleetCoordinator
    folder: Path
    members: list[Member]
    picture: bool = True
    #: The signal that stopped the run (SIGINT, SIGTERM ...), None while it was not.
    stopped_by: str | None = field(default=None, init=False)
    #: On ROS stacks: who gives way among the robots (navseq.fleet.coordinator).
    coordinator: FleetCoordinator | None = field(default=None, init=False)
    #: Called once when the run is finished (the stacks' connections closed).
    on_close: list[Callable[[], None]] = field(default_factory=list, init=False)
    #: One line each for stderr, said before the robots move.
    notes: list[str] = field(default_factory=list, init=False)
    #: Whether (and how) the run is recorded as one MCAP (``--record``).
    record: FleetRecordingChoice | None = field(default=None, init=False)
    #: The fleet's MCAP recording, made when the run starts if it is recorded.
    recording: FleetRecording | None = field(default=None, init=False)

    def stop(self, signal_name: str) -> None:
        """End every robot's mission as an operator's cancel would (each cancels its goal,
        and its journal and report say so); the fleet's exit status then says
        ``signal_name``."""
        self.stopped_by = signal_name
        for member in self.members:
            member.control.submit("cancel", f"fleet run interrupted ({signal_name})")

    def start(self) -> list[threading.Thread]:
        """One thread per robot with waypoints, running its session; started."""
        if (
            self.record is not None
            and self.record.record
            and any(member.session is not None for member in self.members)
        ):  # (a resume of a finished run moves nothing: nothing to record)
            from navseq.fleet.recording import new_fleet_recording

            # The map and every robot's sink, before the robots move.
            self.recording = new_fleet_recording(self.folder, self.record)
            self.recording.start(self)
        threads = []
        for member in self.members:
            if member.session is None:
                continue
            thread = threading.Thread(
                target=self._run_member, args=(member,), name=f"fleet-{member.robot.name}"
            )
            thread.start()
            threads.append(thread)
        if self.coordinator is not None:
            running = [m.robot.name for m in self.members if m.session is not None]
            self.coordinator.start(running, threads)
        return threads

    def close(self) -> None:
        """Stop the coordinator and close the stacks' connections (once)."""
        if self.coordinator is not None:
            self.coordinator.close()
        closers, self.on_close = self.on_close, []
        for closer in closers:
            closer()

    def _run_member(self, member: Member) -> None:
        assert member.session is not None
        try:
            member.outcome = member.session.run(
                [member.hear, *member.listeners], control=member.control
            )
        except BaseException as error:  # reported by the face; the others go on
            member.error = error
            member.state = "error"
        finally:
            try:
                self.clock.leave(member.robot.name)
            except BaseException as error:  # the fleet's last step failed: said above
                member.error = member.error or error

    def finish(self) -> tuple[int, dict[str, Any]]:
        """The fleet's exit status and report, written with its picture into the folder."""
        from navseq.files import write_atomically
        from navseq.fleet.products import fleet_picture_png, fleet_report
        from navseq.sinks.report import report_json

        self.close()
        report = fleet_report(self)
        if self.coordinator is not None:
            report["coordinator"] = self.coordinator.summary()
        files: dict[str, str] = {}
        if self.recording is not None:
            self.recording.finish()  # every robot's run has ended: its summary now
            if self.recording.error is None:
                files["recording"] = str(self.recording.path)
            else:  # the robots went on without it; the report says why
                report["files_not_written"] = {"recording": self.recording.error}
        if self.picture:
            try:
                picture = self.folder / "fleet.png"
                write_atomically(picture, fleet_picture_png(self))
                files["picture"] = str(picture)
            except OSError as error:
                report["picture_error"] = str(error)
        report["files"] = files
        write_atomically(self.folder / "fleet-report.json", report_json(report))
        return report["exit_status"], report


def _control() -> MissionControl:
    from navseq.executor.control import MissionControl

    return MissionControl()


def prepare_fleet_run(request: FleetRunRequest) -> FleetRun:
    """Plan, check and make ready; raises NavseqError / MissionErrors (every problem at
    once) before anything moves. The run folder is made here, with its
    ``fleet-run.json`` (what :func:`navseq.fleet.resume.prepare_fleet_resume` needs)."""
    from navseq.fleet.lockstep import FleetClock
    from navseq.fleet.manifest import manifest_of, write_manifest
    from navseq.fleet.planning import plan_fleet
    from navseq.fleet.recording import choose
    from navseq.run.folder import create_run_folder, default_run_folder
    from navseq.sim.fleet_world import FleetRobot as SimRobot
    from navseq.sim.fleet_world import FleetWorld

    if request.resume is not None:
        raise ValueError("a resume is prepared by navseq.fleet.resume.prepare_fleet_resume")
    if request.navigator is not None:
        raise ValueError("a run on ROS stacks is prepared by navseq.fleet.stack_run")
    plan = plan_fleet(
        request.fleet,
        request.mission,
        map_path=request.map,
        time_limit_s=request.time_limit_s,
        need_map=True,
    )
    grid = plan.grid
    assert grid is not None  # need_map
    record = choose(
        request.record,
        request.record_format,
        plan.fleet.mission.record,
        topics=request.record_topics,
    )
    world = FleetWorld(grid, [SimRobot(r.name, r.start, r.profile) for r in plan.fleet.robots])
    with_work = [share.robot.name for share in plan.split.shares if share.order]
    clock = FleetClock(world, with_work, realtime=request.realtime)
    fresh = request.folder is None
    made_here = fresh or not request.folder.exists()  # type: ignore[union-attr]
    folder = create_run_folder(
        request.folder or default_run_folder(request.fleet.stem), fresh=fresh
    )
    try:
        members = _members(plan, world, clock, folder)
        manifest = manifest_of(request.fleet, request.mission, request.map, plan.split)
        write_manifest(folder, manifest.with_recording(record))
    except BaseException:
        if made_here:  # a refused run leaves nothing behind
            _remove_tree(folder)
        raise
    run = FleetRun(plan, world, clock, folder, members, picture=request.picture)
    run.record = record
    return run


def _members(plan: FleetPlan, world: FleetWorld, clock: FleetClock, folder: Path) -> list[Member]:
    """A session per robot with waypoints; pre-flight problems of all robots at once."""
    from navseq.fleet.checks import raise_all
    from navseq.fleet.lockstep import MemberNavigator
    from navseq.mission import write_mission
    from navseq.run.folder import reserve_file
    from navseq.run.request import Outputs, RunRequest, UseNavigator
    from navseq.run.session import prepare

    members: list[Member] = []
    problems: list[NavseqError] = []
    for share in plan.split.shares:
        robot = share.robot
        mission = share.mission(plan.fleet)
        if mission is None:
            members.append(Member(robot, None, None, 0, state="idle"))
            continue
        own = folder / robot.name
        own.mkdir(exist_ok=True)
        path = reserve_file(own, "mission.yaml")
        write_mission(mission, path, overwrite=True)  # our own file, reserved just now
        navigator = MemberNavigator(world, robot.name, clock)
        try:
            session = prepare(
                RunRequest(
                    mission=path,
                    navigator=UseNavigator(
                        navigator,
                        {"kind": "sim", "robot": robot.profile.name, "fleet_robot": robot.name},
                        grid=plan.grid,
                    ),
                    start=robot.start,
                    # The fleet records its robots in one file (FleetRun.record).
                    outputs=Outputs(folder=own, picture=False, record=False),
                )
            )
        except NavseqError as error:
            problems.append(
                NavseqError(error_text(error), source=f"robot '{robot.name}'")
            )  # with the others
            continue
        members.append(Member(robot, session, navigator, len(share.order)))
    raise_all(problems)
    return members


def _remove_tree(folder: Path) -> None:
    import shutil

    shutil.rmtree(folder, ignore_errors=True)


__all__ = ["FinishedShare", "FleetRun", "FleetRunRequest", "Member", "prepare_fleet_run"]
