"""The studio offers a mission's keepout and speed zones as a map overlay, and shows
GPS waypoints in map coordinates."""

from __future__ import annotations

import io
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from starlette.testclient import TestClient

from navseq.studio.app import StudioConfig, create_app
from navseq.studio.security import FileRoots

REPO = Path(__file__).resolve().parents[1]
TOKEN = "test-token"


def client_for(workspace: Path, mission: str) -> TestClient:
    mission_path = (workspace / mission).resolve()
    roots = FileRoots([mission_path.parent, workspace / "maps"], mission_path.parent)
    config = StudioConfig(
        token=TOKEN, roots=roots, mission_path=mission_path, out_base=workspace / "out"
    )
    return TestClient(
        create_app(config), base_url="http://127.0.0.1:8765", headers={"x-navseq-token": TOKEN}
    )


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    return tmp_path


def zones_image(client: TestClient) -> np.ndarray:
    map_text = "../maps/turtlebot3_world.yaml"  # the mission's map:, as the page sends it
    answer = client.get("/api/map/image", params={"layer": "zones", "map": map_text})
    assert answer.status_code == 200, answer.text
    assert answer.headers["content-type"] == "image/png"
    return np.asarray(Image.open(io.BytesIO(answer.content)).convert("RGBA"))


def test_the_zones_overlay_shows_the_missions_keepout_and_speed_zones(workspace: Path) -> None:
    pixels = zones_image(client_for(workspace, "examples/keepout.yaml"))
    visible = pixels[..., 3] > 0
    red = visible & (pixels[..., 0] > 200) & (pixels[..., 1] < 80)
    amber = visible & (pixels[..., 0] > 200) & (pixels[..., 1] > 120) & (pixels[..., 2] < 40)
    # The keepout zone: 0.8 m x ~1.15 m at 5 cm cells; the speed zone 1.5 m square.
    assert 300 < red.sum() < 450
    assert 800 < amber.sum() < 950
    plain = zones_image(client_for(workspace, "examples/turtlebot3_world.yaml"))
    assert not (plain[..., 3] > 0).any()  # no filters: nothing drawn


def test_gps_waypoints_open_in_map_coordinates(workspace: Path) -> None:
    answer = client_for(workspace, "examples/gps.yaml").get("/api/mission")
    assert answer.status_code == 200, answer.text
    waypoints = answer.json()["mission"]["waypoints"]
    assert waypoints[0]["x"] == pytest.approx(-0.55, abs=0.01)
    assert waypoints[0]["y"] == pytest.approx(-1.75, abs=0.01)
    assert "latitude" not in waypoints[0]


def test_a_draft_with_filters_is_checked_against_its_keepout_zone(workspace: Path) -> None:
    client = client_for(workspace, "examples/keepout.yaml")
    document = client.get("/api/mission").json()["mission"]
    answer = client.post("/api/check", json={"mission": document})
    assert answer.status_code == 200, answer.text
    assert answer.json()["problems"] == []
    document["waypoints"][0].update(x=0.55, y=-1.75)  # into the keepout zone
    problems = client.post("/api/check", json={"mission": document}).json()["problems"]
    assert len(problems) == 1 and "is in a keepout zone" in problems[0]["text"]
    assert problems[0]["fix"] is not None  # the nearest allowed spot, one click away
