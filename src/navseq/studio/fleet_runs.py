"""A fleet run on the embedded simulator from the studio, watched live.

The run is ``navseq run --fleet``'s own (:mod:`navseq.fleet.run`): the fleet file is
planned and checked (every problem at once, nothing moved), every robot with a share
runs its session in a thread of its own on one :class:`~navseq.sim.fleet_world.FleetWorld`
clock, and the run folder (``navseq-out/<fleet>-<time>/``) gets the same files as the
CLI's: a folder per robot, ``fleet-run.json``, ``fleet-report.json`` and ``fleet.png``.
The studio adds, per robot, the one-robot run's live view
(:class:`~navseq.studio.runs.LiveView`, a mission listener on the robot's thread) and
reads the robots' poses from the simulator itself; the page's Stop cancels every
robot's mission as an operator's cancel would.
"""

from __future__ import annotations

import contextlib
import math
import os
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.sim.fleet_world import FleetWorld
from navseq.studio.fleet_replay import robot_colour
from navseq.studio.runs import LiveView

if TYPE_CHECKING:
    from navseq.fleet.run import FleetRun, Member

#: The reason each robot's mission ends with on the page's Stop (an operator's cancel).
STOP_SERVICE = "the studio"
#: What the fleet report's ``interrupted`` says after the page's Stop.
STOPPED_BY = "Stop (the studio)"
#: Fleet files listed at most for the page's choice.
MAX_FLEETS_LISTED = 200
#: How much of a YAML file is read to tell a fleet file (``navseq_fleet:`` or ``robots:``).
SNIFF_BYTES = 4096


@dataclass(frozen=True)
class FleetRunOrder:
    """What the page asked to run: a fleet file, at a pace (None: as fast as the CPU)."""

    fleet: Path
    realtime: float | None


def is_fleet_file(path: Path) -> bool:
    """Whether a YAML file reads as a fleet file: a top-level ``navseq_fleet:`` or
    ``robots:`` key near its start (a mission has ``waypoints:``, never ``robots:``)."""
    try:
        with path.open("rb") as handle:
            head = handle.read(SNIFF_BYTES).decode("utf-8", "replace")
    except OSError:
        return False
    return any(line.startswith(("navseq_fleet:", "robots:")) for line in head.splitlines())


class RobotView:
    """One robot of a live fleet run as the page shows it."""

    def __init__(self, member: Member, place: int) -> None:
        self.member = member
        self.colour = robot_colour(place)
        footprint = [(float(x), float(y)) for x, y in member.robot.profile.footprint]
        session = member.session
        mission = session.mission if session is not None else None
        self.points = [] if mission is None else [[w.x, w.y] for w in mission.waypoints]
        self.labels = [] if mission is None else [w.name or "" for w in mission.waypoints]
        self.view = LiveView(len(self.points), footprint)
        self.view.navigator = member.navigator
        member.listeners.append(self.view)

    def snapshot(self, world_pose: tuple[float, float, float] | None) -> dict[str, Any]:
        member = self.member
        live = self.view.snapshot()
        pose = live["pose"]
        if pose is None and world_pose is not None:  # parked (no share), or not moved yet
            x, y, yaw = world_pose
            pose = {"x_m": x, "y_m": y, "yaw_deg": math.degrees(yaw)}
        eta = member.eta.eta_s if member.eta is not None else None
        return {
            "name": member.robot.name,
            "colour": self.colour,
            "robot": member.robot.profile.name,
            "state": member.state,
            "current": live["current"],
            "current_label": member.current,
            "reached": member.counts["reached"],
            "skipped": member.counts["skipped"],
            "failed": member.counts["failed"],
            "waypoints": member.waypoints,
            "waypoint_points": self.points,
            "waypoint_labels": self.labels,
            "waypoint_states": live["waypoints"],
            "time_s": round(member.time_s, 1),
            "eta_s": None if eta is None or not math.isfinite(eta) else round(max(eta, 0.0), 1),
            "pose": pose,
            "footprint_m": live["footprint_m"],
            "trail": live["trail"],
            "plan": live["plan"],
            "error": None if member.error is None else str(member.error),
        }


class StudioFleetRun:
    """One fleet run: prepared as ``navseq run --fleet`` prepares it, run in a thread."""

    def __init__(self, order: FleetRunOrder, out_base: Path) -> None:
        self.order = order
        self.out_base = out_base
        self.run: FleetRun | None = None
        self.robots: list[RobotView] = []
        self.status = "starting"
        self.error: str | None = None
        self.report: dict[str, Any] | None = None
        self.folder: str | None = None
        self.stop_requested = False
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()
        self._version = 0

    def start(self) -> None:
        """Plan, check and prepare every robot (raises NavseqError, every problem at
        once, before anything moves), then run in a thread."""
        from navseq.fleet.run import FleetRunRequest, prepare_fleet_run
        from navseq.run.folder import create_run_folder, default_run_folder

        folder = create_run_folder(
            self.out_base / default_run_folder(self.order.fleet.stem), fresh=True
        )
        try:
            run = prepare_fleet_run(
                FleetRunRequest(fleet=self.order.fleet, folder=folder, realtime=self.order.realtime)
            )
        except BaseException:
            _remove_if_empty(folder)
            raise
        self.run = run
        self.folder = os.path.relpath(folder, self.out_base)
        self.robots = [RobotView(member, place) for place, member in enumerate(run.members)]
        self._thread = threading.Thread(target=self._run, name="navseq-studio-fleet")
        self._thread.start()

    def _run(self) -> None:
        run = self.run
        assert run is not None
        self._set("running")
        try:
            threads = run.start()
            for thread in threads:
                thread.join()
            self._set("finishing")  # the report and picture are written next
            status, report = run.finish()
        except Exception as failure:  # shown on the page; the server goes on
            self.error = f"{type(failure).__name__}: {failure}"
            self.report = _fleet_report(run.folder)
            self._set("error")
            return
        self.report = report
        errors = [f"{m.robot.name}: {m.error}" for m in run.members if m.error is not None]
        self.error = "; ".join(errors) or None
        if self.stop_requested:
            self._set("stopped")
        else:
            self._set("completed" if status == 0 else "failed")

    def _set(self, status: str) -> None:
        with self._lock:
            self.status = status
            self._version += 1

    # -- operator requests (any thread) ------------------------------------------------

    def stop(self) -> tuple[bool, str]:
        """End every robot's mission as an operator's cancel (each cancels its goal, its
        journal and report say so); the fleet's report says it was stopped."""
        from navseq.executor.control import operator_reason

        run = self.run
        if run is None or not self.alive:
            return False, "the fleet run has ended"
        self.stop_requested = True
        run.stopped_by = STOPPED_BY
        reason = operator_reason("cancel", STOP_SERVICE)
        for member in run.members:
            member.control.submit("cancel", reason)
        return True, "stopping every robot"

    def stop_and_wait(self, timeout: float = 30.0) -> None:
        if self.alive:
            self.stop()
        if self._thread is not None:
            self._thread.join(timeout)

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def wait(self, timeout: float | None = None) -> bool:
        if self._thread is not None:
            self._thread.join(timeout)
        return not self.alive

    @property
    def done(self) -> bool:
        return self.status in ("completed", "failed", "stopped", "error")

    # -- the page (any thread) ---------------------------------------------------------

    def snapshot(self) -> dict[str, Any]:
        """Every robot's pose, waypoint and state, and the fleet's totals and ETA."""
        run = self.run
        assert run is not None
        world = run.world
        # The studio runs fleets on the embedded simulator only (never on ROS stacks).
        assert isinstance(world, FleetWorld)
        robots = []
        for robot in self.robots:
            pose = world.world(robot.member.robot.name).robot.pose  # immutable Pose2D
            robots.append(robot.snapshot((pose.x, pose.y, pose.yaw)))
        totals = {key: sum(r[key] for r in robots) for key in ("reached", "skipped", "failed")}
        running = [r["eta_s"] for r in robots if r["eta_s"] is not None and not _ended(r["state"])]
        with self._lock:
            version = self._version
            status = self.status
        clock = world.now
        return {
            "version": f"{version}:{clock:.3f}",
            "status": status,
            "fleet": os.path.relpath(self.order.fleet, self.out_base),
            "folder": self.folder,
            "clock_s": round(clock, 2),
            # The time the robots have been going, so far: the makespan once all are done.
            "makespan_s": round(max((r["time_s"] for r in robots), default=0.0), 1),
            "planned_makespan_s": round(run.plan.split.makespan_s, 1),
            "eta_s": max(running) if running and not self.done else None,
            "waypoints": sum(r["waypoints"] for r in robots),
            **totals,
            "robot_overlaps": world.collisions,
            "robots": robots,
            "report": self.report,
            "error": self.error,
        }


def _ended(state: str) -> bool:
    return state in ("done", "ended", "error", "idle")


def _fleet_report(folder: Path) -> dict[str, Any] | None:
    """The fleet report in ``folder``, if the run got to write it."""
    from navseq.studio.fleet_replay import FLEET_REPORT, read_json

    return read_json(folder / FLEET_REPORT)


def _remove_if_empty(folder: Path) -> None:
    with contextlib.suppress(OSError):  # not empty: the run wrote in it, keep it
        folder.rmdir()


class FleetDesk:
    """The studio's fleets: the fleet files it may run, the fleet run going on."""

    def __init__(self, fleet_path: Path | None, out_base: Path) -> None:
        self.fleet_path = fleet_path  # navseq studio --fleet FLEET: chosen at start
        self.out_base = out_base
        self.run: StudioFleetRun | None = None
        self._lock = threading.Lock()

    def start(self, fleet: Path, realtime: float | None) -> StudioFleetRun:
        """Start a fleet run of ``fleet`` (checked by the caller against the roots)."""
        with self._lock:
            if self.run is not None and self.run.alive:
                raise NavseqError("a fleet run is going on; stop it first")
            run = StudioFleetRun(FleetRunOrder(fleet, realtime), self.out_base)
            run.start()
            self.run = run
            return run

    @property
    def busy(self) -> bool:
        return self.run is not None and self.run.alive

    def close(self) -> None:
        run = self.run
        if run is not None:
            run.stop_and_wait()


__all__ = [
    "FleetDesk",
    "FleetRunOrder",
    "RobotView",
    "StudioFleetRun",
    "is_fleet_file",
]
