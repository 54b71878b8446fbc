"""Writing missions: readable navseq YAML, never clobbering what the user has."""

import math
import os
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

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
from navseq.mission.writer import dump_mission_yaml_slowly, yaw_degrees_for_file

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


# --- the waypoints' lines are written as PyYAML writes them, without PyYAML ------------

_NAMES = st.one_of(
    st.none(),
    st.sampled_from(
        [
            *("dock", "wp7", "dock 1", "a.b-c_d", "Küche", "yes", "no", "on", "null", "true"),
            *("~", "7", "1.5", "1e3", "0x1F", "1:30", "2001-12-14", "", " x", "x ", "a  b"),
            *("a: b", "a #b", "#x", "-x", "- x", "[x]", "{x}", "x,y", "'q'", '"q"', "it's"),
            *("a\tb", "\u00e9t\u00e9", "\u2028", "\x85", "\ufeffx", "x" * 256, "<<", "=", "!x"),
        ]
    ),
    st.text(max_size=12),
    st.from_regex(r"\w{1,6}(?:[ .-]\w{1,6}){0,3}", fullmatch=True),  # the written-plain shape
)
_OVERRIDES = st.fixed_dictionaries(
    {},
    optional={
        "goal_timeout_s": st.floats(0.1, 1e5),
        "retries": st.integers(0, 5),
        "clear_costmaps_on_retry": st.booleans(),
        "on_failure": st.sampled_from(list(FailureAction)),
        "pass_through_m": st.floats(0.01, 5.0),
        "dwell_s": st.floats(0.0, 100.0),
        "yaw_tolerance_deg": st.floats(0.1, 90.0),
    },
)
_COORDINATES = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6)


@st.composite
def _waypoints(draw: st.DrawFn) -> Waypoint:
    yaw = draw(st.one_of(st.integers(-180, 180), st.floats(-180, 180), st.just(1e-300)))
    return Waypoint(
        draw(_COORDINATES),
        draw(st.one_of(_COORDINATES, st.sampled_from([-0.0, 5e-324, 1e16, 1e-5, 123456789.0]))),
        yaw_deg=yaw,
        z=draw(st.sampled_from([0.0, 0.5, -1e-7])),
        name=draw(_NAMES),
        overrides=draw(_OVERRIDES),
    )


@settings(max_examples=300, deadline=None)
@given(st.lists(_waypoints(), min_size=1, max_size=6))
def test_the_fast_waypoint_lines_are_exactly_what_pyyaml_writes(waypoints: list[Waypoint]) -> None:
    mission = Mission(waypoints=tuple(waypoints))
    assert dump_mission_yaml(mission) == dump_mission_yaml_slowly(mission)


def test_a_large_conversion_writes_every_waypoint_right(tmp_path: Path) -> None:
    from cli_support import navseq

    source = tmp_path / "patrol.yaml"
    source.write_text(
        "navseq: 1\nwaypoints:\n"
        + "".join(
            f"  - {{name: wp{i}, x: {i * 0.001:.3f}, y: -{i % 977}.25, yaw: {i % 360 - 179}}}\n"
            for i in range(100_000)
        )
        + "  - {name: 'dock yes', x: 1e3, y: 2, dwell: 5, on_failure: skip}\n"
    )
    target = tmp_path / "converted.yaml"
    result = navseq("convert", source, target, cwd=tmp_path, timeout=300)
    assert result.returncode == 0, result.stderr
    original, converted = load_mission(source), load_mission(target)
    assert converted.waypoints == original.waypoints
    text = target.read_text()
    assert text.count("\n  - {name: wp") == 100_000
    assert text.endswith(
        "  - {name: dock yes, x: 1000.0, y: 2.0, yaw: 0, on_failure: skip, dwell: 5.0}\n"
    )
    head = Mission(waypoints=original.waypoints[:3000] + original.waypoints[-1:])
    assert dump_mission_yaml(head) == dump_mission_yaml_slowly(head)


def test_the_waypoints_of_a_plain_mission_do_not_go_through_pyyamls_emitter(monkeypatch):
    """PyYAML spent some 120 µs on each waypoint (12-25 s for 100 000): it writes the
    settings only, whatever the mission's size (the text is the same, see above)."""
    from navseq.mission import writer

    represented = []
    real = writer._MissionDumper.represent_scalar

    def counting(dumper, tag, value, style=None):
        represented.append(value)
        return real(dumper, tag, value, style)

    monkeypatch.setattr(writer._MissionDumper, "represent_scalar", counting)
    mission = Mission(
        waypoints=tuple(Waypoint(i * 0.5, -i, yaw_deg=i % 360, name=f"wp {i}") for i in range(1000))
    )
    text = dump_mission_yaml(mission)
    assert len(represented) < 50  # the settings' keys and values
    monkeypatch.undo()
    assert text == dump_mission_yaml_slowly(mission)
