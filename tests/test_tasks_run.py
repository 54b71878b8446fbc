"""Tasks at waypoints in real runs on the simulator: wait, run, input and rehearsed ROS
tasks; what is refused before the robot moves; timeouts and failures under on_failure;
pause and skip during a task; a crash during a task, then --resume."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from cli_support import (
    NAVSEQ,
    REPO,
    TURTLEBOT3_MAP,
    assert_clean_error,
    journal_records,
    navseq,
    start_navseq,
    wait_for,
    write_mission,
)
from navseq.errors import NavseqError
from navseq.executor.control import MissionControl
from navseq.executor.events import MissionEvent, TaskStarted
from navseq.mission import load_mission
from navseq.run.request import Outputs, RunRequest
from navseq.run.session import prepare
from navseq.tasks.options import TaskOptions
from navseq.tasks.permissions import task_problems
from navseq.tasks.runner import TaskRunner

HEADER = f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n"
PY = sys.executable


def mission(tmp_path: Path, waypoints: str, defaults: str = "") -> Path:
    header = HEADER + (f"defaults: {defaults}\n" if defaults else "")
    return write_mission(tmp_path / "m.yaml", waypoints, header)


def report(out: Path) -> dict[str, Any]:
    return dict(json.loads((out / "report.json").read_text()))


def schema(name: str) -> Draft202012Validator:
    return Draft202012Validator(json.loads((REPO / "docs" / "schemas" / name).read_text()))


PRINT_30 = f"[{PY}, -c, 'for i in range(30): print(\"line\", i)']"


def test_wait_run_and_simulated_ros_tasks_run_in_order_and_are_reported(tmp_path: Path) -> None:
    path = mission(
        tmp_path,
        f"""\
  - name: dock
    x: -1.0
    y: -0.5
    tasks:
      - wait: 2
      - run: {{argv: {PRINT_30}}}
      - call: {{service: /dock/open}}
  - {{name: back, x: -2.0, y: -0.5}}
""",
    )
    out = tmp_path / "out"
    done = navseq(
        "run", path, "--allow-run", "--simulate-tasks", "0.5", "--json", "--out", out, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    tasks = report(out)["visits"][0]["tasks"]
    assert [(t["kind"], t["outcome"]) for t in tasks] == [
        ("wait", "succeeded"),
        ("run", "succeeded"),
        ("call", "succeeded"),
    ]
    assert tasks[0]["duration_s"] == 2.0 and tasks[2]["duration_s"] == 0.5
    assert tasks[1]["detail"] == "exit status 0"
    assert tasks[1]["output"] == [f"line {i}" for i in range(10, 30)]  # the last 20
    assert tasks[2]["detail"] == "simulated"
    assert report(out)["visits"][1]["tasks"] == []
    assert "simulated: call /dock/open" in done.stderr
    records = [json.loads(line) for line in done.stdout.splitlines()]
    started = [r for r in records if r["event"] == "TaskStarted"]
    assert [(r["task"], r["kind"]) for r in started] == [(1, "wait"), (2, "run"), (3, "call")]
    events, report_schema = schema("events.schema.json"), schema("report.schema.json")
    for record in records:
        assert list(events.iter_errors(record)) == [], record
    assert list(report_schema.iter_errors(report(out))) == []


def test_run_and_ros_tasks_are_refused_before_the_robot_moves(tmp_path: Path) -> None:
    path = mission(
        tmp_path,
        """\
  - x: -1.0
    y: -0.5
    tasks:
      - run: {argv: [touch, ran]}
      - publish: {topic: /beep, type: std_msgs/Empty}
""",
    )
    done = navseq("run", path, "--out", tmp_path / "out", cwd=tmp_path)
    assert_clean_error(done)
    assert "m.yaml:8, waypoint 1, task 1 (run): starts a program" in done.stderr
    assert "--allow-run" in done.stderr
    assert "m.yaml:9, waypoint 1, task 2 (publish): needs ROS" in done.stderr
    assert "--simulate-tasks" in done.stderr
    assert not (tmp_path / "out").exists() and not (tmp_path / "ran").exists()
    checked = navseq("validate", path, cwd=tmp_path)
    assert_clean_error(checked)
    assert "m.yaml:8" in checked.stderr and "m.yaml:9" in checked.stderr
    assert navseq("validate", path, "--allow-run", "--simulate-tasks", cwd=tmp_path).returncode == 0


class _KnownTypes:
    """The types a running ROS could load, as a navigator's port says (no ROS here)."""

    def type_problem(self, type_name: str, *, service: bool = False) -> str | None:
        known = {"std_srvs/Trigger"} if service else {"std_msgs/Bool"}
        return None if type_name in known else "not found"

    def fields_problem(self, type_name: str, fields: Any, *, service: bool = False) -> str | None:
        return next((f"no field {name!r}" for name in fields if name != "data"), None)


def test_ros_tasks_on_a_ros_navigator_are_checked_against_its_types(tmp_path: Path) -> None:
    path = mission(
        tmp_path,
        "  - {x: -1, y: -0.5, tasks: [{call: {service: /x}}, {wait: 1}]}\n"
        "  - x: -1\n    y: 0\n    tasks:\n"
        "      - publish: {topic: /a, type: std_msgs/Missing}\n"
        "      - call: {service: /y, type: my_srvs/Nope}\n"
        "      - snapshot: {topic: /b, type: std_msgs/Bool}\n"
        "      - publish: {topic: /c, type: std_msgs/Bool, message: {datum: true}}\n"
        "      - call: {service: /d, request: {data: 1}}\n",
    )
    loaded = load_mission(path)
    problems = task_problems(loaded, TaskOptions(), "ros1", simulated=False, types=_KnownTypes())
    assert [str(p) for p in problems] == [
        f"{path}:9, waypoint 2, task 1 (publish): message type std_msgs/Missing cannot be "
        "loaded here: not found",
        f"{path}:10, waypoint 2, task 2 (call): service type my_srvs/Nope cannot be loaded "
        "here: not found",
        f"{path}:12, waypoint 2, task 4 (publish): message does not fit a std_msgs/Bool "
        "message: no field 'datum'",
    ]
    # A node writes no run folder: a snapshot has nowhere to go.
    without_folder = task_problems(
        loaded, TaskOptions(), "ros1", simulated=False, types=_KnownTypes(), has_folder=False
    )
    assert str(without_folder[-2]) == (
        f"{path}:11, waypoint 2, task 3 (snapshot): a snapshot is saved into the run folder, "
        "and this run writes none (a navseq node: give it a snapshot_dir parameter)"
    )
    # A navigator that is no simulator and offers no ROS cannot run them at all.
    (refused,) = task_problems(
        load_mission(mission(tmp_path, "  - {x: -1, y: -0.5, tasks: [{call: {service: /x}}]}\n")),
        TaskOptions(simulate_ros_s=1.0),
        "studio",
        simulated=False,
    )
    assert "call tasks need ROS, and the studio navigator offers none" in str(refused)


@pytest.mark.parametrize(
    ("on_failure", "exit_code", "outcomes", "second"),
    [
        ("stop", 1, ["failed"], "not_run"),
        ("skip", 1, ["failed"], "reached"),
    ],
)
def test_a_failing_program_is_handled_by_on_failure(
    tmp_path: Path, on_failure: str, exit_code: int, outcomes: list[str], second: str
) -> None:
    path = mission(
        tmp_path,
        f"""\
  - x: -1.0
    y: -0.5
    tasks: [{{run: {{argv: [{PY}, -c, "import sys; print('jammed'); sys.exit(3)"]}}}}]
  - {{x: -2.0, y: -0.5}}
""",
        f"{{on_failure: {on_failure}}}",
    )
    out = tmp_path / "out"
    done = navseq("run", path, "--allow-run", "--out", out, cwd=tmp_path)
    assert done.returncode == exit_code, done.stderr
    visits = report(out)["visits"]
    assert [t["outcome"] for t in visits[0]["tasks"]] == outcomes
    assert visits[0]["tasks"][0]["detail"] == "exit status 3"
    assert visits[0]["tasks"][0]["output"] == ["jammed"]
    assert visits[0]["reason"] == "task 1 (run) failed: exit status 3"
    assert visits[1]["outcome"] == second


def test_a_program_over_its_timeout_is_killed_and_retried(tmp_path: Path) -> None:
    path = mission(
        tmp_path,
        f"""\
  - x: -1.0
    y: -0.5
    tasks:
      - run: {{argv: [{PY}, -c, "import time; time.sleep(60)"]}}
        timeout: 0.5
""",
        "{retries: 1, on_failure: skip}",
    )
    out = tmp_path / "out"
    done = navseq("run", path, "--allow-run", "--out", out, cwd=tmp_path)
    assert done.returncode == 1, done.stderr
    tasks = report(out)["visits"][0]["tasks"]
    assert [(t["attempt"], t["outcome"]) for t in tasks] == [(1, "timed_out"), (2, "timed_out")]
    assert report(out)["visits"][0]["outcome"] == "skipped"
    assert "task 1 (run) timed out" in report(out)["visits"][0]["reason"]


def confirm_when_asked(args: list[str], cwd: Path, prompt: str) -> str:
    """Run ``navseq ARGS`` and press Enter once ``prompt`` shows on stderr (what was
    typed before it would not count); the rest of its stderr."""
    with (cwd / "stdout.txt").open("w") as stdout:
        process = subprocess.Popen(
            [NAVSEQ, *args],
            cwd=cwd,
            stdin=subprocess.PIPE,
            stdout=stdout,  # a file: the progress lines never fill a pipe meanwhile
            stderr=subprocess.PIPE,
            text=True,
        )
        assert process.stdin is not None and process.stderr is not None
        seen = []
        for line in process.stderr:
            seen.append(line)
            if prompt in line:
                break
        process.stdin.write("\n")
        process.stdin.flush()
        _, stderr = process.communicate(timeout=60)
    assert process.returncode == 0, "".join(seen) + stderr
    return "".join(seen) + stderr


def test_input_is_confirmed_by_a_line_on_stdin(tmp_path: Path) -> None:
    path = mission(tmp_path, "  - {x: -1.0, y: -0.5, tasks: [{input: {prompt: Load it}}]}\n")
    out = tmp_path / "out"
    stderr = confirm_when_asked(["run", str(path), "--out", str(out)], tmp_path, "Load it")
    assert "Load it — press Enter to go on" in stderr
    (task,) = report(out)["visits"][0]["tasks"]
    assert (task["kind"], task["outcome"], task["detail"]) == (
        "input",
        "succeeded",
        "confirmed in the terminal",
    )


def in_process(tmp_path: Path, path: Path, react: Any, **options: Any) -> dict[str, Any]:
    """Run ``path`` on the simulator in this process; ``react(event, control, runner)``
    sees every event. Returns the report."""
    control = MissionControl()
    session = prepare(
        RunRequest(
            mission=path,
            outputs=Outputs(folder=tmp_path / "out", picture=False),
            tasks=TaskOptions(**options),
        )
    )
    runner = session.task_runner = TaskRunner(session.request.tasks, say=lambda line: None)

    def listener(event: MissionEvent) -> None:
        react(event, control, runner)

    session.run([listener], control=control)
    return report(tmp_path / "out")


def test_the_api_confirms_an_input_task(tmp_path: Path) -> None:
    path = mission(tmp_path, "  - {x: -1.0, y: -0.5, tasks: [{input: {prompt: ok?}}]}\n")
    answered: list[bool] = []

    def react(event: MissionEvent, control: MissionControl, runner: TaskRunner) -> None:
        if isinstance(event, TaskStarted):
            answered.append(runner.confirm())

    written = in_process(tmp_path, path, react)
    assert answered == [True]
    assert written["visits"][0]["tasks"][0]["detail"] == "confirmed"


def test_skip_during_a_task_cancels_it_and_goes_on(tmp_path: Path) -> None:
    path = mission(
        tmp_path,
        "  - {x: -1.0, y: -0.5, tasks: [{wait: 1000}]}\n  - {x: -2.0, y: -0.5}\n",
    )

    def react(event: MissionEvent, control: MissionControl, runner: TaskRunner) -> None:
        if isinstance(event, TaskStarted):
            control.request_skip()

    visits = in_process(tmp_path, path, react)["visits"]
    assert visits[0]["outcome"] == "skipped"
    assert [t["outcome"] for t in visits[0]["tasks"]] == ["cancelled"]
    assert visits[1]["outcome"] == "reached"


def test_pause_during_a_task_cancels_it_and_resume_runs_it_again(tmp_path: Path) -> None:
    path = mission(tmp_path, "  - {x: -1.0, y: -0.5, tasks: [{wait: 3}]}\n")
    seen: list[int] = []

    def react(event: MissionEvent, control: MissionControl, runner: TaskRunner) -> None:
        if isinstance(event, TaskStarted):
            seen.append(event.task)
            if len(seen) == 1:
                control.request("pause", timeout=None)
                control.request("resume", timeout=None)

    visits = in_process(tmp_path, path, react)["visits"]
    assert seen == [1, 1]
    assert visits[0]["outcome"] == "reached"
    assert [(t["outcome"], t["duration_s"]) for t in visits[0]["tasks"]] == [("succeeded", 3.0)]


def test_a_task_running_at_a_crash_runs_again_on_resume_a_finished_one_does_not(
    tmp_path: Path,
) -> None:
    # The program sleeps the first time (navseq is killed meanwhile), not the second.
    program = (
        "import os, time; first = not os.path.exists('marker'); open('marker', 'a').write('x');"
        " open('pid', 'w').write(str(os.getpid())); time.sleep(60 if first else 0)"
    )
    path = mission(
        tmp_path,
        f"""\
  - x: -1.0
    y: -0.5
    tasks:
      - wait: 1
      - run: {{argv: [{PY}, -c, "{program}"]}}
  - {{x: -2.0, y: -0.5}}
""",
    )
    out = tmp_path / "out"
    journal = out / "journal.jsonl"
    process = start_navseq("run", path, "--allow-run", "--out", out, cwd=tmp_path)
    try:
        wait_for(lambda: (tmp_path / "pid").exists(), 60, "the run task")
        wait_for(
            lambda: any(
                r.get("type") == "TaskStarted" and r["task"] == 2 for r in journal_records(journal)
            ),
            60,
            "the journal's TaskStarted",
        )
    finally:
        process.kill()
        process.communicate(timeout=30)
        _kill(tmp_path / "pid")
    resumed = navseq("run", "--resume", journal, "--allow-run", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    records = journal_records(journal)
    after = records[next(i for i, r in enumerate(records) if r.get("kind") == "resumed") :]
    assert [r["task"] for r in after if r.get("type") == "TaskStarted"] == [2]
    assert (tmp_path / "marker").read_text() == "xx"  # ran twice: killed, then again
    assert report(out)["success"] is True
    # The report tells of the task before the crash too.
    tasks = report(out)["visits"][0]["tasks"]
    assert [(t["number"], t["kind"], t["outcome"]) for t in tasks] == [
        (1, "wait", "succeeded"),
        (2, "run", "succeeded"),
    ]


def _kill(pid_file: Path) -> None:
    """Stop the orphaned program of the killed run (it runs in a session of its own)."""
    with contextlib.suppress(OSError, ValueError):
        os.kill(int(pid_file.read_text()), signal.SIGKILL)


def test_task_options_refuse_a_negative_simulated_time() -> None:
    with pytest.raises(NavseqError, match="simulate_ros_s"):
        TaskOptions(simulate_ros_s=-1.0)


def test_the_example_mission_runs_on_the_simulator(tmp_path: Path) -> None:
    out = tmp_path / "out"
    example = str(REPO / "examples" / "tasks.yaml")
    args = ["run", example, "--allow-run", "--simulate-tasks", "--no-picture", "--out", str(out)]
    confirm_when_asked(args, tmp_path, "Unload the tray")
    kinds = [[t["kind"] for t in visit["tasks"]] for visit in report(out)["visits"]]
    assert kinds == [["call", "run"], ["wait"], ["input"]]
    # The report rebuilt from the journal lists the same tasks.
    written = report(out)
    (out / "report.json").unlink()
    assert navseq("report", out, cwd=tmp_path).returncode == 0
    assert [v["tasks"] for v in report(out)["visits"]] == [v["tasks"] for v in written["visits"]]


@pytest.mark.ros
def test_a_ros1_run_refuses_an_unknown_message_type_before_connecting(tmp_path: Path) -> None:
    path = write_mission(
        tmp_path / "m.yaml",
        "  - {x: 1, y: 0, tasks: [{publish: {topic: /a, type: std_msgs/Emptyish}}]}\n",
    )
    # No rosmaster anywhere: the type is refused before navseq looks for one.
    done = navseq("run", path, "--navigator", "ros1", "--out", tmp_path / "out", cwd=tmp_path)
    assert_clean_error(done)
    assert (
        "m.yaml:3, waypoint 1, task 1 (publish): message type std_msgs/Emptyish cannot be "
        "loaded here" in done.stderr
    )
    assert not (tmp_path / "out").exists()
