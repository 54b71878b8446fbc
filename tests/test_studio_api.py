"""navseq studio's JSON API, in process with Starlette's test client (docs/studio.md)."""

from __future__ import annotations

import difflib
import itertools
import json
import shutil
import time
from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient

from cli_support import navseq
from navseq.journal.writer import HEARTBEAT
from navseq.mission import load_mission
from navseq.studio.app import MAX_BODY_BYTES, StudioConfig, create_app
from navseq.studio.security import FileRoots, allowed_hosts, host_allowed

REPO = Path(__file__).resolve().parents[1]
TOKEN = "test-token"
LOCAL = "http://127.0.0.1:8765"
JSON_BODY = {"content-type": "application/json"}
PILLAR = (1.0, 0.0)  # on the west face of the arena's middle east pillar (an occupied cell)


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    return tmp_path


def make_client(workspace: Path, mission: str = "examples/turtlebot3_world.yaml") -> TestClient:
    mission_path = (workspace / mission).resolve()
    roots = FileRoots([mission_path.parent, workspace / "maps"], mission_path.parent)
    config = StudioConfig(
        token=TOKEN, roots=roots, mission_path=mission_path, out_base=workspace / "out"
    )
    return TestClient(create_app(config), base_url=LOCAL, headers={"x-navseq-token": TOKEN})


@pytest.fixture
def client(workspace: Path) -> TestClient:
    return make_client(workspace)


def opened(client: TestClient) -> dict:
    answer = client.get("/api/mission")
    assert answer.status_code == 200
    return answer.json()


def test_every_request_needs_the_token(client: TestClient) -> None:
    bare = TestClient(client.app, base_url=LOCAL)
    for path in ("/", "/api/mission", "/static/studio.js", "/api/map"):
        answer = bare.get(path)
        assert answer.status_code == 403, path
        assert "token" in answer.json()["error"]
    assert bare.get("/api/mission", headers={"x-navseq-token": "wrong"}).status_code == 403
    # The page's URL sets a cookie that carries the token from then on.
    page = bare.get(f"/?token={TOKEN}")
    assert page.status_code == 200 and "navseq studio" in page.text
    assert bare.get("/api/mission").status_code == 200


def test_a_post_from_another_origin_is_refused(client: TestClient) -> None:
    answer = client.post(
        "/api/check", json={"mission": {}}, headers={"origin": "http://evil.example"}
    )
    assert answer.status_code == 403


def test_a_request_for_a_foreign_host_name_is_refused_even_with_the_token(
    client: TestClient,
) -> None:
    """DNS rebinding: a page at evil.example made to resolve to 127.0.0.1 sends its own
    name as Host and as Origin, so the origin check alone would let it through."""
    foreign = {"host": "evil.example:8765", "origin": "http://evil.example:8765"}
    answer = client.post("/api/check", json={"mission": {}}, headers=foreign)
    assert answer.status_code == 403
    assert "this machine" in answer.json()["error"]
    for host in ("evil.example", "10.0.0.7:8765", "127.0.0.2"):
        assert client.get("/api/mission", headers={"host": host}).status_code == 403, host
    for host in ("localhost:8765", "127.0.0.1:8765", "[::1]:8765", "LOCALHOST"):
        assert client.get("/api/mission", headers={"host": host}).status_code == 200, host


@pytest.mark.parametrize(
    ("listen", "host", "allowed"),
    [
        ("127.0.0.1", "my-laptop.local:8765", False),
        ("my-laptop.local", "my-laptop.local:8765", True),  # --host given by name
        ("192.168.1.5", "192.168.1.5:8765", True),
        ("192.168.1.5", "192.168.1.6:8765", False),
        ("0.0.0.0", "192.168.1.6:8765", True),  # every interface: any of its addresses
        ("0.0.0.0", "evil.example:8765", False),  # ... but never a name
    ],
)
def test_the_hosts_a_request_may_name_follow_host(listen: str, host: str, allowed: bool) -> None:
    assert host_allowed(host, allowed_hosts(listen)) is allowed


def test_a_body_not_declared_json_is_refused(client: TestClient) -> None:
    """A cross-site form may post text/plain without a preflight: only JSON is taken."""
    answer = client.post(
        "/api/check", content=b'{"mission": {}}', headers={"content-type": "text/plain"}
    )
    assert answer.status_code == 415
    assert "application/json" in answer.json()["error"]
    assert client.post("/api/check", json={"mission": {}}).status_code != 415


def test_every_answer_keeps_the_page_out_of_frames_and_foreign_code_out_of_the_page(
    client: TestClient,
) -> None:
    bare = TestClient(client.app, base_url=LOCAL)
    answers = [client.get("/"), client.get("/static/studio.js"), client.get("/api/mission")]
    answers.append(bare.get("/api/mission"))  # refused for want of the token: still headed
    for answer in answers:
        policy = answer.headers["content-security-policy"]
        assert "frame-ancestors 'none'" in policy and "script-src 'self'" in policy
        assert answer.headers["x-content-type-options"] == "nosniff"
        assert answer.headers["referrer-policy"] == "no-referrer"


def test_the_mission_comes_as_its_document_with_units_and_version(
    client: TestClient, workspace: Path
) -> None:
    body = opened(client)
    mission = body["mission"]
    assert body["units"]["yaw"] == "deg" and body["units"]["x"] == "m"
    assert len(mission["waypoints"]) == 7
    assert mission["waypoints"][1] == {"name": "east-dock", "x": 1.75, "y": -0.55, "yaw": 90}
    assert mission["map"] == "../maps/turtlebot3_world.yaml"
    data = (workspace / "examples/turtlebot3_world.yaml").read_bytes()
    import hashlib

    assert body["version"]["sha256"] == hashlib.sha256(data).hexdigest()
    assert body["problems"] == []


def test_the_map_and_its_costmap_are_served_in_metres(client: TestClient) -> None:
    info = client.get("/api/map", params={"map": "../maps/turtlebot3_world.yaml"}).json()
    assert info["resolution_m"] == 0.05
    assert info["bounds_m"]["xmin"] == -10.0 and info["width_cells"] == 384
    for layer in ("map", "costmap"):
        image = client.get(
            "/api/map/image", params={"map": "../maps/turtlebot3_world.yaml", "layer": layer}
        )
        assert image.status_code == 200 and image.content.startswith(b"\x89PNG")
        from io import BytesIO

        from PIL import Image

        assert Image.open(BytesIO(image.content)).size == (384, 384)


def test_a_checked_draft_gets_validate_problems_and_planned_legs(client: TestClient) -> None:
    document = opened(client)["mission"]
    answer = client.post("/api/check", json={"mission": document}).json()
    assert answer["problems"] == []
    assert len(answer["legs"]) == 7  # start -> 1, then 1 -> 2 ... 6 -> 7
    assert all(leg["length_m"] > 0 and len(leg["points"]) >= 2 for leg in answer["legs"])
    assert answer["total_length_m"] == pytest.approx(sum(leg["length_m"] for leg in answer["legs"]))
    assert answer["estimated_duration"].startswith("~1 min")  # the ETA, as navseq plan says
    assert answer["upper_bound_s"] >= answer["expected_duration_s"] > 50.0

    document["waypoints"][2].update(x=PILLAR[0], y=PILLAR[1])
    answer = client.post("/api/check", json={"mission": document}).json()
    assert [problem["waypoint"] for problem in answer["problems"]] == [2]
    problem = answer["problems"][0]
    assert problem["text"].startswith(
        "turtlebot3_world.yaml, waypoint 3 'inner-east': at (1.00, 0.00)"
    )
    assert "obstacle" in problem["message"]


def test_the_shortest_order_is_that_of_navseq_plan(client: TestClient, workspace: Path) -> None:
    document = opened(client)["mission"]
    answer = client.post("/api/order", json={"mission": document, "keep_last": True})
    assert answer.status_code == 200, answer.text
    found = answer.json()
    assert sorted(found["order"]) == list(range(7)) and found["order"][-1] == 6
    assert found["length_m"] < found["length_before_m"]
    mission = workspace / "examples/turtlebot3_world.yaml"
    plan = navseq("plan", mission, "--order", "shortest", "--keep-last", "--json", cwd=workspace)
    route = json.loads(plan.stdout)
    assert [index + 1 for index in found["order"]] == route["order"]
    assert found["length_m"] == route["length_m"]
    # A draft that does not read, or a bad option: a 4xx that says why.
    document["waypoints"][0]["x"] = "oops"
    refused = client.post("/api/order", json={"mission": document})
    assert refused.status_code == 422 and refused.json()["problems"]
    assert client.post("/api/order", json={"mission": {}, "keep_last": "yes"}).status_code == 400


def test_the_draft_problems_are_those_of_navseq_validate(
    client: TestClient, workspace: Path
) -> None:
    from navseq.commands.validate import mission_file_problems

    document = opened(client)["mission"]
    document["waypoints"][0]["x"] = PILLAR[0]
    document["waypoints"][0]["y"] = PILLAR[1]
    document["waypoints"][4]["retries"] = -2
    answer = client.post("/api/check", json={"mission": document}).json()
    # The same draft written as a file and checked by validate's own function.
    path = workspace / "examples/edited.yaml"
    path.write_text(json.dumps(document), encoding="utf-8")
    _, errors = mission_file_problems(path)
    assert [p["message"] for p in answer["problems"]] == [e.message for e in errors]
    assert answer["readable"] is False
    # The file problem first, then pre-flight of the waypoints that did read (as validate).
    assert [p["waypoint"] for p in answer["problems"]] == [4, 0]


@pytest.mark.parametrize(
    ("body", "status", "said"),
    [
        (b"{not json", 400, "not valid JSON"),
        (b"[1, 2]", 400, "JSON object"),
        (b'{"mission": [1]}', 400, "JSON object"),
        (b'{"mission": {"waypoints": []}}', 400, "navseq: 1"),
        (b"\xff\xfe", 400, "UTF-8"),
    ],
)
def test_bad_requests_get_a_4xx_with_a_message(
    client: TestClient, body: bytes, status: int, said: str
) -> None:
    answer = client.post("/api/check", content=body, headers=JSON_BODY)
    assert answer.status_code == status
    assert said in answer.json()["error"]


def test_a_body_over_the_limit_is_refused(client: TestClient) -> None:
    answer = client.post("/api/check", content=b" " * (MAX_BODY_BYTES + 1))
    assert answer.status_code == 413


def test_files_outside_the_studios_folders_are_refused(client: TestClient, workspace: Path) -> None:
    document = opened(client)["mission"]
    outside = workspace / "elsewhere"
    outside.mkdir()
    shutil.copy(workspace / "maps/turtlebot3_world.yaml", outside / "m.yaml")
    (workspace / "examples/link.yaml").symlink_to(outside / "m.yaml")
    for map_text in ("../../elsewhere/m.yaml", str(outside / "m.yaml"), "link.yaml", "/etc/passwd"):
        answer = client.post("/api/check", json={"mission": {**document, "map": map_text}})
        assert answer.status_code == 422, map_text
        assert "outside the folders the studio may use" in answer.json()["error"]
        assert client.get("/api/map", params={"map": map_text}).status_code == 422
    for path in ("../../elsewhere/new.yaml", "/tmp/new.yaml"):
        answer = client.post("/api/save", json={"mission": document, "path": path})
        assert answer.status_code == 422 and "outside" in answer.json()["error"]
    assert not (outside / "new.yaml").exists()


def test_save_replaces_the_opened_file_only_when_confirmed(
    client: TestClient, workspace: Path
) -> None:
    body = opened(client)
    document, version = body["mission"], body["version"]
    document["waypoints"].append({"x": 0.5, "y": -1.6, "yaw": 45, "name": "added"})
    answer = client.post("/api/save", json={"mission": document, "version": version})
    assert answer.status_code == 409 and answer.json()["conflict"] == "exists"
    path = workspace / "examples/turtlebot3_world.yaml"
    assert len(load_mission(path).waypoints) == 7  # unchanged
    answer = client.post(
        "/api/save", json={"mission": document, "version": version, "overwrite": True}
    )
    assert answer.status_code == 200
    saved = load_mission(path)
    assert [w.name for w in saved.waypoints][-1] == "added"
    assert saved.waypoints[-1].yaw_deg == pytest.approx(45)
    assert saved.map == (workspace / "maps/turtlebot3_world.yaml").resolve()
    assert "map: ../maps/turtlebot3_world.yaml" in path.read_text()
    assert answer.json()["version"] == opened(client)["version"]


def test_a_stale_version_is_a_conflict_and_nothing_is_lost(
    client: TestClient, workspace: Path
) -> None:
    first_tab, second_tab = opened(client), opened(client)
    first_tab["mission"]["waypoints"][0]["name"] = "first"
    second_tab["mission"]["waypoints"][0]["name"] = "second"
    ok = client.post(
        "/api/save",
        json={"mission": first_tab["mission"], "version": first_tab["version"], "overwrite": True},
    )
    assert ok.status_code == 200
    stale = client.post(
        "/api/save",
        json={
            "mission": second_tab["mission"],
            "version": second_tab["version"],
            "overwrite": True,
        },
    )
    assert stale.status_code == 409 and stale.json()["conflict"] == "changed"
    assert "changed on disk since it was opened" in stale.json()["error"]
    assert load_mission(workspace / "examples/turtlebot3_world.yaml").waypoints[0].name == "first"


def save_edited(client: TestClient, path: Path, edit: Any) -> list[str]:
    """Open, ``edit(document)``, save over the file; the unified diff of the file."""
    before = path.read_text()
    body = opened(client)
    edit(body["mission"])
    answer = client.post(
        "/api/save",
        json={"mission": body["mission"], "version": body["version"], "overwrite": True},
    )
    assert answer.status_code == 200, answer.json()
    assert answer.json()["kept_formatting"] is True
    return [
        line
        for line in difflib.unified_diff(before.splitlines(), path.read_text().splitlines(), n=0)
        if line[:1] in "+-" and line[:3] not in ("+++", "---")
    ]


def test_save_changes_only_the_lines_of_what_was_edited(
    client: TestClient, workspace: Path
) -> None:
    """The example is commented, aligned and written with integers: one field edited,
    one line changes, its comment kept."""
    path = workspace / "examples/turtlebot3_world.yaml"

    def move_east_dock(document: dict) -> None:
        document["waypoints"][1]["x"] = 1.7

    assert save_edited(client, path, move_east_dock) == [
        "-  - {name: east-dock, x: 1.75, y: -0.55, yaw: 90}",
        "+  - {name: east-dock, x: 1.7, y: -0.55, yaw: 90}",
    ]

    def shorter_timeout(document: dict) -> None:
        document["defaults"]["goal_timeout"] = 90

    assert save_edited(client, path, shorter_timeout) == [
        "-  goal_timeout: 120        # s for one attempt at a waypoint",
        "+  goal_timeout: 90         # s for one attempt at a waypoint",  # comment column kept
    ]
    assert load_mission(path).waypoints[1].x == pytest.approx(1.7)


def test_recoveries_added_to_the_defaults_save_as_one_line_the_way_files_write_them(
    client: TestClient, workspace: Path
) -> None:
    path = workspace / "examples/turtlebot3_world.yaml"

    def add_recovery(document: dict) -> None:
        document["defaults"]["recovery"] = [{"spin": 90}, {"backup": 0.15}, "clear_costmaps"]

    assert save_edited(client, path, add_recovery) == [
        "+  recovery: [spin: 90, backup: 0.15, clear_costmaps]"
    ]
    recoveries = load_mission(path).defaults.recoveries
    assert [(r.kind, r.amount) for r in recoveries] == [
        ("spin", 90.0),
        ("backup", 0.15),
        ("clear_costmaps", None),
    ]
    # Opened again, the page gets the list back as it saved it.
    assert opened(client)["mission"]["defaults"]["recovery"] == [
        {"spin": 90},
        {"backup": 0.15},
        "clear_costmaps",
    ]


def test_inserting_and_deleting_waypoints_leaves_the_others_and_comments_alone(
    client: TestClient, workspace: Path
) -> None:
    path = workspace / "examples/turtlebot3_world.yaml"
    text = path.read_text().replace(
        "yaw: 90}\n", "yaw: 90}   # the dock's charger faces north\n", 1
    )
    path.write_text(text)

    def insert_and_delete(document: dict) -> None:
        document["waypoints"].insert(1, {"name": "new", "x": 0.5, "y": -1.6, "yaw": 45})
        del document["waypoints"][4]  # north-dock, now fifth

    assert save_edited(client, path, insert_and_delete) == [
        "+  - {name: new, x: 0.5, y: -1.6, yaw: 45}",
        "-  - {name: north-dock, x: 0.0, y: 1.75, yaw: 180}",
    ]
    assert "# the dock's charger faces north" in path.read_text()
    names = [w.name for w in load_mission(path).waypoints]
    assert names == [
        "south-gate",
        "new",
        "east-dock",
        "inner-east",
        "west-gate",
        "inner-west",
        "home",
    ]


def test_save_as_a_new_file_and_a_mission_with_pre_flight_problems(
    client: TestClient, workspace: Path
) -> None:
    document = opened(client)["mission"]
    document["waypoints"][0].update(x=PILLAR[0], y=PILLAR[1])
    answer = client.post("/api/save", json={"mission": document, "path": "copy.yaml"})
    assert answer.status_code == 200
    assert len(answer.json()["problems"]) == 1  # saved, and said
    assert load_mission(workspace / "examples/copy.yaml").waypoints[0].x == PILLAR[0]
    document["waypoints"][0]["yaw"] = "north"
    answer = client.post("/api/save", json={"mission": document, "path": "bad.yaml"})
    assert answer.status_code == 422 and answer.json()["problems"]
    assert not (workspace / "examples/bad.yaml").exists()


@pytest.mark.parametrize(
    ("target", "said"),
    [
        ("../maps/turtlebot3_world.yaml", "a map_server map"),
        ("tutorial_params.yaml", "a ROS parameter file"),
    ],
)
def test_save_as_never_replaces_a_file_that_is_not_a_navseq_mission(
    client: TestClient, workspace: Path, target: str, said: str
) -> None:
    """Even confirmed: a map saved over with a mission is a broken map."""
    document = opened(client)["mission"]
    path = workspace / "examples" / target
    before = path.read_bytes()
    answer = client.post("/api/save", json={"mission": document, "path": target, "overwrite": True})
    assert answer.status_code == 409
    assert said in answer.json()["error"] and "nothing was written" in answer.json()["error"]
    assert path.read_bytes() == before


def wait_for_run(client: TestClient, timeout: float = 60.0) -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        state = client.get("/api/run").json()
        if state["status"] in ("completed", "failed", "stopped", "error"):
            return state
        time.sleep(0.05)
    raise AssertionError(f"the run did not end within {timeout} s: {state}")


def test_a_run_writes_the_usual_output_folder(client: TestClient, workspace: Path) -> None:
    document = opened(client)["mission"]
    started = client.post("/api/run", json={"mission": document})
    assert started.status_code == 200
    state = wait_for_run(client)
    assert state["status"] == "completed", state
    assert state["waypoints"] == ["reached"] * 7
    folder = workspace / "out" / state["folder"]
    assert folder.parent == workspace / "out/navseq-out"
    names = {path.name for path in folder.iterdir()}
    assert {"journal.jsonl", "report.json", "mission.png", "turtlebot3_world.yaml"} <= names
    report = json.loads((folder / "report.json").read_text())
    assert report["totals"]["reached"] == 7 and report == state["report"]
    assert len(state["trail"]) > 50 and state["pose"] is not None
    assert state["eta_s"] == 0.0  # over: nothing left to go
    assert report["eta"]["actual_s"] == report["totals"]["duration_s"]  # the ETA was kept
    # The folder is navseq run's own: navseq report rebuilds from its journal.
    from navseq.journal.writer import read_journal

    assert read_journal(folder / "journal.jsonl").mission_started is not None


def test_a_run_with_pre_flight_problems_is_refused_with_them(client: TestClient) -> None:
    document = opened(client)["mission"]
    document["waypoints"][3].update(x=PILLAR[0], y=PILLAR[1])
    answer = client.post("/api/run", json={"mission": document})
    assert answer.status_code == 422
    assert [p["waypoint"] for p in answer.json()["problems"]] == [3]
    assert client.get("/api/run").status_code == 404


def test_stop_cancels_the_goal_and_the_report_is_written(client: TestClient) -> None:
    document = opened(client)["mission"]
    assert client.post("/api/run", json={"mission": document, "realtime": 2}).status_code == 200
    again = client.post("/api/run", json={"mission": document})
    assert again.status_code == 409  # one run at a time
    time.sleep(1.0)
    paused = client.post("/api/run/pause").json()
    assert paused["ok"] and client.get("/api/run").json()["status"] == "paused"
    assert client.post("/api/run/resume").json()["ok"]
    stopped = client.post("/api/run/stop").json()
    assert stopped["ok"], stopped
    state = wait_for_run(client)
    assert state["status"] == "stopped"
    assert state["report"]["reason"] == "cancelled by the operator (the studio)"
    assert state["report"]["totals"]["reached"] < 7
    # The waypoint being driven to was stopped, not failed by the robot.
    assert "failed" not in state["waypoints"] and "stopped" in state["waypoints"]
    assert client.post("/api/run/stop").status_code == 409  # nothing left to stop


def test_the_live_view_streams_server_sent_events(client: TestClient) -> None:
    document = opened(client)["mission"]
    assert client.post("/api/run", json={"mission": document}).status_code == 200
    snapshots = []
    with client.stream("GET", "/api/run/events") as stream:
        assert stream.headers["content-type"].startswith("text/event-stream")
        for line in stream.iter_lines():
            if line.startswith("data: "):
                snapshots.append(json.loads(line[6:]))
    assert snapshots[-1]["status"] == "completed"  # the stream ends with the run
    assert snapshots[-1]["report"]["totals"]["reached"] == 7
    assert len(snapshots[-1]["footprint_m"]) >= 3


def test_a_new_mission_on_a_map(workspace: Path) -> None:
    mission_path = workspace / "examples/new.yaml"
    roots = FileRoots([mission_path.parent, workspace / "maps"], mission_path.parent)
    config = StudioConfig(
        token=TOKEN,
        roots=roots,
        mission_path=mission_path,
        map_path=(workspace / "maps/turtlebot3_world.yaml").resolve(),
    )
    client = TestClient(create_app(config), base_url=LOCAL, headers={"x-navseq-token": TOKEN})
    body = client.get("/api/mission").json()
    assert body["exists"] is False and body["mission"]["waypoints"] == []
    document = body["mission"]
    document["waypoints"] = [{"x": -0.55, "y": -1.75, "yaw": 0}]
    answer = client.post("/api/save", json={"mission": document, "version": None})
    assert answer.status_code == 200
    assert load_mission(mission_path).waypoints[0].x == -0.55


# --- performance on big maps: the costmap is built once per (map, robot) --------------


def test_validate_checks_against_a_costmap_it_is_given(workspace: Path) -> None:
    """The core's ``costmaps`` parameter: pre-flight uses the costmap it hands back."""
    from navseq.commands.common import costmap_for_robot
    from navseq.commands.validate import mission_file_problems
    from navseq.sim.occupancy import OccupancyGrid

    path = workspace / "examples/turtlebot3_world.yaml"
    asked: list[tuple[Path, str]] = []

    def walled(map_path: Path, robot: object) -> object:
        # The arena's map with every cell occupied: every waypoint is in an obstacle.
        asked.append((map_path, robot.name))  # type: ignore[attr-defined]
        from navseq.sim.occupancy import load_map

        grid = load_map(map_path)
        full = OccupancyGrid(grid.data * 0 + 100, grid.resolution, grid.origin, grid.source)
        return costmap_for_robot(full)

    _, plain = mission_file_problems(path)
    _, errors = mission_file_problems(path, costmaps=walled)  # type: ignore[arg-type]
    assert plain == []
    assert asked == [((workspace / "maps/turtlebot3_world.yaml").resolve(), "turtlebot3_burger")]
    assert len(errors) == 8 and all("obstacle" in error.message for error in errors)


def test_checks_inflate_the_map_once_until_its_file_changes(
    client: TestClient, workspace: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import navseq.commands.common as common

    built: list[object] = []
    real = common.costmap_for_robot

    def counting(grid: object, robot: object = None) -> object:
        built.append(robot)
        return real(grid, robot)  # type: ignore[arg-type]

    monkeypatch.setattr(common, "costmap_for_robot", counting)
    document = opened(client)["mission"]
    for step in range(4):  # a drag: the same mission, one waypoint moved a little each time
        document["waypoints"][2]["x"] = 0.55 + 0.01 * step
        assert client.post("/api/check", json={"mission": document}).json()["problems"] == []
    assert len(built) == 1
    # Another robot is another costmap; the first one is still kept.
    document["robot"] = "turtlebot3_waffle"
    client.post("/api/check", json={"mission": document})
    del document["robot"]
    client.post("/api/check", json={"mission": document})
    assert len(built) == 2
    # The map's image changes on disk (a wall drawn over the third waypoint): the next
    # check reads it again and says so.
    import numpy as np
    from PIL import Image

    image_path = workspace / "maps/turtlebot3_world.pgm"
    pixels = np.array(Image.open(image_path))
    # The image's top row is y = -10 + 384 * 0.05 = 9.2 m; x starts at -10 m.
    row, col = round((9.2 - 0.55) / 0.05), round((0.58 + 10.0) / 0.05)  # (0.58, 0.55)
    pixels[row - 4 : row + 4, col - 4 : col + 4] = 0
    Image.fromarray(pixels).save(image_path)
    answer = client.post("/api/check", json={"mission": document}).json()
    assert len(built) == 3
    assert [problem["waypoint"] for problem in answer["problems"]] == [2]


def test_the_images_show_the_map_greys_and_where_the_centre_may_not_be(
    client: TestClient, workspace: Path
) -> None:
    from io import BytesIO

    import numpy as np
    from PIL import Image

    from navseq.commands.common import costmap_for_map
    from navseq.sim.costmap import INSCRIBED, LETHAL

    query = {"map": "../maps/turtlebot3_world.yaml"}
    shown = Image.open(BytesIO(client.get("/api/map/image", params=query).content))
    grey = np.array(shown.convert("L"))[::-1]  # the image's top row is the map's last
    costmap = costmap_for_map(workspace / "maps/turtlebot3_world.yaml")
    data = costmap.grid.data
    assert set(np.unique(grey[data == 0])) == {254}  # map_server's free
    assert set(np.unique(grey[data == 100])) == {0}  # occupied
    assert set(np.unique(grey[data < 0])) == {205}  # unknown
    overlay = Image.open(
        BytesIO(client.get("/api/map/image", params={**query, "layer": "costmap"}).content)
    )
    rgba = np.array(overlay.convert("RGBA"))[::-1]
    no_centre = (costmap.planning_cost >= INSCRIBED) & (costmap.cost < LETHAL)
    assert no_centre.any()
    assert (rgba[no_centre] == (220, 40, 40, 150)).all()  # red: the centre may not go
    assert (rgba[costmap.cost >= LETHAL][:, 3] == 0).all()  # obstacles: the map shows them
    assert (rgba[costmap.cost == 0][:, 3] == 0).all()  # free of cost: clear


def test_the_map_image_does_not_wait_for_a_costmap_being_built(
    client: TestClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The page's first paint needs the map's PNG; the costmap and plans of the first
    check (seconds on a big map) are made beside it, not before it."""
    import threading

    import navseq.commands.common as common

    inflating, release = threading.Event(), threading.Event()
    real = common.costmap_for_robot

    def slow(grid: object, robot: object = None) -> object:
        inflating.set()
        assert release.wait(30)
        return real(grid, robot)  # type: ignore[arg-type]

    monkeypatch.setattr(common, "costmap_for_robot", slow)
    document = opened(client)["mission"]
    answers: list[dict] = []
    checking = threading.Thread(
        target=lambda: answers.append(client.post("/api/check", json={"mission": document}).json())
    )
    checking.start()
    try:
        assert inflating.wait(30)
        # Would hang until release (30 s, then fail) if the image waited for it.
        image = client.get("/api/map/image", params={"map": "../maps/turtlebot3_world.yaml"})
        assert image.status_code == 200 and image.content.startswith(b"\x89PNG")
        assert answers == []  # the check is still waiting for its costmap
    finally:
        release.set()
        checking.join(30)
    assert len(answers[0]["legs"]) == 7


def test_warm_up_makes_the_map_image_before_the_first_check(
    workspace: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from navseq.studio import mapview
    from navseq.studio.app import Studio

    mission_path = (workspace / "examples/turtlebot3_world.yaml").resolve()
    roots = FileRoots([mission_path.parent, workspace / "maps"], mission_path.parent)
    studio = Studio(StudioConfig(token=TOKEN, roots=roots, mission_path=mission_path))
    done: list[str] = []
    real_png, real_check = mapview.map_png, studio.check
    monkeypatch.setattr(mapview, "map_png", lambda grid: done.append("map image") or real_png(grid))
    monkeypatch.setattr(
        studio, "check", lambda document, base=None: done.append("check") or real_check(document)
    )
    studio.warm_up()  # no page to wait for
    assert done == ["map image", "check"]
    # What the page then asks for is made already.
    monkeypatch.setattr(mapview, "map_png", lambda grid: pytest.fail("made twice"))
    assert studio.map_image("../maps/turtlebot3_world.yaml", "map").startswith(b"\x89PNG")


def test_a_draft_checked_again_unchanged_gets_the_same_answer_without_a_new_check(
    client: TestClient, workspace: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each page load's first check sends the opened mission as the warm-up checked it:
    the answer is sent again, until the draft or its map file changes."""
    import os

    import navseq.studio.app as app

    checked: list[object] = []
    real = app.check_draft

    def counting(document: object, **kwargs: object) -> object:
        checked.append(document)
        return real(document, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(app, "check_draft", counting)
    document = opened(client)["mission"]
    first = client.post("/api/check", json={"mission": document}).json()
    assert client.post("/api/check", json={"mission": document}).json() == first
    assert len(checked) == 1
    document["waypoints"][2]["x"] = 0.56
    moved = client.post("/api/check", json={"mission": document}).json()
    assert len(checked) == 2  # a new draft: checked
    # The map's image is touched on disk: the same draft is checked again.
    image = workspace / "maps/turtlebot3_world.pgm"
    stat = image.stat()
    os.utime(image, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))
    again = client.post("/api/check", json={"mission": document}).json()
    assert again["check"] > moved["check"]  # a new answer, the same as the last one
    assert {**again, "check": 0} == {**moved, "check": 0}
    assert len(checked) == 3


# --- files: import, export, the robot: section ------------------------------------------


def test_the_import_list_offers_every_format_the_loader_reads(client: TestClient) -> None:
    missions = client.get("/api/files").json()["missions"]
    assert {
        "tutorial_move_base_seq.launch",
        "tutorial_params.yaml",
        "recorded.csv",
        "patrol.yaml",
        "turtlebot3_world.yaml",
    } <= set(missions)


@pytest.mark.parametrize(
    ("name", "count", "first"),
    [
        ("tutorial_move_base_seq.launch", 3, {"x": -1.0, "y": -4.0, "yaw": 90}),
        ("tutorial_params.yaml", 4, {"x": -1.6, "y": -0.5, "yaw": -30}),
        ("recorded.csv", 5, {"x": -1.6, "y": -0.5}),
    ],
)
def test_the_tutorials_files_import_as_documents(
    client: TestClient, name: str, count: int, first: dict
) -> None:
    answer = client.post("/api/import", json={"path": name})
    assert answer.status_code == 200, answer.text
    body = answer.json()
    assert body["path"] == name and body["problems"] == []
    waypoints = body["mission"]["waypoints"]
    assert len(waypoints) == count
    for key, value in first.items():
        assert waypoints[0][key] == pytest.approx(value)
    # The document checks like any other (a tutorial file names no map: no pre-flight).
    assert client.post("/api/check", json={"mission": body["mission"]}).json()["readable"]


def test_nav2s_waypoint_files_import_as_documents(client: TestClient, workspace: Path) -> None:
    (workspace / "examples/wp.yaml.yaml").write_text(
        "waypoints:\n  waypoint0:\n    pose: [-1.6, -0.5, 0.0]\n"
        "    orientation: [0.7071068, 0.0, 0.0, 0.7071068]\n",
        encoding="utf-8",
    )
    pose = "- position: {x: %s, y: 0.5, z: 0.0}\n  orientation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}\n"
    echo = "header: {frame_id: map}\nposes:\n"
    (workspace / "examples/poses.yaml").write_text(
        f"{echo}{pose % 9.0}---\n{echo}{pose % 1.6}---\n", encoding="utf-8"
    )
    panel = client.post("/api/import", json={"path": "wp.yaml.yaml"})
    assert panel.status_code == 200, panel.text
    [waypoint] = panel.json()["mission"]["waypoints"]
    assert (waypoint["x"], waypoint["y"], waypoint["yaw"]) == pytest.approx((-1.6, -0.5, 90.0))
    echoed = client.post("/api/import", json={"path": "poses.yaml"})
    assert echoed.status_code == 200, echoed.text
    assert [w["x"] for w in echoed.json()["mission"]["waypoints"]] == [1.6]  # the last message


def test_a_bad_or_missing_import_is_a_4xx_with_its_problems(
    client: TestClient, workspace: Path
) -> None:
    (workspace / "examples/bad.launch").write_text(
        '<launch><node pkg="p" type="t" name="n"><rosparam param="p_seq">[1, 2]</rosparam>'
        '<rosparam param="yea_seq">[0]</rosparam></node></launch>',
        encoding="utf-8",
    )
    answer = client.post("/api/import", json={"path": "bad.launch"})
    assert answer.status_code == 422
    assert "multiple of 3" in answer.json()["problems"][0]["text"]
    assert client.post("/api/import", json={"path": "nope.csv"}).status_code == 404
    assert client.post("/api/import", json={"path": "/etc/passwd"}).status_code == 422


def test_export_writes_the_tutorials_launch_file_and_says_what_it_leaves_out(
    client: TestClient, workspace: Path
) -> None:
    document = opened(client)["mission"]
    answer = client.post("/api/export", json={"mission": document, "path": "seq.launch"})
    assert answer.status_code == 200, answer.text
    assert answer.json()["path"] == "seq.launch"
    assert "waypoint names" in answer.json()["left_out"]
    exported = load_mission(workspace / "examples/seq.launch")
    assert [(w.x, w.y) for w in exported.waypoints] == [
        (w["x"], w["y"]) for w in document["waypoints"]
    ]
    again = client.post("/api/export", json={"mission": document, "path": "seq.launch"})
    assert again.status_code == 409 and again.json()["conflict"] == "exists"
    confirmed = client.post(
        "/api/export", json={"mission": document, "path": "seq.launch", "overwrite": True}
    )
    assert confirmed.status_code == 200
    wrong = client.post("/api/export", json={"mission": document, "path": "seq.yaml"})
    assert wrong.status_code == 422 and ".launch" in wrong.json()["error"]


def test_a_mission_with_a_robot_section_saves_without_losing_it(
    client: TestClient, workspace: Path
) -> None:
    body = opened(client)
    document = body["mission"]
    document["robot"] = {"base": "turtlebot3_waffle", "radius": 0.2, "max_angular_speed": 90}
    answer = client.post(
        "/api/save",
        json={"mission": document, "version": body["version"], "overwrite": True},
    )
    assert answer.status_code == 200, answer.text
    saved = load_mission(workspace / "examples/turtlebot3_world.yaml")
    assert saved.robot is not None and saved.robot.circumscribed_radius == pytest.approx(0.2)
    # Opened again, the section comes back as written, and saves again unchanged.
    reopened = opened(client)
    assert reopened["mission"]["robot"]["max_angular_speed"] == 90
    again = client.post(
        "/api/save",
        json={"mission": reopened["mission"], "version": reopened["version"], "overwrite": True},
    )
    assert again.status_code == 200
    assert load_mission(workspace / "examples/turtlebot3_world.yaml") == saved


# --- past runs ---------------------------------------------------------------------------


def test_a_past_run_replays_as_a_timeline(client: TestClient, workspace: Path) -> None:
    document = opened(client)["mission"]
    assert client.post("/api/run", json={"mission": document}).status_code == 200
    finished = wait_for_run(client)
    runs = client.get("/api/runs").json()["runs"]
    assert [run["folder"] for run in runs] == [finished["folder"]]
    assert runs[0]["reached"] == 7 and runs[0]["reason"] == "completed"
    replay = client.get("/api/replay", params={"folder": finished["folder"]}).json()
    assert replay["report"] == finished["report"]
    assert len(replay["mission"]["waypoints"]) == 7
    assert replay["duration_s"] == pytest.approx(finished["report"]["totals"]["duration_s"], 0.05)
    times = [pose[0] for pose in replay["poses"]]
    assert times == sorted(times) and times[-1] <= replay["duration_s"]
    # The journal keeps the driven path's corners and the pose at every arrival.
    assert len(replay["poses"]) >= 2 * 7
    assert max(b - a for a, b in itertools.pairwise(times)) <= HEARTBEAT
    # Waypoints go driving -> reached in turn; at the end every one is reached. Each
    # change carries only the waypoints it changed.
    statuses = ["pending"] * 7
    seen: list[list[str]] = []
    for change in replay["states"]:
        assert len(change["changes"]) <= 1
        for index, status in change["changes"]:
            statuses[index] = status
        seen.append(list(statuses))
    assert statuses == ["reached"] * 7
    first_reached = next(state for state in seen if state[0] == "reached")
    assert first_reached[1:] in (["pending"] * 6, ["driving"] + ["pending"] * 5)
    assert replay["plans"] and all(len(plan["points"]) >= 2 for plan in replay["plans"])


def test_replay_refuses_what_is_not_a_run_folder(client: TestClient, workspace: Path) -> None:
    assert client.get("/api/replay", params={"folder": "../../../etc"}).status_code == 422
    (workspace / "out/navseq-out/empty").mkdir(parents=True)
    answer = client.get("/api/replay", params={"folder": "navseq-out/empty"})
    assert answer.status_code == 422 and "journal" in answer.json()["error"]
    assert client.get("/api/replay").status_code == 400
