"""Running tasks outside the executor: what ``StartTask`` and ``CancelTask`` ask.

:class:`TaskRunner` keeps one job per running task and, polled with the navigator's
clock, hands back a :class:`~navseq.tasks.base.TaskDone` for each job that ended by
itself. Timeouts are the executor's: it cancels a task that takes too long. The kinds
are a registry (:data:`JOBS`): a new kind is one job class and one entry.

- ``wait``: the navigator's clock (simulated time on the simulator).
- ``input``: confirmed by :meth:`TaskRunner.confirm` (the Python API, other faces) or by
  a line on standard input when it is a terminal or a pipe (lines typed before the
  prompt do not count).
- ``run``: the program without a shell, its output's last lines kept; cancelling kills
  it.
- ROS kinds (wait_for, snapshot, call, publish): on a ROS navigator, run through its
  :class:`~navseq.tasks.ros_port.RosPort` (:meth:`TaskRunner.attach`;
  :mod:`navseq.tasks.ros_jobs`); on a navigator without ROS, simulated
  (``--simulate-tasks``), logged and successful after the set time.
"""

from __future__ import annotations

import contextlib
import os
import queue
import select
import signal
import stat
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import IO, Protocol

from navseq.executor.commands import StartTask
from navseq.mission.tasks import (
    CallTask,
    InputTask,
    PublishTask,
    RunTask,
    SnapshotTask,
    Task,
    WaitForTask,
    WaitTask,
)
from navseq.tasks.base import TaskDone
from navseq.tasks.options import DEFAULT_SIMULATED_SECONDS, TaskOptions
from navseq.tasks.ros_port import RosPort

#: Lines of a ``run`` program's output kept for the report.
OUTPUT_LINES = 20
#: Characters kept of one output line (a program may print megabytes without a newline).
LINE_CHARACTERS = 500

Say = Callable[[str], None]


class Job(Protocol):
    """One running task. ``real_time``: it lives on the wall clock (a program, a person),
    so the navigator's clock may not run ahead of it (a fast simulator would time it out
    in milliseconds)."""

    real_time: bool

    def poll(self, now: float) -> TaskDone | None:
        """Its end, once it ended by itself; None while it runs."""

    def cancel(self) -> None:
        """Stop it; no TaskDone follows."""


class _Context:
    """What jobs share: the runner's options, how to tell the operator, stdin's lines;
    once attached (:meth:`TaskRunner.attach`), the navigator's ROS port, the run folder
    and the waypoints' names."""

    def __init__(self, options: TaskOptions, say: Say, operator: OperatorInput) -> None:
        self.options = options
        self.say = say
        self.operator = operator
        self.port: RosPort | None = None
        self.folder: Path | None = None
        self.waypoint_name: Callable[[int], str | None] = lambda _index: None


class _WaitJob:
    real_time = False

    def __init__(self, task_id: int, seconds: float, now: float) -> None:
        self._done = TaskDone(task_id, True)
        self._end = now + seconds

    def poll(self, now: float) -> TaskDone | None:
        return self._done if now >= self._end else None

    def cancel(self) -> None:
        pass


class _InputJob:
    real_time = True

    def __init__(self, task_id: int, context: _Context, prompt: str) -> None:
        self._task_id = task_id
        self._operator = context.operator
        self._ticket = self._operator.ask()
        context.say(f"{prompt} — {self._operator.how_to_confirm()}")

    def poll(self, now: float) -> TaskDone | None:
        answer = self._operator.answer(self._ticket)
        if answer is None:
            return None
        confirmed, detail = answer
        return TaskDone(self._task_id, confirmed, detail)

    def cancel(self) -> None:
        self._operator.withdraw(self._ticket)


class _RunJob:
    """A program without a shell; stdout and stderr together, the last lines kept."""

    real_time = True

    def __init__(self, task_id: int, task: RunTask, refuse: str | None) -> None:
        self._task_id = task_id
        self._lines: deque[str] = deque(maxlen=OUTPUT_LINES)
        self._failed: TaskDone | None = None
        self._process: subprocess.Popen[bytes] | None = None
        self._reader: threading.Thread | None = None
        if refuse is not None:
            self._failed = TaskDone(task_id, False, refuse)
            return
        try:
            self._process = subprocess.Popen(
                list(task.argv),
                cwd=task.cwd,
                env={**os.environ, **task.env} if task.env else None,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                start_new_session=True,  # Ctrl-C in the terminal is navseq's, not its
            )
        except OSError as error:
            self._failed = TaskDone(task_id, False, f"cannot start {task.argv[0]}: {error}")
            return
        self._reader = threading.Thread(target=self._read, name="navseq-run-task", daemon=True)
        self._reader.start()

    def _read(self) -> None:
        """Keep the last lines, each cut short: a program printing a gigabyte without a
        newline takes no more memory than one piece of it."""
        assert self._process is not None and self._process.stdout is not None
        stdout, continued = self._process.stdout, False
        while raw := stdout.readline(LINE_CHARACTERS * 4):
            if not continued:
                text = raw.decode("utf-8", "replace").rstrip("\r\n")
                self._lines.append(text[:LINE_CHARACTERS])
            continued = not raw.endswith(b"\n")

    def poll(self, now: float) -> TaskDone | None:
        if self._failed is not None:
            return self._failed
        assert self._process is not None
        status = self._process.poll()
        if status is None:
            return None
        if self._reader is not None:
            self._reader.join(timeout=1.0)  # the output's last lines, written before exit
        return TaskDone(
            self._task_id,
            status == 0,
            f"exit status {status}" if status >= 0 else f"killed by signal {-status}",
            output=tuple(self._lines),
        )

    def cancel(self) -> None:
        process = self._process
        if process is None or process.poll() is not None:
            return
        with contextlib.suppress(OSError):
            os.killpg(process.pid, signal.SIGKILL)  # its children too: its own session
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(timeout=5.0)


class _SimulatedRosJob:
    """A ROS task on a navigator without ROS, rehearsed: logged, then a success."""

    real_time = False

    def __init__(self, task_id: int, context: _Context, task: Task, now: float) -> None:
        seconds = context.options.simulate_ros_s
        seconds = DEFAULT_SIMULATED_SECONDS if seconds is None else seconds
        context.say(f"simulated: {task.describe()} ({seconds:g} s)")
        self._wait = _WaitJob(task_id, seconds, now)
        self._done = TaskDone(task_id, True, "simulated")

    def poll(self, now: float) -> TaskDone | None:
        return self._done if self._wait.poll(now) is not None else None

    def cancel(self) -> None:
        pass


def _wait_job(command: StartTask, context: _Context, now: float) -> Job:
    assert isinstance(command.task, WaitTask)
    return _WaitJob(command.task_id, command.task.seconds, now)


def _input_job(command: StartTask, context: _Context, now: float) -> Job:
    assert isinstance(command.task, InputTask)
    return _InputJob(command.task_id, context, command.task.prompt)


def _run_job(command: StartTask, context: _Context, now: float) -> Job:
    assert isinstance(command.task, RunTask)
    refuse = None if context.options.allow_run else "refused: running programs needs --allow-run"
    return _RunJob(command.task_id, command.task, refuse)


def _simulated_job(command: StartTask, context: _Context, now: float) -> Job:
    if context.options.simulate_ros_s is None:
        return _Refused(command.task_id, f"{command.task.kind} tasks need ROS (--simulate-tasks)")
    return _SimulatedRosJob(command.task_id, context, command.task, now)


def _wait_for_job(command: StartTask, context: _Context, port: RosPort) -> Job:
    from navseq.tasks.ros_jobs import WaitForJob

    assert isinstance(command.task, WaitForTask)
    return WaitForJob(command.task_id, command.task, port)


def _snapshot_job(command: StartTask, context: _Context, port: RosPort) -> Job:
    from navseq.tasks.ros_jobs import SnapshotJob
    from navseq.tasks.snapshots import snapshot_stem

    assert isinstance(command.task, SnapshotTask)
    stem = snapshot_stem(context.waypoint_name(command.index), command.index, command.number)
    if command.loop > 0:  # a patrol's later loops (0-based): one file per visit
        stem += f"-loop{command.loop + 1}"
    return SnapshotJob(command.task_id, command.task, port, context.folder, stem)


def _call_job(command: StartTask, context: _Context, port: RosPort) -> Job:
    from navseq.tasks.ros_jobs import CallJob

    assert isinstance(command.task, CallTask)
    return CallJob(command.task_id, command.task, port)


def _publish_job(command: StartTask, context: _Context, port: RosPort) -> Job:
    from navseq.tasks.ros_jobs import PublishJob

    assert isinstance(command.task, PublishTask)
    return PublishJob(command.task_id, command.task, port)


def _on_ros(
    start: Callable[[StartTask, _Context, RosPort], Job],
) -> Callable[[StartTask, _Context, float], Job]:
    """A ROS kind: run through the navigator's ROS port, simulated where there is none."""

    def start_job(command: StartTask, context: _Context, now: float) -> Job:
        if context.port is None:
            return _simulated_job(command, context, now)
        return start(command, context, context.port)

    return start_job


class _Refused:
    real_time = False

    def __init__(self, task_id: int, detail: str) -> None:
        self._done = TaskDone(task_id, False, detail)

    def poll(self, now: float) -> TaskDone | None:
        return self._done

    def cancel(self) -> None:
        pass


#: Each task kind -> how to start its job. The ROS kinds run on the navigator's ROS
#: port, and are simulated on a navigator without ROS.
JOBS: Mapping[str, Callable[[StartTask, _Context, float], Job]] = {
    "wait": _wait_job,
    "input": _input_job,
    "run": _run_job,
    "wait_for": _on_ros(_wait_for_job),
    "snapshot": _on_ros(_snapshot_job),
    "call": _on_ros(_call_job),
    "publish": _on_ros(_publish_job),
}


class OperatorInput:
    """Confirmations of ``input`` tasks: from :meth:`confirm`, or a line on ``stdin``.

    ``stdin`` is read only when it is a terminal or a pipe (a file or /dev/null would
    confirm at once or never), by one daemon thread started at the first prompt; lines
    typed before a prompt do not count. Each prompt is a ticket. :meth:`confirm` answers
    the open prompt, or, when none is open, the next one: a listener that confirms on
    ``TaskStarted`` does so before the runner has asked.
    """

    def __init__(self, stdin: IO[str] | None = None, hint: str | None = None) -> None:
        self._stdin = stdin if stdin is not None else sys.stdin
        self._hint = hint  # how else to confirm (a node's ~confirm service)
        self._lock = threading.Lock()
        self._ticket = 0
        self._open = False  # a prompt waits for its answer
        self._answer: tuple[bool, str] | None = None  # the open prompt's
        self._early: tuple[bool, str] | None = None  # for the next prompt
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._reader: threading.Thread | None = None
        self._reads = _reads_lines(self._stdin)

    def how_to_confirm(self) -> str:
        ways = ["press Enter"] if self._reads else []
        ways += [self._hint] if self._hint else []
        return " or ".join(ways) + " to go on" if ways else "waiting for confirmation"

    def ask(self) -> int:
        """A new prompt: lines typed before it do not count."""
        with self._lock:
            self._ticket += 1
            self._open = True
            self._answer, self._early = self._early, None
            while not self._lines.empty():
                if self._lines.get_nowait() is None:  # stdin ended: say so again
                    self._lines.put(None)
                    break
            if self._reads and self._reader is None:
                _discard_pending(self._stdin)  # typed before the first prompt
                self._reader = threading.Thread(
                    target=self._read, name="navseq-operator-input", daemon=True
                )
                self._reader.start()
            return self._ticket

    def _read(self) -> None:
        try:
            for line in self._stdin:
                self._lines.put(line)
        except (OSError, ValueError):
            pass
        self._lines.put(None)

    def confirm(self, confirmed: bool = True, detail: str = "") -> bool:
        """Answer the open prompt, or the next one; False when one is already answered."""
        answer = (confirmed, detail or ("confirmed" if confirmed else "refused"))
        with self._lock:
            if self._open:
                if self._answer is not None:
                    return False
                self._answer = answer
                return True
            if self._early is not None:
                return False
            self._early = answer
            return True

    def answer(self, ticket: int) -> tuple[bool, str] | None:
        """The answer to prompt ``ticket``, once there is one (the prompt then closes)."""
        with self._lock:
            if ticket != self._ticket or not self._open:
                return None
            if self._answer is None and not self._lines.empty():
                line = self._lines.get_nowait()
                if line is None:
                    self._lines.put(None)
                    self._answer = (False, "no operator: standard input ended")
                else:
                    self._answer = (True, "confirmed in the terminal")
            answer = self._answer
            if answer is not None:
                self._open, self._answer = False, None
            return answer

    def confirm_waiting(self, detail: str) -> bool:
        """Confirm the prompt open now; False when none is open or it is answered
        already (unlike :meth:`confirm`, nothing is kept for a later prompt: a ROS
        service's caller must learn that nobody was waiting)."""
        with self._lock:
            if not self._open or self._answer is not None:
                return False
            self._answer = (True, detail)
            return True

    def withdraw(self, ticket: int) -> None:
        """Prompt ``ticket`` was cancelled: a confirmation now goes to the next one."""
        with self._lock:
            if ticket == self._ticket:
                self._open, self._answer = False, None


def _discard_pending(stream: IO[str]) -> None:
    """Throw away what waits to be read on ``stream`` now (not its end, if it ended)."""
    try:
        descriptor = stream.fileno()
        while select.select([descriptor], [], [], 0)[0]:
            if not os.read(descriptor, 65536):
                return  # the end: the reader thread will see it too
    except (OSError, ValueError):
        pass


def _reads_lines(stream: IO[str]) -> bool:
    """Whether ``stream`` is a terminal or a pipe (someone may type or send a line)."""
    try:
        if stream.isatty():
            return True
        return stat.S_ISFIFO(os.fstat(stream.fileno()).st_mode)
    except (OSError, ValueError, AttributeError):
        return False


class TaskRunner:
    """Runs the tasks a mission's executor starts; see the module docstring.

    ``say`` gets the lines an operator should see (a prompt, a simulated task);
    ``stdin`` is where an operator's Enter comes from (default: the process's);
    ``confirm_hint`` names another way to confirm, for the prompt ("call
    /navseq/confirm").
    """

    def __init__(
        self,
        options: TaskOptions | None = None,
        *,
        say: Say | None = None,
        stdin: IO[str] | None = None,
        confirm_hint: str | None = None,
    ) -> None:
        self.operator = OperatorInput(stdin, confirm_hint)
        self._context = _Context(options or TaskOptions(), say or _to_stderr, self.operator)
        self._jobs: dict[int, Job] = {}
        # (navigator time, wall time) when a real-time job started: see pace().
        self._paced_from: tuple[float, float] | None = None

    def attach(
        self,
        port: RosPort | None,
        folder: Path | None,
        waypoint_name: Callable[[int], str | None] | None = None,
    ) -> None:
        """Where ROS tasks run (the navigator's port; None: simulated) and where
        snapshots go (the run folder; None: nowhere, a snapshot fails);
        ``waypoint_name(index)`` names a snapshot's file."""
        self._context.port = port
        self._context.folder = folder
        if waypoint_name is not None:
            self._context.waypoint_name = waypoint_name

    def start(self, command: StartTask, now: float) -> None:
        job = self._jobs[command.task_id] = JOBS[command.task.kind](command, self._context, now)
        if job.real_time:
            self._paced_from = (now, time.monotonic())

    def pace(self, now: float) -> None:
        """Hold the navigator's clock to the wall clock while a real-time job runs.

        Called after each step of the run: a simulator running 1000x real time then
        waits, so that a program's or an operator's timeout means seconds. A navigator
        that keeps real time (ROS, ``--realtime 1``) is never held.
        """
        if not any(job.real_time for job in self._jobs.values()):
            self._paced_from = None
            return
        if self._paced_from is None:
            self._paced_from = (now, time.monotonic())
        navigator_start, wall_start = self._paced_from
        ahead = (now - navigator_start) - (time.monotonic() - wall_start)
        if ahead > 0:
            time.sleep(min(ahead, 1.0))

    def cancel(self, task_id: int) -> None:
        job = self._jobs.pop(task_id, None)
        if job is not None:
            job.cancel()

    def poll(self, now: float) -> list[TaskDone]:
        """The tasks that ended since the last poll."""
        ended = []
        for task_id, job in list(self._jobs.items()):
            done = job.poll(now)
            if done is not None:
                del self._jobs[task_id]
                ended.append(done)
        return ended

    def confirm(self, confirmed: bool = True, detail: str = "") -> bool:
        """Answer the ``input`` task waiting for an operator; False when none waits."""
        return self.operator.confirm(confirmed, detail)

    def confirm_waiting(self, detail: str = "confirmed") -> bool:
        """Confirm the ``input`` task waiting now; False when none waits (nothing is
        kept for a later one)."""
        return self.operator.confirm_waiting(detail)

    def close(self) -> None:
        """Stop every task still running (the run ended)."""
        for task_id in list(self._jobs):
            self.cancel(task_id)


def _to_stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


__all__ = ["JOBS", "OUTPUT_LINES", "Job", "OperatorInput", "TaskRunner"]
