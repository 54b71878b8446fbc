"""The studio's fleets: a fleet run started, watched and stopped from the page's API, and
a past fleet run replayed on one clock (docs/studio.md, "Fleets")."""

from __future__ import annotations

import itertools
import json
import math
import shutil
import time
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from cli_support import navseq
from navseq.studio.app import StudioConfig, create_app
from navseq.studio.fleet_replay import ROBOT_COLOURS, fleet_replay_of
from navseq.studio.fleet_runs import STOPPED_BY
from navseq.studio.security import FileRoots

REPO = Path(__file__).resolve().parents[1]
TOKEN = "test-token"
LOCAL = "http://127.0.0.1:8765"
ENDED = ("completed", "failed", "stopped", "error")


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    return tmp_path


def make_client(workspace: Path, fleet: str | None = "examples/fleet.yaml") -> TestClient:
    mission = (workspace / "examples/turtlebot3_world.yaml").resolve()
    roots = FileRoots([mission.parent, workspace / "maps"], mission.parent)
    config = StudioConfig(
        token=TOKEN,
        roots=roots,
        mission_path=mission,
        out_base=workspace / "out",
        fleet_path=None if fleet is None else (workspace / fleet).resolve(),
    )
    return TestClient(create_app(config), base_url=LOCAL, headers={"x-navseq-token": TOKEN})


def wait_for_fleet(client: TestClient, timeout: float = 120.0) -> list[dict]:
    """Every snapshot seen until the fleet run ended (the last one is its end)."""
    seen: list[dict] = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = client.get("/api/fleet/run").json()
        seen.append(state)
        if state["status"] in ENDED:
            return seen
        time.sleep(0.05)
    raise AssertionError(f"the fleet run did not end within {timeout} s: {seen[-1]}")


def test_the_robot_colours_are_those_of_fleet_png() -> None:
    """fleet.png draws robot k in matplotlib's colour "Ck"; the page uses the same."""
    from matplotlib.colors import to_hex

    assert list(ROBOT_COLOURS) == [to_hex(f"C{k}") for k in range(10)]


def test_a_fleet_run_from_the_studio_is_navseq_run_fleets_and_is_watched_live(
    workspace: Path,
) -> None:
    client = make_client(workspace)
    fleets = client.get("/api/fleets").json()
    assert fleets["chosen"] == "fleet.yaml" and "fleet.yaml" in fleets["fleets"]
    assert "turtlebot3_world.yaml" not in fleets["fleets"]  # a mission is not a fleet
    started = client.post("/api/fleet/run", json={"fleet": "fleet.yaml"})
    assert started.status_code == 200, started.json()
    seen = wait_for_fleet(client)
    end = seen[-1]
    assert end["status"] == "completed", end
    assert [robot["name"] for robot in end["robots"]] == ["alpha", "beta", "gamma"]
    assert (end["reached"], end["skipped"], end["failed"], end["waypoints"]) == (7, 0, 0, 7)
    assert all(robot["state"] == "done" for robot in end["robots"])
    assert [robot["colour"] for robot in end["robots"]] == list(ROBOT_COLOURS[:3])
    for robot in end["robots"]:
        assert robot["waypoint_states"] == ["reached"] * robot["waypoints"]
        assert robot["pose"] is not None and len(robot["footprint_m"]) >= 3
    # While it ran: every robot's pose, and each robot's waypoint and state.
    running = [state for state in seen if state["status"] == "running"]
    assert running and all(r["pose"] is not None for s in running for r in s["robots"])
    assert any(r["state"] == "driving" and r["current_label"] for s in running for r in s["robots"])
    # The folder is navseq run --fleet's: a folder per robot, the fleet's report and picture.
    folder = workspace / "out" / end["folder"]
    assert folder.parent == workspace / "out/navseq-out"
    names = {path.name for path in folder.iterdir()}
    assert {"fleet-run.json", "fleet-report.json", "fleet.png", "alpha", "beta", "gamma"} <= names
    report = json.loads((folder / "fleet-report.json").read_text())
    assert report == end["report"] and report["reached"] == 7
    assert end["makespan_s"] == pytest.approx(report["makespan_s"], abs=0.15)
    # The runs list has it once, with its robots and waypoints, not its robots' folders.
    runs = client.get("/api/runs").json()["runs"]
    assert [(r["folder"], r["fleet"], r["robots"], r["reached"], r["visits"]) for r in runs] == [
        (end["folder"], True, 3, 7, 7)
    ]


def test_stop_ends_every_robots_mission_as_an_operators_cancel(workspace: Path) -> None:
    client = make_client(workspace)
    assert client.post("/api/fleet/run", json={"realtime": 1}).status_code == 200
    again = client.post("/api/fleet/run", json={})
    assert again.status_code == 409  # one fleet run at a time
    mission = client.get("/api/mission").json()["mission"]
    assert client.post("/api/run", json={"mission": mission}).status_code == 409
    deadline = time.monotonic() + 30
    while client.get("/api/fleet/run").json()["clock_s"] < 1.0:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    assert client.post("/api/fleet/run/stop").status_code == 200
    end = wait_for_fleet(client)[-1]
    assert end["status"] == "stopped"
    assert end["report"]["interrupted"] == STOPPED_BY and end["reached"] < 7
    states = [state for robot in end["robots"] for state in robot["waypoint_states"]]
    assert "stopped" in states and "failed" not in states
    assert client.post("/api/fleet/run/stop").status_code == 409  # over already


def test_a_fleet_that_cannot_run_is_refused_with_every_problem_and_leaves_nothing(
    workspace: Path,
) -> None:
    bad = workspace / "examples/crowded.yaml"
    bad.write_text(
        "navseq_fleet: 1\nmission: turtlebot3_world.yaml\nrobots:\n"
        "  - {name: a, start: {x: -2.0, y: -0.5, yaw: 0}}\n"
        "  - {name: b, start: {x: -2.0, y: -0.5, yaw: 0}}\n"
        "  - {name: c, start: {x: 1.0, y: 0.0, yaw: 0}}\n"
    )
    client = make_client(workspace, fleet=None)
    assert "crowded.yaml" in client.get("/api/fleets").json()["fleets"]
    answer = client.post("/api/fleet/run", json={"fleet": "crowded.yaml"})
    assert answer.status_code == 422
    texts = [problem["text"] for problem in answer.json()["problems"]]
    assert len(texts) >= 2 and all("crowded.yaml" in text for text in texts), texts
    assert not list((workspace / "out").glob("navseq-out/*"))
    assert client.get("/api/fleet/run").status_code == 404
    outside = client.post("/api/fleet/run", json={"fleet": "../../../etc/passwd"})
    assert outside.status_code == 422 and "outside" in outside.json()["error"]


@pytest.fixture(scope="module")
def fleet_run_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """examples/fleet.yaml run by navseq run --fleet, as a user runs it."""
    workspace = tmp_path_factory.mktemp("fleet")
    shutil.copytree(REPO / "examples", workspace / "examples")
    shutil.copytree(REPO / "maps", workspace / "maps")
    out = workspace / "navseq-out/tour"
    done = navseq("run", "--fleet", "examples/fleet.yaml", "--out", out, cwd=workspace)
    assert done.returncode == 0, done.stderr
    return out


def test_a_fleet_replay_draws_only_journaled_poses_on_one_clock_never_through_a_wall(
    fleet_run_folder: Path,
) -> None:
    """Every replayed pose of every robot is one its journal holds, at the fleet clock's
    time it was journaled; the trail between two stays off the arena's walls."""
    from navseq.executor import events as ev
    from navseq.journal.reader import journal_events
    from navseq.sim.occupancy import load_map

    root = fleet_run_folder.parent.parent
    replay = fleet_replay_of(fleet_run_folder, "tour", root, lambda path: True)
    robots = {robot["name"]: robot for robot in replay["robots"]}
    assert list(robots) == ["alpha", "beta", "gamma"]
    assert [robot["colour"] for robot in robots.values()] == list(ROBOT_COLOURS[:3])
    grid = load_map(REPO / "maps/turtlebot3_world.yaml")
    occupied = grid.occupied_mask()
    for name, robot in robots.items():
        journaled = [
            (event.t, event.x, event.y)
            for event in journal_events(fleet_run_folder / name / "journal.jsonl")
            if isinstance(event, ev.WaypointProgress)
        ]
        poses = robot["replay"]["poses"]
        assert len(poses) == len(journaled) >= 2
        for (t, x, y, _), (jt, jx, jy) in zip(poses, journaled, strict=True):
            assert t == pytest.approx(jt, abs=0.002)  # the fleet's clock: all start at 0
            assert math.dist((x, y), (jx, jy)) <= 0.05
        for (_, x0, y0, _), (_, x1, y1, _) in itertools.pairwise(poses):
            steps = max(2, int(math.dist((x0, y0), (x1, y1)) / 0.01))
            for k in range(steps + 1):
                cell = grid.world_to_cell(x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps)
                assert not occupied[cell], f"{name}'s trail crosses a wall at {x0:.2f},{y0:.2f}"
        states = robot["replay"]["states"]
        assert [t["t"] for t in states] == sorted(t["t"] for t in states)
        assert robot["report"]["reached"] == robot["report"]["waypoints"]
    report = json.loads((fleet_run_folder / "fleet-report.json").read_text())
    assert replay["duration_s"] == pytest.approx(report["makespan_s"], abs=0.15)
    assert replay["map"] is not None and replay["map"].endswith("turtlebot3_world.yaml")


def test_the_replay_api_reads_fleet_run_folders_only(workspace: Path) -> None:
    client = make_client(workspace)
    out = workspace / "out/navseq-out/tour"
    done = navseq("run", "--fleet", "examples/fleet.yaml", "--out", out, cwd=workspace)
    assert done.returncode == 0, done.stderr
    answer = client.get("/api/fleet/replay", params={"folder": "navseq-out/tour"})
    assert answer.status_code == 200
    replay = answer.json()
    assert replay["fleet"] is True and len(replay["robots"]) == 3
    assert replay["map"] == "../maps/turtlebot3_world.yaml"  # as the page loads maps
    assert client.get("/api/map", params={"map": replay["map"]}).status_code == 200
    robot = client.get("/api/fleet/replay", params={"folder": "navseq-out/tour/alpha"})
    assert robot.status_code == 404 and "fleet-run.json" in robot.json()["error"]
    assert client.get("/api/fleet/replay", params={"folder": "../../.."}).status_code == 422
    assert client.get("/api/fleet/replay").status_code == 400


def test_a_robot_with_no_share_is_replayed_parked_where_the_fleet_put_it(tmp_path: Path) -> None:
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    fleet = tmp_path / "pair.yaml"
    fleet.write_text(
        "navseq_fleet: 1\nmap: maps/turtlebot3_world.yaml\n"
        "mission: {waypoints: [{name: p, x: -1.0, y: -0.5, yaw: 0}]}\nrobots:\n"
        "  - {name: a, start: {x: -2.0, y: -0.5, yaw: 0}}\n"
        "  - {name: b, start: {x: 0.5, y: 2.0, yaw: -90}}\n"
        "waypoints:\n  p: {robots: [a]}\n"
    )
    out = tmp_path / "navseq-out/pair"
    done = navseq("run", "--fleet", fleet, "--out", out, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    replay = fleet_replay_of(out, "pair", tmp_path, lambda path: True)
    a, b = replay["robots"]
    assert a["replay"] is not None and a["parked"] is None
    assert b["replay"] is None and b["report"]["waypoints"] == 0
    assert b["parked"]["pose"] == pytest.approx([0.5, 2.0, -90.0])
    assert len(b["parked"]["footprint_m"]) >= 3
    # Not readable (outside the studio's folders): no pose rather than a guess.
    assert fleet_replay_of(out, "pair", tmp_path, lambda path: False)["robots"][1]["parked"] is None


def test_a_resumed_fleet_run_replays_forward_through_the_resume(tmp_path: Path) -> None:
    """The simulator's clock starts at 0 again in a resumed run: the replay lays the
    resumed part after the part before, so every robot's timeline goes forward."""
    import signal

    from cli_support import TURTLEBOT3_MAP, journal_events, journal_records, start_navseq, wait_for

    (tmp_path / "mission.yaml").write_text(
        "navseq: 1\nwaypoints:\n"
        "  - {name: east-dock, x: 1.75, y: -0.55, yaw: 90}\n"
        "  - {name: inner-east, x: 0.55, y: 0.55, yaw: 180}\n"
        "  - {name: north-dock, x: 0.0, y: 1.75, yaw: 180}\n"
    )
    fleet = tmp_path / "fleet.yaml"
    fleet.write_text(
        f"navseq_fleet: 1\nmission: mission.yaml\nmap: {TURTLEBOT3_MAP}\nrobots:\n"
        "  - {name: b, start: {x: 2.0, y: 0.5, yaw: 180}}\n"
    )
    run = tmp_path / "run"
    process = start_navseq("run", "--fleet", fleet, "--out", run, "--realtime", "2", cwd=tmp_path)
    try:
        journal = run / "b" / "journal.jsonl"
        wait_for(
            lambda: journal.exists() and journal_events(journal, "WaypointFinished"),
            60,
            "robot b's first arrival",
        )
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert navseq("run", "--fleet", fleet, "--resume", run, cwd=tmp_path).returncode == 0
    raw = [r["t"] for r in journal_records(run / "b" / "journal.jsonl") if "t" in r]
    assert any(b < a for a, b in itertools.pairwise(raw))  # the clock went back at the resume
    replay = fleet_replay_of(run, "run", tmp_path, lambda path: True)["robots"][0]["replay"]
    times = [pose[0] for pose in replay["poses"]]
    assert times == sorted(times) and len(times) >= 4
    changes = [state["t"] for state in replay["states"]]
    assert changes == sorted(changes)
    report = json.loads((run / "fleet-report.json").read_text())
    assert replay["duration_s"] == pytest.approx(report["makespan_s"], abs=0.5)


def test_navseq_studio_refuses_a_missing_fleet_or_one_outside_root_in_one_line(
    workspace: Path,
) -> None:
    missing = navseq("studio", "--fleet", "nope.yaml", "--no-browser", cwd=workspace)
    assert missing.returncode == 2 and "Traceback" not in missing.stderr
    assert missing.stderr.strip() == "navseq studio: --fleet: no such file: nope.yaml"
    outside = navseq(
        "studio", "--fleet", "examples/fleet.yaml", "--root", "maps", "--no-browser", cwd=workspace
    )
    assert outside.returncode == 2 and "Traceback" not in outside.stderr
    assert outside.stderr.startswith("navseq studio: --fleet: ") and "--root" in outside.stderr
