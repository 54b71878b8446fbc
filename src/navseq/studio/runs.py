"""A mission run on the embedded simulator from the studio, in a thread, watched live.

The run is ``navseq run``'s own: the draft is written by the mission writer into a new
output folder (``navseq-out/<mission>-<time>/``, like ``navseq run``'s), then the run
service (:mod:`navseq.run`) prepares and runs a :class:`~navseq.run.request.RunRequest`
for it, with its journal, report and picture, so the folder is the one the CLI leaves
and ``navseq run --resume`` / ``navseq report`` work on it. The run's thread is not the
main thread: it asks for no signal handling (the studio's server has its own). The studio adds a
mission listener (:class:`LiveView`) that folds the mission events into what the page
draws, and a :class:`~navseq.executor.control.MissionControl` through which the page's
stop, pause and skip reach the run's thread as executor inputs (stop cancels the goal,
as Ctrl-C does).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from navseq.executor.control import MissionControl
    from navseq.executor.events import MissionEvent, WaypointFinished
    from navseq.mission.model import Mission
    from navseq.navigators.base import Navigator
    from navseq.run.session import Session
    from navseq.sinks.json_events import Eta

#: Trail points kept for the page (older ones are thinned to every other one).
MAX_TRAIL_POINTS = 4000
#: The trail gets a point when the robot moved this far (m).
TRAIL_STEP_M = 0.02


@dataclass(frozen=True)
class StudioRunOrder:
    """What the page asked to run: the checked mission and the pace."""

    mission: Mission
    stem: str  # the mission file's name without extension, for the folder's name
    realtime: float | None  # None: as fast as the CPU goes


class LiveView:
    """The run as the page shows it, folded from mission events (any thread may read).

    ``version`` grows with every change, so a watcher sends only what is new.
    """

    def __init__(self, waypoint_count: int, footprint: list[tuple[float, float]]) -> None:
        self._lock = threading.Lock()
        self.version = 0
        self.status = "starting"
        self.reason = ""
        self.clock_s = 0.0
        self.current: int | None = None
        self.loop = 0
        self.waypoints = ["pending"] * waypoint_count
        self.pose: tuple[float, float, float] | None = None
        self.plan: list[tuple[float, float]] = []
        self.trail: list[tuple[float, float]] = []
        self.footprint = footprint
        self.report: dict[str, Any] | None = None
        self.folder: str | None = None
        self.error: str | None = None
        self.navigator: Navigator | None = None
        self.eta: Eta | None = None  # the run's ETA (the session's), for the time to go
        self._start_t: float | None = None
        # The clock shows the mission's running time: a pause holds it, as it holds every
        # deadline of the run, so that it does not jump by the pause on Resume.
        self._paused_s = 0.0
        # Waypoint states changed since take_changes() (a replay's timeline is made of them).
        self._changed: set[int] = set()
        self._reset = False

    # -- the run's thread --------------------------------------------------------------

    def __call__(self, event: MissionEvent) -> None:
        from navseq.executor import events as ev

        with self._lock:
            if self._start_t is None:
                self._start_t = event.t
            if isinstance(event, ev.MissionResumed):
                self._paused_s += max(0.0, event.paused_for)
            self.clock_s = max(self.clock_s, event.t - self._start_t - self._paused_s)
            if isinstance(event, ev.MissionStarted):
                self.status = "running"
            elif isinstance(event, ev.LoopStarted):
                self.loop = event.loop
                self.waypoints = ["pending"] * len(self.waypoints)
                self._reset = True
                self._changed.clear()
            elif isinstance(event, ev.WaypointStarted):
                self.current = event.index
                self._set(event.index, "driving")
                self.plan = []
            elif isinstance(event, ev.WaypointProgress):
                self._moved(event.x, event.y, event.yaw)
            elif isinstance(event, ev.WaypointPlan):
                self.plan = [(round(x, 3), round(y, 3)) for x, y in event.path]
            elif isinstance(event, ev.WaypointDwelling):
                self._set(event.index, "dwelling")
            elif isinstance(event, ev.WaypointFinished):
                self._set(event.index, _shown_outcome(event))
            elif isinstance(event, ev.MissionPaused):
                self.status = "paused"
            elif isinstance(event, ev.MissionResumed):
                self.status = "running"
            elif isinstance(event, ev.MissionFinished):
                self.status = "finishing"  # the outputs are written next
                self.reason = event.reason
                self.current = None
            self.version += 1

    def _set(self, index: int, state: str) -> None:
        if self.waypoints[index] != state:
            self.waypoints[index] = state
            self._changed.add(index)

    def take_changes(self) -> tuple[bool, list[tuple[int, str]]]:
        """What changed in the waypoints' states since the last call: whether every one
        went back to pending (a new loop) first, then ``(index, state)`` in index order."""
        with self._lock:
            reset, self._reset = self._reset, False
            changes = [(index, self.waypoints[index]) for index in sorted(self._changed)]
            self._changed.clear()
            return reset, changes

    def _moved(self, x: float, y: float, yaw: float) -> None:
        self.pose = (x, y, yaw)
        if not self.trail or math.dist(self.trail[-1], (x, y)) >= TRAIL_STEP_M:
            self.trail.append((round(x, 3), round(y, 3)))
            if len(self.trail) > MAX_TRAIL_POINTS:
                self.trail = self.trail[::2]

    def finished(self, status: str, report: dict[str, Any] | None, error: str | None) -> None:
        with self._lock:
            self.status = status
            self.report = report
            self.error = error
            self.current = None
            self.version += 1

    # -- any thread --------------------------------------------------------------------

    @property
    def done(self) -> bool:
        return self.status in ("completed", "failed", "stopped", "error")

    def snapshot(self) -> dict[str, Any]:
        """Everything the page draws; the robot's pose read from the simulator itself."""
        with self._lock:
            pose = self.pose
            navigator = self.navigator
            if navigator is not None and not self.done:
                live = navigator.robot_pose()  # an immutable Pose2D: safe to read
                if live is not None:
                    pose = (live.x, live.y, live.yaw)
                    self._moved(*pose)
            return {
                "version": self.version,
                "status": self.status,
                "reason": self.reason,
                "clock_s": round(self.clock_s, 2),
                "eta_s": _seconds(self.eta.eta_s) if self.eta is not None else None,
                "current": self.current,
                "loop": self.loop,
                "waypoints": list(self.waypoints),
                "pose": None
                if pose is None
                else {"x_m": pose[0], "y_m": pose[1], "yaw_deg": math.degrees(pose[2])},
                "footprint_m": self.footprint,
                "plan": list(self.plan),
                "trail": list(self.trail),
                "folder": self.folder,
                "report": self.report,
                "error": self.error,
            }


class StudioRun:
    """One run: its thread, its control mailbox and its live view."""

    def __init__(self, order: StudioRunOrder, out_base: Path) -> None:
        from navseq.executor.control import MissionControl

        self.order = order
        self.out_base = out_base
        self.control: MissionControl = MissionControl()
        robot = order.mission.robot
        from navseq.mission.robot import DEFAULT_PROFILE

        footprint = [(float(x), float(y)) for x, y in (robot or DEFAULT_PROFILE).footprint]
        self.view = LiveView(len(order.mission.waypoints), footprint)
        self._thread: threading.Thread | None = None
        self.folder: Path | None = None
        self.stop_requested = False

    def start(self) -> None:
        """Prepare as ``navseq run`` does (raises NavseqError), then run in a thread."""
        session = self._prepare()
        self._thread = threading.Thread(target=self._run, args=(session,), name="navseq-studio-run")
        self._thread.start()

    def _prepare(self) -> Session:
        from navseq.mission.writer import write_mission
        from navseq.run import Outputs, RunRequest, prepare
        from navseq.run.folder import create_run_folder, default_run_folder

        stem = self.order.stem
        folder = create_run_folder(self.out_base / default_run_folder(stem), fresh=True)
        mission_file = folder / f"{stem}.yaml"
        try:
            # The mission as run, beside its journal: a resume and `navseq report` need it.
            write_mission(self.order.mission, mission_file)
            session = prepare(
                RunRequest(
                    mission=mission_file,
                    outputs=Outputs(folder=folder),
                    realtime=self.order.realtime,
                )
            )
        except BaseException:
            mission_file.unlink(missing_ok=True)
            with contextlib.suppress(OSError):
                folder.rmdir()
            raise
        make_navigator = session.make_navigator

        def watched_navigator() -> Navigator:
            navigator = make_navigator()
            self.view.navigator = navigator
            return navigator

        session.make_navigator = watched_navigator
        self.folder = folder
        # Shown as navseq run says it: relative to where the studio was started.
        self.view.folder = os.path.relpath(folder, self.out_base)
        return session

    def _run(self, session: Session) -> None:
        report: dict[str, Any] | None = None
        error: str | None = None
        code: int | None = None
        try:
            self.view.eta = session.eta()
            outcome = session.run([self.view], control=self.control)
            code = outcome.exit_status
            if outcome.error is not None:
                error = str(outcome.error)
        except NavseqError as failure:
            error = str(failure)
        except Exception as failure:  # shown on the page; the server goes on
            error = f"{type(failure).__name__}: {failure}"
        report = _latest_report(self.folder)
        if error is not None and report is None:
            status = "error"
        elif self.stop_requested:
            status = "stopped"
        elif code == 0:
            status = "completed"
        else:
            status = "failed"
        self.view.finished(status, report, error)

    # -- operator requests (any thread) ------------------------------------------------

    def operate(self, kind: str, reason: str) -> tuple[bool, str]:
        """File ``kind`` (cancel, pause, resume, skip) and wait for the run's answer."""
        if kind == "cancel":
            self.stop_requested = True
        return self.control.request(kind, reason, timeout=5.0)

    def stop_and_wait(self, reason: str, timeout: float = 30.0) -> None:
        """Cancel the goal and end the run (as Ctrl-C does), then wait for its outputs."""
        if self._thread is None:
            return
        if self._thread.is_alive():
            self.stop_requested = True
            self.control.request("cancel", reason, timeout=None)
        self._thread.join(timeout)

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def wait(self, timeout: float | None = None) -> bool:
        if self._thread is None:
            return True
        self._thread.join(timeout)
        return not self._thread.is_alive()


def _shown_outcome(event: WaypointFinished) -> str:
    """A visit's state on the page: one cut short by Stop (or a signal) was stopped, not
    failed, though the executor ends it FAILED."""
    from navseq.executor.control import ended_from_outside
    from navseq.executor.events import WaypointOutcome

    if event.outcome is WaypointOutcome.FAILED and ended_from_outside(event.reason):
        return "stopped"
    return event.outcome.value


def _seconds(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else round(max(value, 0.0), 1)


def _latest_report(folder: Path | None) -> dict[str, Any] | None:
    """The report the run wrote (``report.json``, or ``report-N.json`` if that was taken)."""
    if folder is None:
        return None
    reports = sorted(folder.glob("report*.json"), key=lambda path: path.stat().st_mtime_ns)
    if not reports:
        return None
    try:
        loaded = json.loads(reports[-1].read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return loaded if isinstance(loaded, dict) else None
