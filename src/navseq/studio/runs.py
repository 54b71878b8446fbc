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
as Ctrl-C does). The run's :class:`~navseq.tasks.runner.TaskRunner` is the studio's:
the page's Confirm and Refuse answer an ``input`` task through it
(:meth:`StudioRun.confirm`), and the view says which task runs at which waypoint.

The report is shown as soon as it is written: ``navseq run`` writes it first and draws
the picture after (seconds on a big map), so while the run is ``finishing`` the view
looks for it in the run folder and hands it to the page at once.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.tasks.options import TaskOptions

if TYPE_CHECKING:
    from navseq.executor.control import MissionControl
    from navseq.executor.events import MissionEvent, WaypointFinished
    from navseq.mission.model import Mission
    from navseq.navigators.base import Navigator
    from navseq.run.session import Session
    from navseq.sinks.json_events import Eta
    from navseq.tasks.runner import TaskRunner

#: Trail points kept for the page (older ones are thinned to every other one).
MAX_TRAIL_POINTS = 4000
#: The trail gets a point when the robot moved this far (m).
TRAIL_STEP_M = 0.02


@dataclass(frozen=True)
class StudioRunOrder:
    """What the page asked to run: the checked mission, the pace and what its tasks may
    do (``run`` programs only when the studio was started with ``--allow-run``)."""

    mission: Mission
    stem: str  # the mission file's name without extension, for the folder's name
    realtime: float | None  # None: as fast as the CPU goes
    tasks: TaskOptions = field(default_factory=TaskOptions)


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
        # The task running now ({index, number, kind, description, attempt, asks,
        # answered}), the last one that ended, and the last line said to the operator.
        self.task: dict[str, Any] | None = None
        self.last_task: dict[str, Any] | None = None
        self.note = ""
        self.folder_path: Path | None = None  # where the report is looked for early
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
            elif isinstance(event, ev.TaskStarted):
                self.task = {
                    "index": event.index,
                    "number": event.task,
                    "kind": event.task_kind,
                    "description": event.description,
                    "attempt": event.attempt,
                    "asks": event.task_kind == "input",  # waits for Confirm or Refuse
                    "answered": False,
                }
            elif isinstance(event, ev.TaskFinished):
                self.task = None
                self.last_task = {
                    "index": event.index,
                    "number": event.task,
                    "kind": event.task_kind,
                    "outcome": event.outcome,
                    "duration_s": round(event.duration, 2),
                    "detail": event.detail,
                    "files": list(event.files),
                }
            elif isinstance(event, ev.MissionPaused):
                self.status = "paused"
            elif isinstance(event, ev.MissionResumed):
                self.status = "running"
            elif isinstance(event, ev.MissionFinished):
                self.status = "finishing"  # the outputs are written next
                self.reason = event.reason
                self.current = None
                self.task = None
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
            self.report = report if report is not None else self.report
            self.error = error
            self.current = None
            self.task = None
            self.version += 1

    def say(self, line: str) -> None:
        """A line for the operator from the task runner (a prompt, a simulated task)."""
        with self._lock:
            self.note = line
            self.version += 1

    def take_answer(self) -> bool:
        """Mark the waiting ``input`` task answered; False when none waits (no task, not
        an ``input``, or answered already)."""
        with self._lock:
            task = self.task
            if task is None or not task["asks"] or task["answered"]:
                return False
            task["answered"] = True
            self.version += 1
            return True

    def _early_report(self) -> None:
        """While the outputs are written: the report, once it is (before the picture)."""
        if self.status != "finishing" or self.report is not None:
            return
        report = _latest_report(self.folder_path)
        if report is not None:
            self.report = report
            self.version += 1

    # -- any thread --------------------------------------------------------------------

    @property
    def done(self) -> bool:
        return self.status in ("completed", "failed", "stopped", "error")

    def snapshot(self) -> dict[str, Any]:
        """Everything the page draws; the robot's pose read from the simulator itself."""
        with self._lock:
            self._early_report()
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
                "task": dict(self.task) if self.task is not None else None,
                "last_task": self.last_task,
                "note": self.note,
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
        self.tasks: TaskRunner | None = None  # made with the session

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
                    tasks=self.order.tasks,
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
        from navseq.tasks.runner import TaskRunner

        # The studio's own runner: the page answers input tasks; the server's standard
        # input is not the operator's (an empty text is read as no operator there).
        self.tasks = TaskRunner(self.order.tasks, say=self.view.say, stdin=io.StringIO())
        session.task_runner = self.tasks
        self.folder = folder
        self.view.folder_path = folder
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

    def confirm(self, confirmed: bool) -> tuple[bool, str]:
        """Answer the ``input`` task waiting at the current waypoint (the page's Confirm
        or Refuse); ``(False, why)`` when none waits."""
        if self.tasks is None or not self.alive or not self.view.take_answer():
            return False, "no input task waits for an answer"
        detail = "confirmed in the studio" if confirmed else "refused in the studio"
        self.tasks.confirm(confirmed, detail)
        return True, detail

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


def _no_number(_constant: str) -> None:
    return None


def _latest_report(folder: Path | None) -> dict[str, Any] | None:
    """The report the run wrote (``report.json``, or ``report-N.json`` if that was taken)."""
    if folder is None:
        return None
    reports = sorted(folder.glob("report*.json"), key=lambda path: path.stat().st_mtime_ns)
    if not reports:
        return None
    try:
        # NaN or Infinity (which Python writes) as null: the page's JSON has no such number.
        loaded = json.loads(reports[-1].read_text(encoding="utf-8"), parse_constant=_no_number)
    except (OSError, ValueError):
        return None
    return loaded if isinstance(loaded, dict) else None
