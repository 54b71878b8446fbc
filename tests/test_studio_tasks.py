"""The studio and the waypoints' tasks: a run's input task confirmed (or refused) from the
page, what a run's tasks may do, the report as soon as it is written, tasks kept through
a save, and the one-click fix of a misplaced waypoint (docs/studio.md)."""

from __future__ import annotations

import json
import math
import shutil
import time
from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient

from navseq.executor import events as ev
from navseq.mission import load_mission
from navseq.mission.tasks import InputTask, WaitTask
from navseq.studio.app import StudioConfig, create_app
from navseq.studio.runs import LiveView
from navseq.studio.security import FileRoots
from test_studio_api import LOCAL, PILLAR, REPO, TOKEN, make_client, opened, wait_for_run


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    return tmp_path


@pytest.fixture
def client(workspace: Path) -> TestClient:
    return make_client(workspace)


def tasks_client(workspace: Path, *, allow_run: bool = False) -> TestClient:
    mission_path = (workspace / "examples/turtlebot3_world.yaml").resolve()
    roots = FileRoots([mission_path.parent, workspace / "maps"], mission_path.parent)
    config = StudioConfig(
        token=TOKEN,
        roots=roots,
        mission_path=mission_path,
        out_base=workspace / "out",
        allow_run=allow_run,
    )
    return TestClient(create_app(config), base_url=LOCAL, headers={"x-navseq-token": TOKEN})


def with_tasks(client: TestClient, tasks: list[dict[str, Any]], at: int = 1) -> dict[str, Any]:
    """The opened mission cut to its first three waypoints, ``tasks`` at waypoint ``at``."""
    document = opened(client)["mission"]
    document["waypoints"] = document["waypoints"][:3]
    document["waypoints"][at]["tasks"] = tasks
    return document


def wait_for_task(client: TestClient, timeout: float = 60.0) -> dict[str, Any]:
    """The run's state once an input task waits for its answer."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = client.get("/api/run").json()
        if state["task"] is not None and state["task"]["asks"]:
            return state
        assert state["status"] not in ("completed", "failed", "stopped", "error"), state
        time.sleep(0.05)
    raise AssertionError(f"no input task waited within {timeout} s")


def test_confirm_answers_the_input_task_and_the_report_lists_it(client: TestClient) -> None:
    document = with_tasks(client, [{"input": {"prompt": "Load the tray"}}])
    assert client.post("/api/run", json={"mission": document}).status_code == 200
    state = wait_for_task(client)
    assert state["current"] is None or state["task"]["index"] == 1
    assert state["task"]["description"] == "input: Load the tray"
    assert state["task"]["kind"] == "input" and state["task"]["index"] == 1
    assert state["waypoints"][2] == "pending"  # the run waits at waypoint 2
    answer = client.post("/api/run/confirm", json={"confirmed": True})
    assert answer.status_code == 200, answer.json()
    again = client.post("/api/run/confirm", json={"confirmed": True})
    assert again.status_code == 409  # answered already: nothing waits now
    state = wait_for_run(client)
    assert state["status"] == "completed", state
    (task,) = state["report"]["visits"][1]["tasks"]
    assert task["kind"] == "input" and task["outcome"] == "succeeded"
    assert task["detail"] == "confirmed in the studio"
    assert state["last_task"]["outcome"] == "succeeded" and state["task"] is None


def test_refuse_fails_the_task_and_the_waypoints_policy_follows(client: TestClient) -> None:
    document = with_tasks(client, [{"input": {"prompt": "Is the dock clear?"}}])
    document["waypoints"][1].update(on_failure="skip", retries=0)
    assert client.post("/api/run", json={"mission": document}).status_code == 200
    wait_for_task(client)
    assert client.post("/api/run/confirm", json={"confirmed": False}).status_code == 200
    state = wait_for_run(client)
    visit = state["report"]["visits"][1]
    assert visit["outcome"] == "skipped"
    assert visit["tasks"][0]["outcome"] == "failed"
    assert visit["tasks"][0]["detail"] == "refused in the studio"
    assert state["report"]["visits"][2]["outcome"] == "reached"  # the run went on


def test_confirm_with_no_input_task_waiting_is_refused(client: TestClient) -> None:
    assert client.post("/api/run/confirm", json={"confirmed": True}).status_code == 404  # no run
    document = with_tasks(client, [{"wait": 1}])
    assert client.post("/api/run", json={"mission": document}).status_code == 200
    state = wait_for_run(client)
    assert state["status"] == "completed"
    answer = client.post("/api/run/confirm", json={"confirmed": True})
    assert answer.status_code == 409
    assert "no input task waits" in answer.json()["message"]
    # Only JSON, and a yes or no.
    assert client.post("/api/run/confirm", json={"confirmed": "yes"}).status_code == 400
    form = client.post(
        "/api/run/confirm", content=b"confirmed=1", headers={"content-type": "text/plain"}
    )
    assert form.status_code == 415
    bare = TestClient(client.app, base_url=LOCAL)
    assert bare.post("/api/run/confirm", json={"confirmed": True}).status_code == 403


def test_the_page_cannot_let_a_run_start_programs_unless_the_studio_allows_it(
    workspace: Path,
) -> None:
    program = [{"run": {"argv": ["python3", "-c", "print('scanned')"]}}]
    refusing = make_client(workspace)
    document = with_tasks(refusing, program)
    answer = refusing.post("/api/run", json={"mission": document, "allow_run": True})
    assert answer.status_code == 422
    (problem,) = answer.json()["problems"]
    assert problem["waypoint"] == 1 and "--allow-run" in problem["message"]
    allowing = tasks_client(workspace, allow_run=True)
    assert opened(allowing)["allow_run"] is True and opened(refusing)["allow_run"] is False
    assert allowing.post("/api/run", json={"mission": document}).status_code == 200
    state = wait_for_run(allowing)
    (task,) = state["report"]["visits"][1]["tasks"]
    assert task["outcome"] == "succeeded" and task["output"] == ["scanned"]


def test_ros_tasks_run_on_the_simulator_only_when_simulated(client: TestClient) -> None:
    document = with_tasks(client, [{"call": {"service": "/dock/open"}}])
    refused = client.post("/api/run", json={"mission": document})
    assert refused.status_code == 422
    assert "--simulate-tasks" in refused.json()["problems"][0]["message"]
    assert (
        client.post("/api/run", json={"mission": document, "simulate_tasks": "on"}).status_code
        == 400
    )
    started = client.post("/api/run", json={"mission": document, "simulate_tasks": True})
    assert started.status_code == 200
    state = wait_for_run(client)
    (task,) = state["report"]["visits"][1]["tasks"]
    assert task["kind"] == "call" and task["outcome"] == "succeeded"


def test_the_live_view_says_which_task_runs_and_how_the_last_ended() -> None:
    view = LiveView(2, footprint=[])
    view(ev.MissionStarted(t=0.0, waypoint_count=2, loops=None))
    view(ev.TaskStarted(1.0, 1, 0, 2, "input", 1, "input: Load the tray"))
    shown = view.snapshot()["task"]
    assert shown["index"] == 1 and shown["number"] == 2 and shown["asks"]
    assert shown["description"] == "input: Load the tray"
    assert view.take_answer() and not view.take_answer()  # one answer per prompt
    view(ev.TaskFinished(4.0, 1, 0, 2, "input", 1, "succeeded", 3.0, "confirmed"))
    snapshot = view.snapshot()
    assert snapshot["task"] is None and not view.take_answer()
    assert snapshot["last_task"]["outcome"] == "succeeded"
    assert snapshot["last_task"]["duration_s"] == 3.0


def test_the_report_is_shown_once_written_before_the_picture(tmp_path: Path) -> None:
    view = LiveView(1, footprint=[])
    view.folder_path = tmp_path
    view(ev.MissionStarted(t=0.0, waypoint_count=1, loops=None))
    view(ev.MissionFinished(t=5.0, success=True, reason="completed"))
    assert view.snapshot()["report"] is None  # finishing: nothing written yet
    (tmp_path / "report.json").write_text(json.dumps({"totals": {"reached": 1}}))
    snapshot = view.snapshot()
    assert snapshot["status"] == "finishing"  # the picture is still being drawn
    assert snapshot["report"] == {"totals": {"reached": 1}}


def test_tasks_edited_in_the_page_are_saved_and_the_rest_of_the_file_kept(
    client: TestClient, workspace: Path
) -> None:
    path = workspace / "examples/turtlebot3_world.yaml"
    body = opened(client)
    document = body["mission"]
    document["waypoints"][1]["tasks"] = [
        {"wait": 5},
        {"input": {"prompt": "Load the tray"}, "timeout": 120},
        {"call": {"service": "/dock/open", "type": "std_srvs/Trigger"}},
    ]
    answer = client.post(
        "/api/save",
        json={"mission": document, "version": body["version"], "overwrite": True},
    )
    assert answer.status_code == 200, answer.json()
    assert answer.json()["kept_formatting"] is True
    assert "# s for one attempt at a waypoint" in path.read_text()  # comments kept
    mission = load_mission(path)
    tasks = mission.waypoints[1].overrides["tasks"]
    assert tasks[:2] == (WaitTask(5.0), InputTask("Load the tray", timeout_s=120.0))
    assert tasks[2].kind == "call"
    # Opened again, the page gets the same tasks back; a reorder saves as well.
    again = opened(client)
    assert again["mission"]["waypoints"][1]["tasks"][1] == {
        "input": {"prompt": "Load the tray"},
        "timeout": 120.0,
    }
    document = again["mission"]
    document["waypoints"][1]["tasks"].reverse()
    answer = client.post(
        "/api/save",
        json={"mission": document, "version": again["version"], "overwrite": True},
    )
    assert answer.status_code == 200
    kinds = [task.kind for task in load_mission(path).waypoints[1].overrides["tasks"]]
    assert kinds == ["call", "input", "wait"]


def test_a_task_problem_is_shown_with_its_waypoint(client: TestClient) -> None:
    document = opened(client)["mission"]
    document["waypoints"][2]["tasks"] = [{"wait": -1}]
    answer = client.post("/api/check", json={"mission": document}).json()
    assert [problem["waypoint"] for problem in answer["problems"]] == [2]


@pytest.mark.parametrize("where", ["waypoint", "start"])
def test_a_misplaced_point_comes_with_the_nearest_free_spot_to_move_it_to(
    client: TestClient, where: str
) -> None:
    document = opened(client)["mission"]
    point = document["start"] if where == "start" else document["waypoints"][3]
    point.update(x=PILLAR[0], y=PILLAR[1])
    (problem,) = client.post("/api/check", json={"mission": document}).json()["problems"]
    fix = problem["fix"]
    assert fix is not None and "nearest free spot" in problem["message"]
    assert math.dist((fix["x"], fix["y"]), PILLAR) < 0.5  # close by
    point.update(x=fix["x"], y=fix["y"])  # what the page's button does
    assert client.post("/api/check", json={"mission": document}).json()["problems"] == []


def test_a_problem_without_a_spot_to_move_to_has_no_fix(client: TestClient) -> None:
    document = opened(client)["mission"]
    document["waypoints"][0]["yaw"] = "north"
    problems = client.post("/api/check", json={"mission": document}).json()["problems"]
    assert problems and all(problem["fix"] is None for problem in problems)


def test_a_task_without_a_time_limit_leaves_the_route_without_an_upper_bound(
    client: TestClient,
) -> None:
    document = opened(client)["mission"]
    document["waypoints"][1]["tasks"] = [{"input": {"prompt": "Load the tray"}}]
    answer = client.post("/api/check", json={"mission": document})
    assert answer.status_code == 200  # was a 500: an infinite bound is no JSON number
    assert answer.json()["upper_bound_s"] is None
    assert "no upper bound" in answer.json()["estimated_duration"]
