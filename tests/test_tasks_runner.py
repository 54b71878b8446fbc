"""The task runner does what StartTask / CancelTask ask, outside the executor."""

from __future__ import annotations

import io
import os
import sys
import time
from pathlib import Path

from navseq.executor.commands import StartTask
from navseq.mission.tasks import CallTask, InputTask, RunTask, Task, WaitTask
from navseq.tasks.base import TaskDone
from navseq.tasks.options import TaskOptions
from navseq.tasks.runner import TaskRunner


def start(runner: TaskRunner, task: Task, now: float = 0.0, task_id: int = 1) -> None:
    runner.start(StartTask(task_id, task, 0, 0, 1), now)


def until_done(runner: TaskRunner, now: float = 0.0) -> TaskDone:
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        ended = runner.poll(now)
        if ended:
            return ended[0]
        time.sleep(0.01)
    raise AssertionError("the task did not end")


def test_wait_ends_on_the_navigators_clock() -> None:
    runner = TaskRunner(say=lambda line: None)
    start(runner, WaitTask(5.0), now=10.0)
    assert runner.poll(14.9) == []
    assert runner.poll(15.0) == [TaskDone(1, True)]


def test_a_program_is_refused_without_allow_run(tmp_path: Path) -> None:
    runner = TaskRunner(say=lambda line: None)
    start(runner, RunTask(("touch", str(tmp_path / "ran"))))
    done = until_done(runner)
    assert not done.succeeded and "--allow-run" in done.detail
    assert not (tmp_path / "ran").exists()


def test_a_program_runs_without_a_shell_in_its_folder_with_its_environment(
    tmp_path: Path,
) -> None:
    runner = TaskRunner(TaskOptions(allow_run=True), say=lambda line: None)
    code = "import os; print(os.getcwd()); print(os.environ['MODE']); print('$HOME')"
    start(runner, RunTask((sys.executable, "-c", code), cwd=tmp_path, env={"MODE": "dock"}))
    done = until_done(runner)
    assert done.succeeded and done.detail == "exit status 0"
    assert done.output == (str(tmp_path), "dock", "$HOME")  # no shell expanded it


def test_a_program_that_cannot_start_fails_with_why() -> None:
    runner = TaskRunner(TaskOptions(allow_run=True), say=lambda line: None)
    start(runner, RunTask(("/no/such/program",)))
    done = until_done(runner)
    assert not done.succeeded and done.detail.startswith("cannot start /no/such/program")


def test_cancel_kills_the_program_and_its_children(tmp_path: Path) -> None:
    runner = TaskRunner(TaskOptions(allow_run=True), say=lambda line: None)
    pid_file = tmp_path / "child"
    code = (
        "import subprocess, sys, time;"
        "child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)']);"
        f"open({str(pid_file)!r}, 'w').write(str(child.pid)); time.sleep(60)"
    )
    start(runner, RunTask((sys.executable, "-c", code)))
    deadline = time.monotonic() + 30
    while not pid_file.exists() or not pid_file.read_text():
        assert time.monotonic() < deadline
        time.sleep(0.01)
    child = int(pid_file.read_text())
    runner.cancel(1)
    assert runner.poll(0.0) == []  # a cancelled task reports nothing
    deadline = time.monotonic() + 10
    while _alive(child):
        assert time.monotonic() < deadline, "the program's child survived"
        time.sleep(0.05)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie (killed, not reaped by its dead parent yet) is gone for our purpose.
    status = Path(f"/proc/{pid}/status")
    return not status.exists() or "zombie" not in status.read_text()


def test_simulated_ros_tasks_are_logged_and_succeed_after_the_set_time() -> None:
    said: list[str] = []
    runner = TaskRunner(TaskOptions(simulate_ros_s=2.0), say=said.append)
    start(runner, CallTask("/dock/open"), now=1.0)
    assert said == ["simulated: call /dock/open (2 s)"]
    assert runner.poll(2.9) == []
    assert runner.poll(3.0) == [TaskDone(1, True, "simulated")]


def test_input_is_not_read_from_a_plain_file_but_confirm_answers_it() -> None:
    said: list[str] = []
    runner = TaskRunner(say=said.append, stdin=io.StringIO("\n\n"))
    start(runner, InputTask("Load the tray"))
    assert said == ["Load the tray — waiting for confirmation"]
    assert runner.poll(1.0) == []
    assert runner.confirm()
    assert not runner.confirm()  # answered already
    assert runner.poll(2.0) == [TaskDone(1, True, "confirmed")]


def test_a_line_typed_before_the_prompt_does_not_confirm_it() -> None:
    read, write = os.pipe()
    with os.fdopen(read) as stdin, os.fdopen(write, "w") as typed:
        runner = TaskRunner(say=lambda line: None, stdin=stdin)
        start(runner, InputTask("first"))
        typed.write("\n")
        typed.flush()
        assert until_done(runner).detail == "confirmed in the terminal"
        typed.write("\n")  # a stray Enter between two prompts
        typed.flush()
        deadline = time.monotonic() + 10
        while runner.operator._lines.empty():  # read, waiting for a prompt
            assert time.monotonic() < deadline
            time.sleep(0.01)
        start(runner, InputTask("second"), task_id=2)
        assert runner.poll(0.0) == []
        typed.write("\n")
        typed.flush()
        assert until_done(runner) == TaskDone(2, True, "confirmed in the terminal")


def test_a_programs_long_lines_are_cut_and_only_the_last_20_kept() -> None:
    runner = TaskRunner(TaskOptions(allow_run=True), say=lambda line: None)
    code = "print('x' * 100000); [print(i) for i in range(30)]; print('tail', end='')"
    start(runner, RunTask((sys.executable, "-c", code)))
    done = until_done(runner)
    assert done.output == (*[str(i) for i in range(11, 30)], "tail")
    start(runner, RunTask((sys.executable, "-c", "print('y' * 100000)")), task_id=2)
    (line,) = until_done(runner).output
    assert line == "y" * 500


def test_an_enter_pressed_before_the_first_prompt_does_not_confirm_it() -> None:
    read, write = os.pipe()
    os.write(write, b"\n")  # pressed while the robot drove
    os.close(write)  # and then nobody is left to confirm
    with os.fdopen(read) as stdin:
        runner = TaskRunner(say=lambda line: None, stdin=stdin)
        start(runner, InputTask("first"))
        assert until_done(runner) == TaskDone(1, False, "no operator: standard input ended")
