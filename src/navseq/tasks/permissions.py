"""Which of a mission's tasks a run may start, checked before the robot moves.

A ``run`` task needs ``--allow-run``. A ROS task (wait_for, snapshot, call, publish)
needs ROS: on a navigator without it (the embedded simulator, the scripted double) it
is refused unless ``--simulate-tasks``; on a ROS navigator (ros1, nav2) its message or
service type must load on the running ROS (``types``, the navigator's
:class:`~navseq.tasks.ros_port.RosTypes`), and a snapshot needs a run folder to go
into. Every refusal names the task's file:line, all of them at once.
"""

from __future__ import annotations

from collections.abc import Iterator

from navseq.errors import NavseqError
from navseq.mission.model import Mission
from navseq.mission.tasks import CallTask, PublishTask, SnapshotTask, Task
from navseq.tasks.options import TaskOptions
from navseq.tasks.ros_port import RosTypes


def task_problems(
    mission: Mission,
    options: TaskOptions,
    navigator: str,
    *,
    simulated: bool,
    types: RosTypes | None = None,
    has_folder: bool = True,
) -> list[NavseqError]:
    """Every task of ``mission`` that a run with ``options`` on ``navigator`` must refuse.

    ``simulated``: the navigator is a simulated world without ROS (the robot is placed
    by navseq). ``types``: the running ROS's types, on a navigator that runs ROS tasks;
    None on one that cannot. ``has_folder``: the run writes a folder (snapshots go there).
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
        elif task.uses_ros and types is not None:
            problems.extend(
                NavseqError(problem, source=task.where, subject=subject)
                for problem in _ros_task_problems(task, types, has_folder)
            )
        elif task.uses_ros and not simulated:
            problems.append(
                NavseqError(
                    f"{task.kind} tasks need ROS, and the {navigator} navigator offers none "
                    "to run them (wait, input and run work everywhere)",
                    source=task.where,
                    subject=subject,
                )
            )
        elif task.uses_ros and options.simulate_ros_s is None:
            problems.append(
                NavseqError(
                    f"needs ROS, which the {navigator} navigator does not have: run it with "
                    "--navigator ros1 or nav2, or give --simulate-tasks to rehearse it "
                    "(logged, succeeds after a set time)",
                    source=task.where,
                    subject=subject,
                )
            )
    return problems


def _ros_task_problems(task: Task, types: RosTypes, has_folder: bool) -> Iterator[str]:
    """Why the running ROS cannot run ``task``: its type does not load, or a snapshot
    has no folder to go into."""
    service = isinstance(task, CallTask)
    type_name = getattr(task, "type", None)
    if isinstance(type_name, str):
        why = types.type_problem(type_name, service=service)
        if why is not None:
            what = "service" if service else "message"
            yield f"{what} type {type_name} cannot be loaded here: {why}"
        elif isinstance(task, PublishTask | CallTask):
            fields = task.request if isinstance(task, CallTask) else task.message
            why = types.fields_problem(type_name, fields, service=service)
            if why is not None:
                what = f"the request of {type_name}" if service else f"a {type_name} message"
                yield f"{'request' if service else 'message'} does not fit {what}: {why}"
    if isinstance(task, SnapshotTask) and not has_folder:
        yield (
            "a snapshot is saved into the run folder, and this run writes none (a navseq "
            "node: give it a snapshot_dir parameter)"
        )


def _every_task(mission: Mission) -> Iterator[tuple[str, int, Task]]:
    """Each task once: the defaults' list, then each waypoint's own list."""
    for number, task in enumerate(mission.defaults.tasks, 1):
        yield "defaults", number, task
    for index, waypoint in enumerate(mission.waypoints):
        for number, task in enumerate(waypoint.overrides.get("tasks", ()), 1):
            yield mission.waypoint_label(index), number, task


__all__ = ["task_problems"]
