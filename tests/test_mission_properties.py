"""Property tests: the loaders never fail with anything but NavseqError, whatever they
are fed, and writing a mission then reading it back gives the same mission."""

import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission import (
    FailureAction,
    Mission,
    Policy,
    Waypoint,
    dump_mission_yaml,
    load_mission,
    mission_from_params,
    validate_mission_file,
    write_mission,
)

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
EXTENSIONS = (".yaml", ".launch", ".csv", ".txt")
# Example files plus a few richer samples, so mutations reach every reader's corners.
EXTRA_SAMPLES = {
    "rich.yaml": """navseq: 1
frame: map
start: {x: -2.0, y: -0.5, yaw_rad: 0.1}
loops: 2
server_timeout: null
defaults: &d {goal_timeout: 60, stall_timeout: 20, retries: 2, on_failure: retry}
waypoints:
  - {name: a, x: 1.0, y: 2.0, yaw: 90, <<: *d}
  - {name: b, x: 1e3, y: -2.5, orientation: {x: 0, y: 0, z: 0.7, w: 0.7}}
  - [1, 2, 45]
""",
    "group.launch": """<?xml version="1.0"?>
<launch>
  <group ns="r1" if="true">
    <node pkg="p" type="t" name="seq">
      <param name="p_seq" value="[1, 2, 0, 3, 4, 0]"/>
      <rosparam>
        yea_seq: [0, 90]
        retries: 2
      </rosparam>
    </node>
  </group>
</launch>
""",
    "header.csv": "x,y,z,qx,qy,qz,qw\n1,2,0,0,0,0,1\n\n3,4,0,0,0,0.7,0.7\n",
}
# examples/ also holds files that are not missions: a fleet file and a docks file.
NOT_MISSIONS = {"fleet.yaml", "turtlebot3_docks.yaml"}
SAMPLES = {
    path.name: path.read_bytes()
    for path in sorted(EXAMPLES.iterdir())
    if path.suffix in (".yaml", ".launch", ".csv") and path.name not in NOT_MISSIONS
}
SAMPLES.update({name: text.encode() for name, text in EXTRA_SAMPLES.items()})

FUZZ = settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@pytest.fixture(scope="module")
def scratch():
    with tempfile.TemporaryDirectory() as folder:
        yield Path(folder)


def load_never_crashes(path: Path, data: bytes) -> None:
    """Loading gives a Mission or NavseqError; validate agrees with load."""
    path.write_bytes(data)
    problems = validate_mission_file(path)
    try:
        mission = load_mission(path)
    except NavseqError as error:
        assert problems, f"load raised {error!r} but validate found nothing"
        return
    assert not problems
    assert isinstance(mission, Mission) and len(mission) >= 1


# --- loaders on garbage --------------------------------------------------------------

MISSION_ALPHABET = st.sampled_from(
    [
        *"[]{}:,-&*!<>/=\"'# \n\t0123456789.eE+xyzaw_",
        "p_seq",
        "yea_seq",
        "waypoints",
        "yaw",
        "name",
        "<launch>",
        "</launch>",
        "<rosparam",
        "</rosparam>",
        "<node",
        "<param",
        "value=",
        "param=",
        ".nan",
        ".inf",
        "null",
        "true",
        "forever",
        "loops",
        "defaults",
        "<<",
        "goal_timeout",
        "\xe9",
        "\x00",
        "\x85",
    ]
)


@FUZZ
@given(data=st.binary(max_size=400), extension=st.sampled_from(EXTENSIONS))
def test_arbitrary_bytes(scratch, data, extension):
    load_never_crashes(scratch / f"bytes{extension}", data)


@FUZZ
@given(tokens=st.lists(MISSION_ALPHABET, max_size=80), extension=st.sampled_from(EXTENSIONS))
def test_arbitrary_mission_like_text(scratch, tokens, extension):
    load_never_crashes(scratch / f"text{extension}", "".join(tokens).encode())


def _mutate(data: bytes, draw) -> bytes:
    kind = draw(st.sampled_from(["flip", "truncate", "delete_line", "duplicate_line", "insert"]))
    if not data:
        return data
    if kind == "flip":
        for _ in range(draw(st.integers(1, 4))):
            at = draw(st.integers(0, len(data) - 1))
            data = data[:at] + bytes([data[at] ^ (1 << draw(st.integers(0, 7)))]) + data[at + 1 :]
        return data
    if kind == "truncate":
        return data[: draw(st.integers(0, len(data)))]
    lines = data.splitlines(keepends=True)
    at = draw(st.integers(0, len(lines) - 1))
    if kind == "delete_line":
        return b"".join(lines[:at] + lines[at + 1 :])
    if kind == "duplicate_line":
        return b"".join(lines[: at + 1] + lines[at:])
    token = draw(MISSION_ALPHABET).encode()
    offset = draw(st.integers(0, len(data)))
    return data[:offset] + token + data[offset:]


@FUZZ
@given(name=st.sampled_from(sorted(SAMPLES)), data=st.data())
def test_mutated_valid_files(scratch, name, data):
    mutated = SAMPLES[name]
    for _ in range(data.draw(st.integers(1, 3))):
        mutated = _mutate(mutated, data.draw)
    load_never_crashes(scratch / f"mutated{Path(name).suffix}", mutated)


def test_samples_are_valid_before_mutation(scratch):
    for name, data in SAMPLES.items():
        path = scratch / name
        path.write_bytes(data)
        assert validate_mission_file(path) == [], name


# Text that looks like paths, substitutions and lists reaches the file-naming keys.
PARAM_TEXT = st.text(max_size=8) | st.text(st.sampled_from(list("~/.$()[],1 e\x00")), max_size=8)
PARAM_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | PARAM_TEXT,
    lambda inner: (
        st.lists(inner, max_size=6) | st.dictionaries(st.text(max_size=6), inner, max_size=4)
    ),
    max_leaves=20,
)
PARAM_KEYS = st.sampled_from(
    [
        "p_seq",
        "yea_seq",
        "waypoints",
        "mission",
        "frame",
        "loops",
        "start",
        "goal_timeout",
        "retries",
        "on_failure",
        "dwell",
        "x",
    ]
)


@FUZZ
@given(params=st.dictionaries(PARAM_KEYS, PARAM_VALUES, max_size=4))
def test_arbitrary_params(params):
    try:
        mission = mission_from_params(params)
    except NavseqError:
        return
    assert len(mission) >= 1


# --- dump / load round trip ----------------------------------------------------------

# Coordinates a robot can mean (navseq refuses |x| > 1e6 m).
finite = st.floats(-1e6, 1e6)
# Yaws as people write them: degrees with a few decimals (these must survive exactly);
# navseq keeps yaws in (-180, 180] degrees.
typed_yaw = st.decimals(min_value="-179.9999", max_value=180, places=4).map(
    lambda d: math.radians(float(d))
)
positive = st.floats(min_value=1e-6, max_value=1e6)
policy_values = st.fixed_dictionaries(
    {},
    optional={
        "goal_timeout_s": st.none() | positive,
        "stall_timeout_s": st.none() | positive,
        "retries": st.integers(0, 100),
        "clear_costmaps_on_retry": st.booleans(),
        "on_failure": st.sampled_from(FailureAction),
        "pass_through_m": st.none() | st.floats(0, 100),
        "dwell_s": st.floats(0, 1e4),
    },
)
# Names are one line of real text: no control characters, no lone surrogates.
names = st.none() | st.text(
    st.characters(blacklist_categories=("Cc", "Cs", "Cf")), min_size=1, max_size=10
).filter(str.strip)


@st.composite
def missions(draw, yaws=typed_yaw):
    count = draw(st.integers(1, 6))
    chosen_names = draw(
        st.lists(names, min_size=count, max_size=count).filter(
            lambda ns: len([n for n in ns if n]) == len({n for n in ns if n})
        )
    )
    waypoints = tuple(
        Waypoint(
            x=draw(finite),
            y=draw(finite),
            z=draw(st.just(0.0) | finite),
            yaw_rad=draw(yaws),
            name=name,
            overrides=draw(policy_values),
        )
        for name in chosen_names
    )
    segments = st.lists(st.from_regex(r"[a-z0-9_]{1,6}", fullmatch=True), min_size=1, max_size=3)
    return Mission(
        waypoints=waypoints,
        defaults=Policy(**draw(policy_values)),
        frame=draw(st.from_regex(r"/?[A-Za-z_][A-Za-z0-9_/]{0,10}", fullmatch=True)),
        loops=draw(st.none() | st.integers(1, 1000)),
        map=draw(st.none() | segments.map(lambda s: Path("/nonexistent-navseq", *s, "m.yaml"))),
        start=draw(st.none() | st.builds(Pose2D, finite, finite, yaws)),
        server_timeout=draw(st.none() | positive),
    )


def reload(scratch: Path, text: str) -> Mission:
    path = scratch / "roundtrip.yaml"
    path.write_text(text, encoding="utf-8")
    return load_mission(path)


@settings(max_examples=200, deadline=None)
@given(mission=missions())
def test_dump_then_load_gives_the_same_mission(scratch, mission):
    assert reload(scratch, dump_mission_yaml(mission)) == mission


@settings(max_examples=100, deadline=None)
@given(mission=missions(yaws=st.floats(-3.14159, math.pi)))
def test_computed_yaws_round_to_a_millionth_of_a_degree_and_then_stay(scratch, mission):
    text = dump_mission_yaml(mission)
    again = reload(scratch, text)
    for before, after in zip(mission.waypoints, again.waypoints, strict=True):
        assert after.yaw_rad == pytest.approx(before.yaw_rad, abs=math.radians(1e-6))
    assert dump_mission_yaml(again) == text


@settings(max_examples=30, deadline=None)
@given(mission=missions())
def test_write_mission_then_load_gives_the_same_mission(scratch, mission):
    folder = Path(tempfile.mkdtemp(dir=scratch))
    target = folder / "mission.yaml"
    write_mission(mission, target)
    assert load_mission(target) == mission
