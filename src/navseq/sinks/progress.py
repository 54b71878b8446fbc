"""What a person (or a program) watching ``navseq run`` sees while the mission runs.

Three listeners share one model of the run, :class:`RunView`:

- :class:`LiveProgress`: a rich live panel for terminals (current waypoint n/N and
  name, status, distance remaining, mission-clock elapsed time, loop, attempt);
- :class:`LogProgress`: one plain line per thing that happened, for logs and pipes
  (and, through its ``out`` callable, for the ROS node's rospy log);
- :class:`~navseq.sinks.json_events.JsonProgress`: one JSON object per event, for
  programs (``--json``; its own module).

:func:`make_progress` picks one; the table printed at the end is
:mod:`navseq.sinks.summary`'s. Elapsed time is the navigator's clock (simulated time
on the simulator).
"""

from __future__ import annotations

import math
import sys
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import IO

from rich.console import Console, Group, RenderableType
from rich.live import Live
from rich.markup import escape
from rich.panel import Panel
from rich.progress_bar import ProgressBar
from rich.table import Table
from rich.text import Text

from navseq.executor.events import (
    AttemptFailed,
    LoopStarted,
    MissionEvent,
    MissionFinished,
    MissionPaused,
    MissionResumed,
    MissionStarted,
    RecoveryFinished,
    RecoveryStarted,
    ServerStatusChanged,
    TaskFinished,
    TaskStarted,
    WaypointDwelling,
    WaypointFinished,
    WaypointHeld,
    WaypointOutcome,
    WaypointProgress,
    WaypointReleased,
    WaypointStarted,
)
from navseq.mission.model import Mission
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.sinks.json_events import Eta, JsonProgress
from navseq.text import printable

OUTCOME_STYLE = {
    WaypointOutcome.REACHED: "green",
    WaypointOutcome.SKIPPED: "dark_orange",
    WaypointOutcome.FAILED: "red",
    WaypointOutcome.NOT_RUN: "grey50",
}
OUTCOME_MARK = {
    WaypointOutcome.REACHED: "✓",
    WaypointOutcome.SKIPPED: "↷",
    WaypointOutcome.FAILED: "✗",
    WaypointOutcome.NOT_RUN: "·",
}


def _plural(count: int, word: str) -> str:
    return f"{count} {word}{'' if count == 1 else 's'}"


def recoveries_text(recoveries: int | None) -> str:
    """``, 2 recoveries`` once the navigation stack ran recovery behaviours for the goal
    (spins, backing up, costmap clearing: a sign the robot is struggling); else nothing."""
    if not recoveries:
        return ""
    return f", {recoveries} recover{'y' if recoveries == 1 else 'ies'}"


def _why(reason: str, text: str) -> str:
    """navseq's reason with the navigation stack's own words after it, when it gave any."""
    reason, text = printable(reason), printable(text.strip())
    if not text or text == reason:
        return reason
    return f"{reason}: {text}" if reason else text


def mission_eta_text(eta: Eta | None) -> str:
    """`` · mission ends in ~1 min 05 s (at most 1 min 35 s)`` from the run's ETA, or ``""``."""
    from navseq.eta.text import format_duration

    if eta is None or eta.eta_s is None:
        return ""
    text = f"mission ends in ~{format_duration(eta.eta_s)}"
    upper = eta.eta_upper_s
    if upper is not None and upper > eta.eta_s + 0.5:
        text += f" ({format_duration(upper)} if every task takes its timeout)"
    return text


def eta_text(remaining: float, robot: RobotProfile) -> str:
    """``~12 s`` to cover ``remaining`` metres at the robot's top speed (a lower bound)."""
    speed = robot.max_linear_speed
    if speed <= 0.0 or not math.isfinite(remaining):
        return ""
    return f"~{remaining / speed:.0f} s at {speed:.2f} m/s"


class RunView:
    """The state of a run as a watcher sees it, folded from mission events."""

    def __init__(self, mission: Mission, numbers: Sequence[int] | None = None):
        self.mission = mission
        # The waypoints' positions in the file when the mission is a part of it.
        self.numbers = numbers if numbers is not None else mission.numbers
        self.count = len(mission.waypoints)
        self.loops = mission.loops
        self.t = 0.0
        self.t_start: float | None = None
        self.loop = 0
        self.index: int | None = None
        self.attempt = 0
        self.status = "starting"
        self.distance_remaining: float | None = None
        self.distance_driven = 0.0
        self.recoveries: int | None = None  # the stack's count for the current goal
        self.loop_outcomes: dict[int, WaypointOutcome] = {}
        self.totals: dict[WaypointOutcome, int] = dict.fromkeys(WaypointOutcome, 0)
        self.finished: MissionFinished | None = None

    @property
    def elapsed(self) -> float:
        return self.t - self.t_start if self.t_start is not None else 0.0

    def number(self, index: int) -> int:
        """The waypoint's 1-based number in the mission file (as the summary table says)."""
        if self.numbers is not None and 0 <= index < len(self.numbers):
            return self.numbers[index] + 1
        return index + 1

    def waypoint_label(self, index: int) -> str:
        name = self.mission.waypoints[index].name if index < self.count else None
        named = f" '{printable(name)}'" if name else ""
        if self.numbers is not None and index < len(self.numbers):  # a part: file numbers
            return f"waypoint {self.numbers[index] + 1}{named} ({index + 1}/{self.count})"
        return f"waypoint {index + 1}/{self.count}{named}"

    def loop_label(self) -> str:
        total = "∞" if self.loops is None else str(self.loops)
        return f"loop {self.loop + 1}/{total}"

    def update(self, event: MissionEvent) -> None:
        self.t = event.t
        if isinstance(event, MissionStarted):
            self.t_start = event.t
            self.status = "started"
        elif isinstance(event, LoopStarted):
            self.loop = event.loop
            self.loop_outcomes = {}
        elif isinstance(event, WaypointStarted):
            self.loop, self.index, self.attempt = event.loop, event.index, event.attempt
            self.distance_remaining = None
            self.recoveries = None
            self.distance_driven = 0.0 if event.attempt == 1 else self.distance_driven
            self.status = "driving" if event.attempt == 1 else f"driving (attempt {event.attempt})"
        elif isinstance(event, WaypointProgress):
            self.index = event.index
            self.distance_remaining = event.distance_remaining
            self.distance_driven = event.distance_driven
            self.recoveries = event.recoveries
        elif isinstance(event, AttemptFailed):
            then = "will retry" if event.will_retry else "giving up"
            why = _why(event.reason, event.text)
            self.status = f"attempt {event.attempt} failed ({why}), {then}"
        elif isinstance(event, WaypointDwelling):
            self.status = f"dwelling {event.seconds:g} s"
            self.distance_remaining = 0.0
        elif isinstance(event, TaskStarted):
            self.status = f"task {event.task}: {printable(event.description)}"
            self.distance_remaining = 0.0
        elif isinstance(event, TaskFinished):
            self.status = f"task {event.task} {_task_outcome(event)}"
        elif isinstance(event, RecoveryStarted):
            self.status = f"recovery {event.recovery}: {printable(event.description)}"
        elif isinstance(event, RecoveryFinished):
            self.status = f"recovery {event.recovery} {_recovery_outcome(event)}"
        elif isinstance(event, WaypointFinished):
            outcome = WaypointOutcome(event.outcome)
            self.loop_outcomes[event.index] = outcome
            self.totals[outcome] += 1
            self.status = outcome.value.replace("_", " ")
            if outcome == WaypointOutcome.REACHED:
                self.distance_remaining = 0.0
        elif isinstance(event, ServerStatusChanged):
            self.status = (
                "navigation server back"
                if event.available
                else "navigation server lost"
                + (f": {printable(event.reason)}" if event.reason else "")
                + ", waiting"
            )
        elif isinstance(event, MissionPaused):
            self.status = f"paused ({printable(event.reason)})" if event.reason else "paused"
        elif isinstance(event, MissionResumed):
            self.status = "resumed"
        elif isinstance(event, MissionFinished):
            self.finished = event
            self.status = printable(event.reason)


class LiveProgress:
    """A rich live panel, redrawn a few times a second by rich's refresh thread.

    Under the current state it shows the last few notable events (as in the log).

    Events only update the :class:`RunView`; drawing happens on refresh, so a fast
    simulator does not pay for rendering every event.
    """

    def __init__(
        self,
        mission: Mission,
        console: Console,
        *,
        recent_lines: int = 4,
        robot: RobotProfile = DEFAULT_PROFILE,
        numbers: Sequence[int] | None = None,
        eta: Eta | None = None,
    ):
        self.view = RunView(mission, numbers)
        self.robot = robot
        self.eta = eta
        self.console = console
        self.recent: deque[str] = deque(maxlen=recent_lines)
        self._live = Live(
            console=console,
            get_renderable=self.render,
            refresh_per_second=8,
            transient=False,
        )

    def __enter__(self) -> LiveProgress:
        self._live.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._live.refresh()
        self._live.stop()

    def __call__(self, event: MissionEvent) -> None:
        self.view.update(event)
        text = describe(event, self.view)
        if text is not None:
            self.recent.append(f"[{self.view.elapsed:7.1f} s] {text}")

    def render(self) -> RenderableType:
        view = self.view
        header = Table.grid(padding=(0, 3))
        header.add_row(
            Text(f"elapsed {view.elapsed:7.1f} s", style="bold"),
            Text(view.loop_label()),
            Text.assemble(
                *(
                    (f"{OUTCOME_MARK[o]} {view.totals[o]}  ", OUTCOME_STYLE[o])
                    for o in (
                        WaypointOutcome.REACHED,
                        WaypointOutcome.SKIPPED,
                        WaypointOutcome.FAILED,
                    )
                )
            ),
        )
        rows: list[RenderableType] = [header]
        if view.index is not None:
            current = Table.grid(padding=(0, 2))
            current.add_row(
                Text(view.waypoint_label(view.index), style="bold cyan"),
                Text(f"attempt {view.attempt}"),
                Text(view.status, style="yellow" if "fail" in view.status else ""),
            )
            rows.append(current)
            remaining = view.distance_remaining
            if remaining is not None and math.isfinite(remaining):
                total = max(view.distance_driven + remaining, 1e-6)
                bar = Table.grid(padding=(0, 2))
                bar.add_row(
                    ProgressBar(total=total, completed=view.distance_driven, width=40),
                    Text(
                        f"{remaining:6.2f} m to go ({eta_text(remaining, self.robot)}), "
                        f"{view.distance_driven:6.2f} m driven{recoveries_text(view.recoveries)}"
                    ),
                )
                rows.append(bar)
        else:
            rows.append(Text(view.status))
        if view.finished is None and (ends := mission_eta_text(self.eta)):
            rows.append(Text(ends))
        if view.count <= 40:
            marks = Text()
            for index in range(view.count):
                outcome = view.loop_outcomes.get(index)
                number = view.number(index)
                if outcome is not None:
                    marks.append(f"{number}{OUTCOME_MARK[outcome]} ", OUTCOME_STYLE[outcome])
                elif index == view.index and view.finished is None:
                    marks.append(f"{number}▶ ", "bold cyan")
                else:
                    marks.append(f"{number}· ", "grey50")
            rows.append(marks)
        rows.extend(
            Text(line, style="dim", overflow="ellipsis", no_wrap=True) for line in self.recent
        )
        title = escape(f"navseq · {view.mission.source}")
        return Panel(Group(*rows), title=title, title_align="left", expand=False)


def describe(event: MissionEvent, view: RunView) -> str | None:
    """One line for a person about a notable event (None for progress, plans, ...).

    ``view`` must already have been updated with ``event``.
    """
    if isinstance(event, MissionStarted):
        loops = "forever" if event.loops is None else _plural(event.loops, "loop")
        resumed = (
            f", resuming at waypoint {view.number(event.resumed_from)}"
            if event.resumed_from is not None
            else ""
        )
        return (
            f"mission {printable(view.mission.source)}: "
            f"{_plural(event.waypoint_count, 'waypoint')}, {loops}{resumed}"
        )
    if isinstance(event, LoopStarted):
        return view.loop_label() if view.loops != 1 else None
    if isinstance(event, WaypointStarted):
        yaw = math.degrees(event.yaw)
        return (
            f"{view.waypoint_label(event.index)}: going to "
            f"({event.x:.2f}, {event.y:.2f}, {yaw:.0f}°), attempt {event.attempt}"
        )
    if isinstance(event, AttemptFailed):
        then = "will retry" if event.will_retry else "giving up"
        return (
            f"{view.waypoint_label(event.index)}: attempt {event.attempt} failed "
            f"({_why(event.reason, event.text)}), {then}"
        )
    if isinstance(event, WaypointDwelling):
        return f"{view.waypoint_label(event.index)}: dwelling {event.seconds:g} s"
    if isinstance(event, TaskStarted):
        again = f", attempt {event.attempt}" if event.attempt > 1 else ""
        return (
            f"{view.waypoint_label(event.index)}: task {event.task} "
            f"{printable(event.description)}{again}"
        )
    if isinstance(event, TaskFinished):
        return (
            f"{view.waypoint_label(event.index)}: task {event.task} ({event.task_kind}) "
            f"{_task_outcome(event)} after {event.duration:.1f} s"
        )
    if isinstance(event, RecoveryStarted):
        return (
            f"{view.waypoint_label(event.index)}: recovery {event.recovery} "
            f"{printable(event.description)} before attempt {event.attempt}"
        )
    if isinstance(event, RecoveryFinished):
        return (
            f"{view.waypoint_label(event.index)}: recovery {event.recovery} "
            f"({event.recovery_kind}) {_recovery_outcome(event)} after {event.duration:.1f} s"
        )
    if isinstance(event, WaypointFinished):
        outcome = WaypointOutcome(event.outcome)
        how = "passed through" if event.passed_through else outcome.value.replace("_", " ")
        why = (
            f" ({printable(event.reason)})"
            if event.reason and outcome != WaypointOutcome.REACHED
            else ""
        )
        return (
            f"{view.waypoint_label(event.index)}: {how}{why} after "
            f"{event.duration:.1f} s, {event.distance_driven:.2f} m, "
            f"{_plural(event.attempts, 'attempt')}"
        )
    if isinstance(event, ServerStatusChanged):
        return view.status
    if isinstance(event, MissionPaused):
        why = f" ({printable(event.reason)})" if event.reason else ""
        return f"{view.waypoint_label(event.index)}: paused{why}, the robot stopped"
    if isinstance(event, MissionResumed):
        return f"{view.waypoint_label(event.index)}: resumed after {event.paused_for:.1f} s"
    if isinstance(event, WaypointHeld):
        why = f" ({printable(event.reason)})" if event.reason else ""
        return f"{view.waypoint_label(event.index)}: held back by the fleet{why}"
    if isinstance(event, WaypointReleased):
        return (
            f"{view.waypoint_label(event.index)}: on its way again after {event.held_for:.1f} s"
            " held (not counted against its timeouts)"
        )
    if isinstance(event, MissionFinished):
        return f"mission finished: {final_status(event.reason, event.success)}"
    return None  # WaypointProgress, WaypointPlan


def _recovery_outcome(event: RecoveryFinished) -> str:
    """``succeeded``, ``failed (COLLISION_AHEAD)`` ..."""
    text = event.outcome.replace("_", " ")
    if event.detail and event.outcome != "succeeded":
        text += f" ({printable(event.detail)})"
    return text


def _task_outcome(event: TaskFinished) -> str:
    """``succeeded``, ``failed (exit status 1), will retry`` ..."""
    text = event.outcome.replace("_", " ")
    if event.detail and event.outcome != "succeeded":
        text += f" ({printable(event.detail)})"
    return text + (", will retry" if event.will_retry else "")


def needs_attention(event: MissionEvent) -> bool:
    """Whether the line about ``event`` tells of something that went wrong.

    A waypoint not reached, a failed attempt, a lost server, a mission that did not
    reach every waypoint: what a log shows as a warning.
    """
    if isinstance(event, WaypointFinished):
        return WaypointOutcome(event.outcome) in (WaypointOutcome.SKIPPED, WaypointOutcome.FAILED)
    if isinstance(event, AttemptFailed):
        return True
    if isinstance(event, TaskFinished):
        return event.outcome != "succeeded"
    if isinstance(event, ServerStatusChanged):
        return not event.available
    if isinstance(event, MissionFinished):
        return not event.success
    return False


def final_status(reason: str, success: bool) -> str:
    """How the mission ended, in one sentence that says each thing once.

    ``completed, every waypoint reached``; ``completed: 8 waypoint visits not reached``
    (the reason says it already); ``interrupted: SIGINT; not every waypoint reached``.
    """
    reason = printable(reason)
    if success:
        return f"{reason}, every waypoint reached"
    if "not reached" in reason:
        return reason
    return f"{reason}; not every waypoint reached"


@dataclass(frozen=True)
class LogLine:
    """One line of :class:`LogProgress`, before it is written anywhere."""

    text: str
    elapsed: float  # s of mission time since the mission started
    attention: bool  # something went wrong (:func:`needs_attention`): a warning
    event: MissionEvent  # what the line is about


class LogProgress:
    """Plain one-line log messages, for output that is not a terminal.

    Progress (distance to go) is logged at most once per ``progress_period`` seconds
    of mission time, so a log of a long run stays readable.

    ``out`` is a stream (each line written as ``[elapsed s] text``) or a callable given
    each :class:`LogLine`: the ROS node logs the same lines through rospy, which stamps
    them itself, so which events make a line and what it says live here only.
    """

    def __init__(
        self,
        mission: Mission,
        out: IO[str] | Callable[[LogLine], None],
        *,
        progress_period: float = 10.0,
        robot: RobotProfile = DEFAULT_PROFILE,
        numbers: Sequence[int] | None = None,
        eta: Eta | None = None,
    ):
        self.view = RunView(mission, numbers)
        self.robot = robot
        self.eta = eta
        self.stream = None if callable(out) else out
        self._emit = out if callable(out) else self._write
        self.progress_period = progress_period
        self._last_progress_t = -math.inf

    def __enter__(self) -> LogProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.stream is not None:
            self.stream.flush()

    def _write(self, line: LogLine) -> None:
        assert self.stream is not None  # the default emitter only exists with a stream
        self.stream.write(f"[{line.elapsed:8.1f} s] {line.text}\n")
        self.stream.flush()

    def _log(self, text: str, event: MissionEvent) -> None:
        self._emit(LogLine(text, self.view.elapsed, needs_attention(event), event))

    def __call__(self, event: MissionEvent) -> None:
        view = self.view
        view.update(event)
        if isinstance(event, WaypointStarted):
            self._last_progress_t = event.t
        if isinstance(event, WaypointProgress):
            if event.t - self._last_progress_t >= self.progress_period:
                self._last_progress_t = event.t
                to_go = (
                    f"{event.distance_remaining:.2f} m to go "
                    f"({eta_text(event.distance_remaining, self.robot)}), "
                    if event.distance_remaining is not None
                    and math.isfinite(event.distance_remaining)
                    else ""
                )
                ends = mission_eta_text(self.eta)
                self._log(
                    f"{view.waypoint_label(event.index)}: {to_go}"
                    f"{event.distance_driven:.2f} m driven{recoveries_text(event.recoveries)}"
                    + (f"; {ends}" if ends else ""),
                    event,
                )
            return
        text = describe(event, view)
        if text is not None:
            self._log(text, event)


ProgressSink = LiveProgress | LogProgress | JsonProgress


def make_progress(
    mission: Mission,
    *,
    json_lines: bool,
    stream: IO[str] | None = None,
    robot: RobotProfile = DEFAULT_PROFILE,
    numbers: Sequence[int] | None = None,
    eta: Eta | None = None,
) -> ProgressSink:
    """JSON lines if asked, a live panel on a terminal, plain log lines otherwise.

    ``robot``'s top speed gives the time still to go (at least) shown with the distance.
    ``numbers``: the waypoints' positions in the file when ``mission`` is a part of it.
    ``eta``: the run's ETA (the session's), shown and written with the progress.
    """
    stream = stream if stream is not None else sys.stdout
    numbers = numbers if numbers is not None else mission.numbers
    if json_lines:
        return JsonProgress(stream, numbers, eta)
    console = Console(file=stream)
    if console.is_terminal:
        return LiveProgress(mission, console, robot=robot, numbers=numbers, eta=eta)
    return LogProgress(mission, stream, robot=robot, numbers=numbers, eta=eta)
