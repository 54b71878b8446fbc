"""Fuzzing every loader of user input with hostile material (issue 9).

Each loader gets at least 2 000 generated inputs per normal test run (derandomized:
the same inputs every run), built from the pieces that broke navseq before — huge
and tiny numbers, aliases and tags, lone surrogates and escape sequences, deep
nesting, $(arg) chains, lying image headers, damaged journal lines. The loaders are
called in-process and only NavseqError may escape; what loads must be within the
documented limits. ``make fuzz`` runs the same tests with NAVSEQ_FUZZ_SCALE=10.

FIFOs and devices are left to test_hostile_input.py, which runs them in a
subprocess with a timeout: in-process, a regression there would hang the suite.
"""

from __future__ import annotations

import json
import math
import os
import random
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from navseq.errors import NavseqError
from navseq.journal.writer import read_journal, resume_point
from navseq.mission import inspect_mission_file
from navseq.mission.fields import MAX_COORDINATE
from navseq.mission.model import Mission
from navseq.sim.occupancy import MAX_RESOLUTION, MIN_RESOLUTION, load_map, max_map_pixels
from navseq.text import text_problem

CASES = max(1, round(2000 * float(os.environ.get("NAVSEQ_FUZZ_SCALE", "1"))))
FUZZ = settings(
    max_examples=CASES,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=list(HealthCheck),
)


@pytest.fixture(scope="module")
def scratch() -> Iterator[Path]:
    # Thousands of small writes: in memory where the machine has a tmpfs (30x faster).
    memory = "/dev/shm" if os.access("/dev/shm", os.W_OK) else None
    with tempfile.TemporaryDirectory(dir=memory) as folder:
        yield Path(folder)


@pytest.fixture(autouse=True)
def no_package_path(monkeypatch: pytest.MonkeyPatch) -> None:
    # $(find) crawls ROS_PACKAGE_PATH; the machine's packages are not under test.
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.setenv("NAVSEQ_FUZZ_HOME", "/nonexistent-navseq")


def fuzz(strategy: st.SearchStrategy, check: Callable[..., None]) -> None:
    """Run ``check`` on CASES examples and make sure that many really ran."""
    ran = 0

    @FUZZ
    @given(strategy)
    def case(example: object) -> None:
        nonlocal ran
        ran += 1
        check(example)

    case()
    assert ran >= CASES


HOSTILE_NUMBERS = [
    "0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e999",
    "4.9e-324",
    "1e6",
    "1000001",
    "1e20",
    "-1e20",
    "3600",
    "3601",
    "1" * 400,
    "9" * 400 + "a",
    "1" * 400 + "e5",
    "0x1F",
    ".inf",
    "-.inf",
    ".nan",
    "1_000",
    "5e-2",
]
HOSTILE_TEXT = [
    '"\\ud800"',
    '"\\udcff"',
    '"\\e]0;owned\\a"',
    '"\\e[2J"',
    '"a\\nb"',
    '"\\x00"',
    '"\\u202e"',
    '"\\x9b"',
    "'\u00e9'",
    '""',
    "' '",
]


def mission_checks(mission: Mission | None) -> None:
    """What loads is within the documented limits."""
    if mission is None:
        return
    assert len(mission.waypoints) >= 1
    for waypoint in mission.waypoints:
        assert all(abs(v) <= MAX_COORDINATE for v in (waypoint.x, waypoint.y, waypoint.z))
        assert -math.pi < waypoint.yaw_rad <= math.pi
        assert waypoint.name is None or text_problem(waypoint.name) is None
    assert text_problem(mission.frame) is None
    if mission.start is not None:
        assert abs(mission.start.x) <= MAX_COORDINATE and -math.pi < mission.start.yaw <= math.pi


def load_text(scratch: Path, name: str, text: str | bytes) -> None:
    path = scratch / name
    path.write_bytes(text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text)
    mission, problems = inspect_mission_file(path)  # NavseqErrors are collected, not raised
    assert (mission is None) == bool(problems.errors)
    mission_checks(mission)


# --- navseq YAML ----------------------------------------------------------------------

YAML_PIECES = st.sampled_from(
    [
        *"[]{}:,-&*!'\" \n\t#|>",
        "\n  - ",
        "\n    ",
        "navseq: 1\n",
        "waypoints:",
        "frame: ",
        "map: ",
        "start: ",
        "loops: ",
        "defaults: ",
        "name: ",
        "x: ",
        "y: ",
        "z: ",
        "yaw: ",
        "yaw_rad: ",
        "orientation: ",
        "dwell: ",
        "goal_timeout: ",
        "pass_through: ",
        "xy_tolerance: ",
        "yaw_tolerance: ",
        "retries: ",
        "server_timeout: ",
        "&a ",
        "*a",
        "<<: *a",
        "!!python/object/apply:os.system [ls]",
        "!!binary aGk=",
        "!!set {a}",
        "!!timestamp 2001-12-14",
        "!!str",
        "!!float",
        "[[[[[[[[[[[[",
        "]]]]]]]]]]]]",
        "null",
        "true",
        "forever",
        "{x: 1, y: 2}",
        "[1, 2, 90]",
        "{x: 0, y: 0, w: 0, z: 0}",
        *HOSTILE_NUMBERS,
        *HOSTILE_TEXT,
    ]
)
VALID_YAML = (
    "navseq: 1\nframe: map\nstart: {x: 0, y: 0, yaw: 0}\n"
    "defaults: &d {goal_timeout: 60, retries: 1}\n"
    "waypoints:\n  - {name: a, x: 1, y: 2, yaw: 90, <<: *d}\n  - [1, 2, 45]\n"
)


@st.composite
def yaml_documents(draw: st.DrawFn) -> str:
    pieces = "".join(draw(st.lists(YAML_PIECES, max_size=30)))
    if draw(st.booleans()):
        return pieces
    at = draw(st.integers(0, len(VALID_YAML)))
    return VALID_YAML[:at] + pieces + VALID_YAML[at:]


def test_navseq_yaml_loader(scratch: Path) -> None:
    fuzz(yaml_documents(), lambda text: load_text(scratch, "mission.yaml", text))


# --- rosparam YAML (the tutorial's p_seq / yea_seq) ------------------------------------

ROSPARAM_PIECES = st.sampled_from(
    [
        "p_seq: ",
        "yea_seq: ",
        "move_base_seq:\n  ",
        "[",
        "]",
        ", ",
        "\n",
        "  ",
        "{",
        "}",
        ": ",
        "&a ",
        "*a",
        "waypoints: ",
        "mission: ",
        "/dev/null",
        *HOSTILE_NUMBERS,
    ]
)


@st.composite
def rosparam_documents(draw: st.DrawFn) -> str:
    numbers = st.sampled_from(HOSTILE_NUMBERS)
    p_seq = ", ".join(draw(st.lists(numbers, max_size=9)))
    yea_seq = ", ".join(draw(st.lists(numbers, max_size=3)))
    noise = "".join(draw(st.lists(ROSPARAM_PIECES, max_size=12)))
    return f"seq:\n  p_seq: [{p_seq}]\n  yea_seq: [{yea_seq}]\n{noise}"


def test_rosparam_loader(scratch: Path) -> None:
    fuzz(rosparam_documents(), lambda text: load_text(scratch, "params.yaml", text))


# --- roslaunch ------------------------------------------------------------------------

LAUNCH_PIECES = st.sampled_from(
    [
        "<launch>",
        "</launch>",
        '<arg name="a" default="AAAAAAAAAAAAAAAAAAAA"/>',
        '<arg name="b" default="$(arg a)$(arg a)$(arg a)$(arg a)$(arg a)$(arg a)$(arg a)"/>',
        '<arg name="c" default="$(arg b)$(arg b)$(arg b)$(arg b)$(arg b)$(arg b)$(arg b)"/>',
        '<arg name="d" default="$(arg c)$(arg c)$(arg c)$(arg c)$(arg c)$(arg c)$(arg c)"/>',
        '<param name="p" value="$(arg d)"/>',
        '<param name="p_seq" value="[1e308, 0, 0]"/>',
        '<param name="p_seq" value="[1, 2, 0]"/>',
        '<rosparam param="yea_seq">[1e20]</rosparam>',
        '<rosparam param="yea_seq">[90]</rosparam>',
        '<rosparam subst_value="true">',
        "</rosparam>",
        '<rosparam file="fuzz.yaml"/>',
        '<include file="fuzz.launch"/>',
        '<include file="missing.launch"/>',
        '<group ns="r1">',
        "</group>",
        '<node pkg="p" type="t" name="n">',
        "</node>",
        "<!DOCTYPE launch>",
        '<!ENTITY e "x">',
        "&amp;",
        "&#xD800;",
        "$(env HOME)",
        "$(env NAVSEQ_FUZZ_UNSET)",
        "$(optenv NAVSEQ_FUZZ_HOME x)",
        "$(find navseq)",
        "$(eval 1+1)",
        "$(arg",
        'if="$(arg a)"',
        "p_seq: [1, 2, 0]\n",
        "yea_seq: [0]\n",
        "\n",
        " ",
        '"',
        "<",
        ">",
        *HOSTILE_NUMBERS[:8],
        *HOSTILE_TEXT,
    ]
)


@st.composite
def launch_documents(draw: st.DrawFn) -> str:
    return "".join(draw(st.lists(LAUNCH_PIECES, max_size=25)))


def test_launch_loader(scratch: Path) -> None:
    (scratch / "fuzz.yaml").write_text("p_seq: [1, 2, 0]\nyea_seq: [0]\n")
    (scratch / "fuzz.launch").write_text('<launch><include file="fuzz.launch"/></launch>\n')
    fuzz(launch_documents(), lambda text: load_text(scratch, "mission.launch", text))


# --- CSV ------------------------------------------------------------------------------

CSV_PIECES = st.sampled_from(
    [
        ",",
        "\n",
        "\r\n",
        '"',
        "#",
        " ",
        "x,y,z,qx,qy,qz,qw\n",
        "0,0,0,0,0,0,1\n",
        "1,2,0,0,0,0.7,0.7\n",
        "nan",
        "inf",
        "-inf",
        "1e308",
        "1e200",
        "0",
        "1",
        "-1",
        "1e-320",
        "\u00e9",
        "\x0c",
        "a" * 200,
        *HOSTILE_NUMBERS,
    ]
)


def test_csv_loader(scratch: Path) -> None:
    documents = st.lists(CSV_PIECES, max_size=40).map("".join)
    fuzz(documents, lambda text: load_text(scratch, "path.csv", text))


# --- map YAML and images --------------------------------------------------------------


def pgm(width: int, height: int, pixels: bytes) -> bytes:
    return f"P5\n{width} {height}\n255\n".encode() + pixels


IMAGES = [
    pgm(4, 4, bytes([254] * 16)),
    pgm(4, 4, bytes(range(0, 256, 16))),
    pgm(4, 4, bytes(3)),  # truncated
    pgm(100000, 100000, bytes(100)),
    pgm(1, 70000, bytes(10)),
    pgm(0, 0, b""),
    b"P2\n2 2\n255\n0 255 255 0\n",
    b"P6\n1 1\n255\n\x00\x80\xff",
    b"P5\n2 1\n65535\n\x00\x00\xff\xff",
    b"\x89PNG\r\n\x1a\n",
    b"",
    b"not an image",
]
MAP_VALUES = st.sampled_from(
    [
        *HOSTILE_NUMBERS,
        *HOSTILE_TEXT,
        "[0, 0, 0]",
        "[1e308, 0, 0]",
        "[0, 0]",
        "[0, 0, 1e20]",
        "[a, b, c]",
        "trinary",
        "scale",
        "raw",
        "fuzzy",
        "*a",
        "&a 1",
        "!!python/name:os.system",
        "[",
        "",
        "{}",
        "map.pgm",
        "missing.pgm",
        "0.05",
        "1",
        "0.65",
        "0.196",
    ]
)
MAP_KEYS = st.sampled_from(
    [
        "image",
        "resolution",
        "origin",
        "negate",
        "occupied_thresh",
        "free_thresh",
        "mode",
        "extra",
        "<<",
    ]
)


@st.composite
def maps(draw: st.DrawFn) -> tuple[str, bytes]:
    settings_ = {"image": "map.pgm", "resolution": "0.05", "origin": "[0, 0, 0]"}
    for key, value in draw(st.lists(st.tuples(MAP_KEYS, MAP_VALUES), max_size=5)):
        settings_[key] = value
    text = "".join(f"{key}: {value}\n" for key, value in settings_.items())
    image = draw(st.sampled_from(IMAGES) | st.binary(max_size=40))
    return text, image


def test_map_loader(scratch: Path) -> None:
    def check(example: tuple[str, bytes]) -> None:
        text, image = example
        (scratch / "map.pgm").write_bytes(image)
        (scratch / "map.yaml").write_text(text, errors="surrogatepass")
        try:
            grid = load_map(scratch / "map.yaml")
        except NavseqError:
            return
        assert grid.width * grid.height <= max_map_pixels()
        assert MIN_RESOLUTION <= grid.resolution <= MAX_RESOLUTION
        assert all(math.isfinite(v) for v in grid.bounds)

    fuzz(maps(), check)


# --- journals -------------------------------------------------------------------------

EVENT_TYPES = [
    "MissionStarted",
    "LoopStarted",
    "WaypointStarted",
    "WaypointProgress",
    "WaypointPlan",
    "AttemptFailed",
    "WaypointDwelling",
    "TaskStarted",
    "TaskFinished",
    "WaypointFinished",
    "ServerStatusChanged",
    "MissionFinished",
    "Unknown",
]
FIELDS = [
    "t",
    "index",
    "loop",
    "attempt",
    "waypoint_count",
    "loops",
    "outcome",
    "attempts",
    "duration",
    "distance_driven",
    "reason",
    "passed_through",
    "x",
    "y",
    "yaw",
    "path",
    "will_retry",
    "seconds",
    "available",
    "success",
    "resumed",
    "task",
    "task_kind",
    "detail",
    "files",
    "output",
]
HOSTILE_JSON = [
    None,
    True,
    0,
    -1,
    2**70,
    10**30,
    0.5,
    1e308,
    -1e308,
    math.inf,
    math.nan,
    "reached",
    "skipped",
    "failed",
    "\ud800",
    "\x1b[2J",
    "",
    "x" * 100,
    [],
    [1, 2],
    [[0.0, 0.0], [1.0, 1e308]],
    [None],
    {"a": 1},
]


def _record_pool() -> list[str]:
    """Journal lines of every kind, with hostile values; drawn whole, since drawing
    each field with Hypothesis would make a case ten times slower."""
    chooser = random.Random(9)
    lines = [
        "[" * 1100 + "]" * 1100,
        "{",
        "",
        "null",
        "[1, 2]",
        '{"kind": "event"',
        '{"kind": "resumed", "loop": 0, "index": 0}',
        '{"kind": "resumed"}',
    ]
    for _ in range(400):
        record: dict[str, object] = {
            "kind": chooser.choice(["event"] * 4 + ["resumed", "x"]),
            "type": chooser.choice(EVENT_TYPES),
        }
        for name in chooser.sample(FIELDS, chooser.randint(0, 8)):
            record[name] = chooser.choice(HOSTILE_JSON)
        lines.append(json.dumps(record))
    return lines


JOURNAL_LINES = _record_pool()
HEADER_VALUES = [
    None,
    True,
    2,
    0,
    -1,
    "navseq-journal",
    "other",
    "\ud800",
    "m\0.yaml",
    "mission.yaml",
    "/dev/null",
    [1],
    {"a": 1},
]


@st.composite
def journal_lines(draw: st.DrawFn) -> bytes:
    header: dict[str, object] = {
        "kind": "header",
        "format": "navseq-journal",
        "version": 1,
        "mission_source": "mission.yaml",
        "mission_digest": "0" * 64,
        "started": "",
    }
    for key, value in draw(
        st.lists(
            st.tuples(st.sampled_from(sorted(header)), st.sampled_from(HEADER_VALUES)), max_size=2
        )
    ):
        header[key] = value
    lines = [json.dumps(header), *draw(st.lists(st.sampled_from(JOURNAL_LINES), max_size=8))]
    text = "\n".join(lines) + draw(st.sampled_from(["\n", "", '\n{"kind": "ev']))
    return text.encode("utf-8", "surrogatepass")


def test_journal_reader(scratch: Path) -> None:
    def check(data: bytes) -> None:
        path = scratch / "journal.jsonl"
        path.write_bytes(data)
        try:
            state = read_journal(path)
            resume_point(state, mission_digest="0" * 64)
        except NavseqError:
            return

    fuzz(journal_lines(), check)
