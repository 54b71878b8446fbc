"""Which of a mission's tasks a run may start, checked before the robot moves.

A ``run`` task needs ``--allow-run``. A ROS task (wait_for, snapshot, call, publish)
needs ROS: on a navigator without it (the embedded simulator, the scripted double) it
is refused unless ``--simulate-tasks``; on a ROS navigator (ros1, nav2) this version
does not run ROS tasks yet, and says so instead of pretending. Every refusal names
the task's file:line, all of them at once.
"""

from __future__ import annotations

from collections.abc import Iterator

from navseq.errors import NavseqError
from navseq.mission.model import Mission
from navseq.mission.tasks import Task
from navseq.tasks.options import TaskOptions


def task_problems(
    mission: Mission, options: TaskOptions, navigator: str, *, simulated: bool
) -> list[NavseqError]:
    """Every task of ``mission`` that a run with ``options`` on ``navigator`` must refuse.

    ``simulated``: the navigator is a simulated world without ROS (the robot is placed
    by navseq); otherwise it is a robot's ROS stack.
    """
    problems = []
    for owner, number, task in _every_task(mission):
        subject = f"{owner}, task {number} ({task.kind})"
        if task.kind == "run" and not options.allow_run:
            problems.append(
                NavseqError(
                    "starts a program, which a mission file may not do by itself: give "
                    "--allow-run to allow it",
                    source=task.where,
                    subject=subject,
                )
            )
        elif task.uses_ros and not simulated:
            problems.append(
                NavseqError(
                    f"{task.kind} tasks are not supported on the {navigator} navigator yet "
                    "(wait, input and run are)",
                    source=task.where,
                    subject=subject,
                )
            )
        elif task.uses_ros and options.simulate_ros_s is None:
            problems.append(
                NavseqError(
                    f"needs ROS, which the {navigator} navigator does not have: give "
                    "--simulate-tasks to rehearse it (logged, succeeds after a set time)",
                    source=task.where,
                    subject=subject,
                )
            )
    return problems


def _every_task(mission: Mission) -> Iterator[tuple[str, int, Task]]:
    """Each task once: the defaults' list, then each waypoint's own list."""
    for number, task in enumerate(mission.defaults.tasks, 1):
        yield "defaults", number, task
    for index, waypoint in enumerate(mission.waypoints):
        for number, task in enumerate(waypoint.overrides.get("tasks", ()), 1):
            yield mission.waypoint_label(index), number, task


__all__ = ["task_problems"]
