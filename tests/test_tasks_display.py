"""The progress display shows the task a waypoint is running, and how it ended."""

from __future__ import annotations

from helpers_executor import line_mission
from navseq.executor.events import TaskFinished, TaskStarted
from navseq.sinks.progress import RunView, describe, needs_attention


def test_a_running_task_is_the_status_and_a_line_of_the_log() -> None:
    view = RunView(line_mission(2))
    started = TaskStarted(3.0, 0, 0, 2, "run", 1, "run ./scan.sh")
    view.update(started)
    assert view.status == "task 2: run ./scan.sh"
    assert describe(started, view) == "waypoint 1/2 'p1': task 2 run ./scan.sh"
    finished = TaskFinished(5.5, 0, 0, 2, "run", 1, "failed", 2.5, "exit status 3", (), (), True)
    view.update(finished)
    assert view.status == "task 2 failed (exit status 3), will retry"
    assert describe(finished, view) == (
        "waypoint 1/2 'p1': task 2 (run) failed (exit status 3), will retry after 2.5 s"
    )
    assert needs_attention(finished)
    assert not needs_attention(TaskFinished(6.0, 0, 0, 1, "wait", 1, "succeeded", 1.0))
