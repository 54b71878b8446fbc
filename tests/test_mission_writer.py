"""Writing missions: readable navseq YAML, never clobbering what the user has."""

import math
import os
from pathlib import Path

import pytest
import yaml

from navseq.errors import NavseqError
from navseq.geometry import quaternion_to_yaw, yaw_degrees_to_quaternion
from navseq.mission import (
    FailureAction,
    Mission,
    Policy,
    Waypoint,
    dump_mission_yaml,
    load_mission,
    write_mission,
)
from navseq.mission.writer import yaw_degrees_for_file

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def small_mission(**changes) -> Mission:
    fields = {"waypoints": (Waypoint(1.0, 2.0, yaw_deg=90, name="dock"),)}
    fields.update(changes)
    return Mission(**fields)


@pytest.mark.parametrize("degrees", [90, -90, 180, 45, 30, 0, 12.5, 359.9])
def test_yaw_from_a_quaternion_is_written_as_the_degrees_a_person_would_type(degrees):
    yaw = quaternion_to_yaw(*yaw_degrees_to_quaternion(degrees))
    assert yaw_degrees_for_file(yaw) == pytest.approx(
        degrees if degrees <= 180 else degrees - 360, abs=1e-12
    )
    assert len(repr(yaw_degrees_for_file(yaw))) <= len(repr(degrees)) + 1


def test_dump_is_plain_yaml_with_degrees_and_policy_overrides():
    mission = small_mission(
        waypoints=(
            Waypoint(
                1.0,
                2.0,
                yaw_deg=90,
                name="dock",
                overrides={"dwell_s": 5.0, "on_failure": FailureAction.SKIP},
            ),
            Waypoint(3.0, 4.0, yaw_rad=quaternion_to_yaw(0, 0, math.sqrt(0.5), math.sqrt(0.5))),
        ),
        defaults=Policy(goal_timeout_s=60.0),
        loops=None,
    )
    text = dump_mission_yaml(mission)
    doc = yaml.safe_load(text)
    assert doc["loops"] == "forever"
    assert doc["defaults"]["goal_timeout"] == 60.0 and doc["defaults"]["on_failure"] == "stop"
    assert doc["waypoints"] == [
        {"name": "dock", "x": 1.0, "y": 2.0, "yaw": 90, "dwell": 5.0, "on_failure": "skip"},
        {"x": 3.0, "y": 4.0, "yaw": 90},
    ]
    assert "  - {name: dock, x: 1.0, y: 2.0, yaw: 90," in text  # one line per waypoint


@pytest.mark.parametrize(
    "name", ["tutorial_move_base_seq.launch", "tutorial_params.yaml", "recorded.csv", "patrol.yaml"]
)
def test_every_example_converts_to_navseq_yaml_that_loads_the_same(tmp_path, name):
    original = load_mission(EXAMPLES / name)
    target = tmp_path / "converted.yaml"
    write_mission(original, target)
    converted = load_mission(target)
    assert [(w.x, w.y, w.z, w.name) for w in converted.waypoints] == [
        (w.x, w.y, w.z, w.name) for w in original.waypoints
    ]
    assert [w.yaw_rad for w in converted.waypoints] == pytest.approx(
        [w.yaw_rad for w in original.waypoints], abs=1e-7
    )
    assert (converted.defaults, converted.loops, converted.map, converted.start) == (
        original.defaults,
        original.loops,
        original.map,
        original.start,
    )


def test_map_path_is_written_relative_to_the_new_file(tmp_path):
    mission = small_mission(map=(tmp_path / "maps" / "arena.yaml").resolve())
    target = tmp_path / "deep" / "copy.yaml"
    target.parent.mkdir()
    write_mission(mission, target)
    written = yaml.safe_load(target.read_text())["map"]
    assert written == "../maps/arena.yaml"
    assert load_mission(target).map == mission.map


def test_map_path_stays_absolute_when_only_the_root_is_shared(tmp_path):
    mission = small_mission(map=Path("/nonexistent-navseq-maps/arena.yaml"))
    write_mission(mission, tmp_path / "m.yaml")
    written = yaml.safe_load((tmp_path / "m.yaml").read_text())["map"]
    assert written == "/nonexistent-navseq-maps/arena.yaml"


def test_refuses_to_overwrite_an_existing_file(tmp_path):
    target = tmp_path / "mission.yaml"
    target.write_text("my precious notes\n")
    with pytest.raises(NavseqError, match="exists already") as raised:
        write_mission(small_mission(), target)
    assert str(target) in str(raised.value)
    assert target.read_text() == "my precious notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mission.yaml"]  # no leftovers


def test_overwrites_when_asked(tmp_path):
    target = tmp_path / "mission.yaml"
    target.write_text("old\n")
    write_mission(small_mission(), target, overwrite=True)
    assert load_mission(target) == small_mission()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mission.yaml"]


def test_written_file_gets_ordinary_permissions(tmp_path):
    old_mask = os.umask(0o022)
    try:
        write_mission(small_mission(), tmp_path / "m.yaml")
    finally:
        os.umask(old_mask)
    assert (tmp_path / "m.yaml").stat().st_mode & 0o777 == 0o644


def test_a_failed_write_leaves_the_old_file_whole(tmp_path, monkeypatch):
    target = tmp_path / "mission.yaml"
    target.write_text("old\n")

    def full_disk(descriptor):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", full_disk)
    with pytest.raises(NavseqError, match="No space left"):
        write_mission(small_mission(), target, overwrite=True)
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mission.yaml"]


def test_bad_targets(tmp_path):
    with pytest.raises(NavseqError, match="is a folder"):
        write_mission(small_mission(), tmp_path)
    with pytest.raises(NavseqError, match="does not exist"):
        write_mission(small_mission(), tmp_path / "missing" / "m.yaml")
