"""Hostile and oversized input (issue 9): every case is refused with one clear message
(exit 2, no traceback) instead of hanging, crashing or filling the memory.

CLI cases run ``navseq`` in a subprocess with a generous ``timeout=``: a regression
fails with TimeoutExpired instead of hanging the suite. Nothing here times anything.
"""

from __future__ import annotations

import io
import json
import math
import os
import re
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from rich.console import Console

from cli_support import TURTLEBOT3_MAP, assert_clean_error, navseq
from navseq.errors import NavseqError
from navseq.executor.events import (
    AttemptFailed,
    MissionStarted,
    ServerStatusChanged,
    WaypointFinished,
    WaypointOutcome,
    WaypointStarted,
)
from navseq.executor.result import MissionResult, WaypointResult
from navseq.journal.writer import read_journal
from navseq.mission import load_mission
from navseq.mission.model import Mission, Waypoint
from navseq.sim.occupancy import load_map
from navseq.sinks.progress import LogProgress
from navseq.sinks.summary import summary_table
from navseq.text import printable, text_problem

# Long enough to never cut a healthy run short on a loaded machine; short enough that
# a hang or a quadratic blow-up fails the test rather than the whole suite.
GENEROUS = 20.0
ESCAPE = "\x1b"


def one_message(result) -> str:
    """The error of a refused command, checked to be clean (exit 2, no traceback)."""
    assert_clean_error(result)
    assert "internal error" not in result.stderr
    assert ESCAPE not in result.stderr
    assert "Warning" not in result.stderr  # no raw library warning (Pillow's bomb warning)
    return result.stderr


def mission_file(folder: Path, body: str, name: str = "mission.yaml") -> Path:
    path = folder / name
    path.write_text("navseq: 1\n" + body)
    return path


def map_files(
    folder: Path, yaml_text: str, image: bytes | None = None, image_name: str = "map.pgm"
) -> Path:
    if image is not None:
        (folder / image_name).write_bytes(image)
    path = folder / "map.yaml"
    path.write_text(yaml_text)
    return path


def tiny_pgm() -> bytes:
    return b"P5\n4 4\n255\n" + bytes([254] * 16)


def png_header_only(width: int, height: int) -> bytes:
    """A valid PNG signature and header claiming ``width`` x ``height``, and no pixels."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data))
            + kind
            + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        )

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(b"\x00"))
        + chunk(b"IEND", b"")
    )


MAP_YAML = "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"


# --- 1. regular expressions on untrusted text are linear ------------------------------


@pytest.mark.parametrize("scalar", ["1" * 2**20 + "a", "1" * 2**20 + "e", "1." + "1" * 2**20])
def test_a_one_mib_number_like_scalar_is_read_or_refused_promptly(tmp_path, scalar):
    path = mission_file(tmp_path, f"waypoints:\n  - {{x: {scalar}, y: 0}}\n")
    result = navseq("validate", path, cwd=tmp_path, timeout=GENEROUS)
    if result.returncode != 0:
        assert f"{path.name}:3" in one_message(result)
        assert len(result.stderr) < 2000  # the value is quoted short, not in full


MANY_PAIRS = ", ".join(f"k{i}: 1" for i in range(100_000))  # about a megabyte
FIND_RUNS = """
import json, sys
from pathlib import Path
from navseq.mission.yaml_flow_lines import find_runs
text, runs = find_runs(Path(sys.argv[1]).read_text())
print(json.dumps(sorted([first, len(run.bodies)] for first, run in runs.items())))
"""


@pytest.mark.parametrize(
    "line",
    [
        "- {" + MANY_PAIRS + " x",  # flow pairs up to the end of the line, then not
        "- {" + MANY_PAIRS + ", x",
        "- {" + MANY_PAIRS + ", x: 'q'}",
        "- {x: 0, y: 0" + " " * 2**20 + "x}",
        "- {" + "x: " * 2**18 + "}",
        " " * 2**20 + "- {x",
    ],
    ids=["a-word", "a-lone-key", "a-quoted-value", "spaces", "keys", "indent"],
)
def test_a_megabyte_line_that_almost_is_a_one_line_flow_item_is_passed_over_promptly(
    tmp_path, line
):
    # The YAML fast path (navseq.mission.yaml_flow_lines) reads "- {key: value, ...}"
    # lines with a regular expression, without possessive quantifiers (Python 3.10): it
    # must stay linear on a line that fails at its very end. Run in a subprocess, where
    # the timeout can stop a blow-up; the loader's later steps are not what is tested.
    items = "".join(f"- {{x: {i}, y: 0}}\n" for i in range(10))
    path = tmp_path / "items.yaml"
    path.write_text(items + line + "\n" + items)
    result = subprocess.run(
        [sys.executable, "-c", FIND_RUNS, path],
        capture_output=True,
        text=True,
        timeout=GENEROUS,
        check=True,
    )
    assert json.loads(result.stdout) == [[0, 10], [11, 10]]  # the line is in no run


def test_a_megabyte_one_line_flow_item_is_one_item_of_its_run(tmp_path):
    # ... and a line that is one, however long, is read on the fast path.
    items = "".join(f"- {{x: {i}, y: 0}}\n" for i in range(10))
    path = tmp_path / "items.yaml"
    path.write_text(items + "- {" + MANY_PAIRS + "}\n" + items)
    result = subprocess.run(
        [sys.executable, "-c", FIND_RUNS, path],
        capture_output=True,
        text=True,
        timeout=GENEROUS,
        check=True,
    )
    assert json.loads(result.stdout) == [[0, 21]]


def test_a_csv_like_line_with_a_megabyte_of_spaces_is_sniffed_promptly(tmp_path):
    path = tmp_path / "mission.txt"
    path.write_text("1,2" + " " * 2**20 + "x\n")
    one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))


# --- 2. roslaunch $(arg) expansion bombs ----------------------------------------------


def arg_bomb(levels: int, uses: str) -> str:
    lines = ["<launch>", '  <arg name="a0" default="' + "A" * 60 + '"/>']
    for level in range(1, levels + 1):
        lines.append(f'  <arg name="a{level}" default="' + f"$(arg a{level - 1})" * 10 + '"/>')
    lines += [uses, "</launch>", ""]
    return "\n".join(lines)


def test_an_arg_expansion_bomb_is_refused_at_its_line(tmp_path):
    uses = "\n".join(f'  <param name="p{i}" value="$(arg a5)"/>' for i in range(8))
    path = tmp_path / "bomb.launch"
    path.write_text(arg_bomb(5, uses))
    assert path.stat().st_size < 1024  # a small file: the threat is the expansion
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert "bomb.launch:7" in message  # <arg a5>, whose default grows past the limit
    assert "1 MiB" in message


def test_many_values_each_under_the_limit_hit_the_launch_trees_total(tmp_path):
    uses = "\n".join(f'  <param name="p{i}" value="$(arg a4)"/>' for i in range(40))
    path = tmp_path / "bomb.launch"
    path.write_text(arg_bomb(4, uses))
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert "MiB in all" in message
    assert message.count("bomb.launch:") == 1  # fatal: one message, not one per element


def test_modest_args_still_expand(tmp_path):
    path = tmp_path / "ok.launch"
    path.write_text(
        '<launch>\n  <arg name="x" default="1.5"/>\n'
        '  <rosparam param="p_seq" subst_value="true">[$(arg x), 2, 0]</rosparam>\n'
        '  <rosparam param="yea_seq">[90]</rosparam>\n</launch>\n'
    )
    assert load_mission(path).waypoints[0].x == 1.5


# --- 3. and 7. map files --------------------------------------------------------------


@pytest.fixture
def fifo(tmp_path) -> Path:
    path = tmp_path / "pipe"
    os.mkfifo(path)
    return path


def test_map_option_naming_a_fifo_or_a_device_is_refused(tmp_path, fifo):
    mission = mission_file(tmp_path, "waypoints:\n  - [0.5, 0.5]\n")
    for bad in (fifo, Path("/dev/zero")):
        message = one_message(
            navseq("validate", mission, "--map", bad, cwd=tmp_path, timeout=GENEROUS)
        )
        assert "not a regular file" in message


def test_mission_map_key_naming_a_fifo_is_refused_by_run(tmp_path, fifo):
    mission = mission_file(tmp_path, f"map: {fifo}\nwaypoints:\n  - [0.5, 0.5]\n")
    message = one_message(
        navseq("run", mission, "--out", tmp_path / "out", cwd=tmp_path, timeout=GENEROUS)
    )
    assert "not a regular file" in message


@pytest.mark.parametrize("image", ["pipe", "/dev/zero"])
def test_map_image_that_is_a_fifo_or_a_device_is_refused(tmp_path, fifo, image):
    map_yaml = map_files(tmp_path, MAP_YAML.replace("map.pgm", image))
    with pytest.raises(NavseqError, match="not a regular file") as caught:
        load_map(map_yaml)
    assert caught.value.source == f"{map_yaml}:1"


def test_map_yaml_alias_bomb_is_refused(tmp_path):
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 9)]
    map_yaml = map_files(tmp_path, "\n".join(lines) + "\n" + MAP_YAML, tiny_pgm())
    mission = mission_file(tmp_path, "waypoints:\n  - [0.1, 0.1]\n")
    message = one_message(
        navseq("validate", mission, "--map", map_yaml, cwd=tmp_path, timeout=GENEROUS)
    )
    assert "alias bomb" in message


def test_map_yaml_on_dev_zero_through_the_mission_is_refused(tmp_path):
    mission = mission_file(tmp_path, "map: /dev/zero\nwaypoints:\n  - [0.1, 0.1]\n")
    assert "not a regular file" in one_message(
        navseq("validate", mission, cwd=tmp_path, timeout=GENEROUS)
    )


@pytest.mark.parametrize(
    ("image", "name"),
    [
        (b"P5\n100000 100000\n255\n" + bytes(100), "map.pgm"),
        (png_header_only(20000, 20000), "map.png"),
    ],
)
def test_an_image_claiming_billions_of_pixels_is_refused_with_the_limit(tmp_path, image, name):
    map_yaml = map_files(tmp_path, MAP_YAML.replace("map.pgm", name), image, name)
    mission = mission_file(tmp_path, "waypoints:\n  - [0.1, 0.1]\n")
    message = one_message(
        navseq("validate", mission, "--map", map_yaml, cwd=tmp_path, timeout=GENEROUS)
    )
    assert "NAVSEQ_MAX_MAP_PIXELS" in message
    assert "16,000,000" in message


def test_the_pixel_limit_can_be_set(tmp_path, monkeypatch):
    map_yaml = map_files(tmp_path, MAP_YAML, tiny_pgm())
    monkeypatch.setenv("NAVSEQ_MAX_MAP_PIXELS", "15")
    with pytest.raises(NavseqError, match="4 x 4 = 16 pixels; navseq loads at most 15"):
        load_map(map_yaml)
    monkeypatch.setenv("NAVSEQ_MAX_MAP_PIXELS", "16")
    assert load_map(map_yaml).data.shape == (4, 4)
    monkeypatch.setenv("NAVSEQ_MAX_MAP_PIXELS", "lots")
    with pytest.raises(NavseqError, match="NAVSEQ_MAX_MAP_PIXELS: must be a whole number"):
        load_map(map_yaml)


def test_map_yaml_reads_numbers_like_mission_files(tmp_path):
    map_yaml = map_files(tmp_path, MAP_YAML.replace("0.05", "5e-2"), tiny_pgm())
    assert load_map(map_yaml).resolution == 0.05


def test_map_yaml_with_a_python_tag_gets_one_line_naming_its_line(tmp_path):
    map_yaml = map_files(tmp_path, MAP_YAML + "mode: !!python/name:os.system\n", tiny_pgm())
    with pytest.raises(NavseqError) as caught:
        load_map(map_yaml)
    assert str(caught.value).startswith(f"{map_yaml}:4: ")
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(
    ("setting", "key", "accepted"),
    [
        ("resolution: 4.9e-324", "resolution", "from 0.0001 to 1000"),
        ("resolution: 1e300", "resolution", "from 0.0001 to 1000"),
        ("origin: [1e308, 0, 0]", "origin", "±1e+06 m"),
        ("origin: [0, -2e6, 0]", "origin", "±1e+06 m"),
        ("origin: [0, 0, 1e20]", "origin", "ten turns"),
    ],
)
def test_map_values_no_map_can_mean_name_the_key_and_the_range(tmp_path, setting, key, accepted):
    name = setting.split(":")[0]
    text = (
        "\n".join(setting if line.startswith(name) else line for line in MAP_YAML.splitlines())
        + "\n"
    )
    map_yaml = map_files(tmp_path, text, tiny_pgm())
    with pytest.raises(NavseqError, match=re.escape(accepted)) as caught:
        load_map(map_yaml)
    assert caught.value.subject == f"key {key}"


# --- 4. journals ----------------------------------------------------------------------


def journal(folder: Path, mission_source: str, *lines: str) -> Path:
    header = {
        "kind": "header",
        "format": "navseq-journal",
        "version": 1,
        "mission_source": mission_source,
        "mission_digest": "0" * 64,
        "started": "2026-01-01T00:00:00+00:00",
    }
    path = folder / "journal.jsonl"
    path.write_text("\n".join([json.dumps(header), *lines]) + "\n")
    return path


def test_resume_with_a_journal_naming_dev_zero_or_a_fifo_is_refused(tmp_path, fifo):
    for source in ("/dev/zero", str(fifo)):
        path = journal(tmp_path, source)
        message = one_message(navseq("run", "--resume", path, cwd=tmp_path, timeout=GENEROUS))
        assert "not a regular file" in message


def test_resume_from_a_fifo_or_a_device_is_refused(tmp_path, fifo):
    for bad in (fifo, Path("/dev/zero")):
        assert "not a regular file" in one_message(
            navseq("run", "--resume", bad, cwd=tmp_path, timeout=GENEROUS)
        )


def test_deeply_nested_journal_line_is_refused_with_its_line_number(tmp_path):
    mission = mission_file(tmp_path, "waypoints:\n  - [0.1, 0.1]\n")
    path = journal(tmp_path, str(mission), "[" * 100_000 + "]" * 100_000)
    with pytest.raises(NavseqError, match="nests JSON") as caught:
        read_journal(path)
    assert caught.value.source == f"{path}:2"
    one_message(navseq("run", "--resume", path, cwd=tmp_path, timeout=GENEROUS))


def test_journal_header_naming_a_path_with_a_nul_is_refused(tmp_path):
    with pytest.raises(NavseqError, match="mission_source"):
        read_journal(journal(tmp_path, "mission\0.yaml"))


def test_an_overlong_journal_line_is_refused_with_its_line_number(tmp_path):
    # A journal has no size limit (a patrol's grows for weeks); each line has one.
    long_line = '{"kind": "event", "type": "WaypointPlan", "path": [' + "[0, 0], " * 600_000
    path = journal(tmp_path, "m.yaml", '{"kind": "event"}', long_line + "[0, 0]]}")
    with pytest.raises(NavseqError, match="a line over 4 MiB") as caught:
        read_journal(path)
    assert caught.value.source == f"{path}:3"


def test_a_journal_claiming_a_mission_of_a_trillion_waypoints_is_refused(tmp_path):
    started = json.dumps(
        {"kind": "event", "type": "MissionStarted", "t": 0, "waypoint_count": 10**12, "loops": None}
    )
    with pytest.raises(NavseqError, match="1 to 1,000,000 waypoints") as caught:
        read_journal(journal(tmp_path, "m.yaml", started))
    assert caught.value.source.endswith(":2")


# --- 5. numbers no robot can mean -----------------------------------------------------


@pytest.mark.parametrize(
    ("body", "field", "accepted"),
    [
        ("waypoints:\n  - {x: 1e308, y: 0}\n", "waypoint 1, field x", "±1e+06 m"),
        ("waypoints:\n  - [0, -1e7]\n", "waypoint 1, field y", "±1e+06 m"),
        ("start: {x: 1e308, y: 0}\nwaypoints:\n  - [0, 0]\n", "start, field x", "±1e+06 m"),
        ("waypoints:\n  - {x: 0, y: 0, yaw: 1e20}\n", "waypoint 1, field yaw", "±3600 degrees"),
        ("waypoints:\n  - {x: 0, y: 0, yaw_rad: -1e20}\n", "waypoint 1, field yaw_rad", "rad"),
        ("waypoints:\n  - {x: 0, y: 0, dwell: 1e300}\n", "waypoint 1, field dwell", "<= 1e+06 s"),
        (
            "defaults: {goal_timeout: 1e300}\nwaypoints:\n  - [0, 0]\n",
            "defaults, field goal",
            "<= 1e+06 s",
        ),
    ],
)
def test_values_no_robot_can_mean_are_refused_naming_the_field_and_the_range(
    tmp_path, body, field, accepted
):
    path = mission_file(tmp_path, f"map: {TURTLEBOT3_MAP}\n" + body)
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert field in message and accepted in message


def test_huge_coordinates_in_csv_and_tutorial_params_are_refused(tmp_path):
    csv = tmp_path / "path.csv"
    csv.write_text("1e308,0,0,0,0,0,1\n")
    assert "±1e+06 m" in one_message(navseq("validate", csv, cwd=tmp_path, timeout=GENEROUS))
    params = tmp_path / "params.yaml"
    params.write_text("p_seq: [0, 0, 0]\nyea_seq: [1e20]\n")
    assert "±3600 degrees" in one_message(
        navseq("validate", params, cwd=tmp_path, timeout=GENEROUS)
    )


def test_start_option_out_of_range_is_refused(tmp_path):
    path = mission_file(tmp_path, "waypoints:\n  - [0.5, 0.5]\n")
    result = navseq(
        "run", path, "--map", TURTLEBOT3_MAP, "--start", "1e308,0,0", cwd=tmp_path, timeout=GENEROUS
    )
    assert result.returncode == 2 and "±1e+06 m" in result.stderr


@given(turns=st.integers(-9, 9), degrees=st.floats(-179.5, 180.0))
def test_yaws_within_ten_turns_are_normalised_into_minus_pi_to_pi(turns, degrees):
    from navseq.mission.fields import yaw_degrees
    from navseq.mission.located import Located

    written = degrees + 360.0 * turns
    yaw = yaw_degrees(Located(written, "m.yaml:1"), "field yaw")
    assert -math.pi < yaw <= math.pi
    assert math.cos(yaw) == pytest.approx(math.cos(math.radians(written)), abs=1e-9)
    assert math.sin(yaw) == pytest.approx(math.sin(math.radians(written)), abs=1e-9)


def test_a_yaw_of_many_turns_is_driven_as_the_direction_it_means(tmp_path):
    path = mission_file(
        tmp_path,
        f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2, y: -0.5}}\n"
        "waypoints:\n  - {x: -1.9, y: -0.5, yaw: 3590}\n",
    )
    assert load_mission(path).waypoints[0].yaw_deg == pytest.approx(-10.0)
    result = navseq("run", path, "--out", tmp_path / "out", cwd=tmp_path, timeout=60)
    assert result.returncode == 0, result.stderr


# --- 6. strings -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("value", "where"),
    [
        ('name: "\\ud800"', "mission.yaml:3"),
        ('name: "\\e]0;owned\\a"', "waypoint 1, field name"),
        ('name: "line\\nbreak"', "waypoint 1, field name"),
    ],
)
def test_names_that_are_not_one_line_of_text_are_refused_at_load(tmp_path, value, where):
    path = mission_file(tmp_path, f"waypoints:\n  - {{x: 0, y: 0, {value}}}\n")
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert where in message


def test_lone_surrogate_in_frame_or_map_path_is_refused(tmp_path):
    for body in ('frame: "m\\udc80p"\n', 'map: "\\ud83d.yaml"\n'):
        path = mission_file(tmp_path, body + "waypoints:\n  - [0, 0]\n")
        assert "surrogate" in one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))


def test_escape_sequences_in_unknown_keys_are_printed_escaped(tmp_path):
    path = mission_file(tmp_path, 'waypoints:\n  - {x: 0, y: 0, "\\e[2J\\e]0;owned\\a": 1}\n')
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert "\\x1b[2J" in message


def test_a_mission_file_name_that_is_not_utf8_runs_and_reports(tmp_path):
    name = os.fsdecode(b"tour\xff\x1b[2J.yaml")
    path = mission_file(
        tmp_path,
        f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2, y: -0.5}}\nwaypoints:\n  - [-1.9, -0.5]\n",
        name,
    )
    result = navseq("run", path, "--out", tmp_path / "out", cwd=tmp_path, timeout=60)
    assert result.returncode == 0, result.stderr
    assert ESCAPE not in result.stdout
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["mission"]["source"].endswith(name)


def hostile_mission() -> Mission:
    # Built in code (the Python API), where no loader checked the name.
    return Mission(
        waypoints=(Waypoint(1.0, 0.0, name="\x1b]0;owned\x07\x1b[2J"),), source="tour\x1b[2J.yaml"
    )


def test_progress_lines_escape_names_and_server_reasons():
    stream = io.StringIO()
    progress = LogProgress(hostile_mission(), stream)
    for event in (
        MissionStarted(0.0, 1, 1),
        WaypointStarted(0.0, 0, 0, 1, 1, 1.0, 0.0, 0.0),
        ServerStatusChanged(1.0, False, "gone\x1b[2J"),
        AttemptFailed(2.0, 0, 1, "ABORTED\x1b[31m", False),
        WaypointFinished(3.0, 0, 0, WaypointOutcome.FAILED, 1, 3.0, 0.0, reason="\x9b2J"),
    ):
        progress(event)
    assert ESCAPE not in stream.getvalue() and "\x9b" not in stream.getvalue()
    assert "\\x1b]0;owned\\x07" in stream.getvalue()


def test_summary_table_escapes_names_and_reasons():
    visit = WaypointResult(
        index=0,
        loop=0,
        name="\x1b[2Jdock",
        x=1.0,
        y=0.0,
        yaw_rad=0.0,
        outcome=WaypointOutcome.FAILED,
        attempts=1,
        duration=1.0,
        distance_driven=0.0,
        reason="\x1b]0;t\x07",
    )
    result = MissionResult(success=False, reason="failed", visits=[visit], duration=1.0)
    console = Console(file=io.StringIO(), width=120, force_terminal=False)
    console.print(summary_table(hostile_mission(), result))
    shown = console.file.getvalue()
    assert ESCAPE not in shown and "\\x1b[2Jdock" in shown


@given(st.text())
def test_printable_text_holds_no_control_characters_and_always_encodes(text):
    shown = printable(text)
    assert not any(ord(ch) < 0x20 or 0x7F <= ord(ch) < 0xA0 for ch in shown)
    shown.encode("utf-8")  # no lone surrogate left
    assert printable(shown) == shown
    if text_problem(text) is None:
        assert shown == text


def test_megabyte_names_and_keys_give_short_messages(tmp_path):
    path = mission_file(
        tmp_path,
        "waypoints:\n  - x: 0\n    y: 0\n    ? "
        + "k" * 100_000
        + "\n    : 1\n    name: "
        + "n" * 1_000_000
        + "\n",
    )
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert "at most 256" in message
    assert len(message) < 2000


# --- 7. whole numbers longer than Python converts --------------------------------------

LONG = "9" * 5000


@pytest.mark.parametrize(
    ("name", "text", "where"),
    [
        (
            "mission.yaml",
            f"navseq: 1\nwaypoints:\n  - {{x: {LONG}, y: 0}}\n",
            "mission.yaml:3, key x",
        ),
        (
            "mission.yaml",
            f"navseq: 1\nwaypoints:\n  - x: 0\n    y: -{LONG}\n",
            "mission.yaml:4, key y",
        ),
        ("mission.yaml", f"navseq: 1\nwaypoints:\n  - {{x: 0, y: 0, name: {LONG}}}\n", "key name"),
        ("mission.yaml", f"navseq: 1\nwaypoints:\n  - {{x: 0x{'f' * 5000}, y: 0}}\n", "key x"),
        (
            "params.yaml",
            f"p_seq: [0, 0, 0, {LONG}, 0, 0]\nyea_seq: [0, 0]\n",
            "params.yaml:1, key p_seq",
        ),
        (
            "mission.yaml",  # the line path: a run of one-line items
            "navseq: 1\nwaypoints:\n"
            + "".join(f"  - {{x: {i}, y: 0}}\n" for i in range(20))
            + f"  - {{x: {LONG}, y: 0}}\n",
            "mission.yaml:23, key x",
        ),
    ],
)
def test_a_whole_number_of_thousands_of_digits_is_refused_naming_line_and_key(
    tmp_path, name, text, where
):
    path = tmp_path / name
    path.write_text(text)
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert where in message and "5,000 digits" in message
    assert len(message) < 2000


def test_a_long_whole_number_in_a_launch_param_names_the_param(tmp_path):
    path = tmp_path / "tour.launch"
    path.write_text(
        '<launch>\n  <node pkg="p" type="t" name="n">\n'
        f'    <param name="goal_timeout" value="{LONG}"/>\n'
        '    <rosparam param="p_seq">[0, 0, 0]</rosparam>\n'
        '    <rosparam param="yea_seq">[0]</rosparam>\n  </node>\n</launch>\n'
    )
    with pytest.raises(NavseqError, match="5,000 digits") as caught:
        load_mission(path)
    assert caught.value.source == f"{path}:3" and caught.value.subject == "param goal_timeout"


def test_ros2_waypoints_string_is_read_by_the_mission_files_reader():
    from navseq.ros2.node_params import read_node_params

    for text, expected in [
        (f"[{{x: {LONG}, y: 0}}]", "5,000 digits"),
        ("[" * 100_000 + "]" * 100_000, "nested more than 64 levels deep"),
    ]:
        with pytest.raises(NavseqError, match=expected):
            read_node_params({"waypoints": text}, "/navseq")
    mission, _ = read_node_params({"waypoints": "[{x: 1, y: 2, yaw: 90}]"}, "/navseq")
    assert mission.waypoints[0].x == 1.0


# --- 8. nesting deep enough to crash PyYAML's composer ---------------------------------


def nested(kind: str, levels: int) -> str:
    if kind == "flow list":
        return "[" * levels + "]" * levels
    if kind == "flow mapping":
        return "{a: " * levels + "1" + "}" * levels
    if kind == "unclosed":
        return "[" * levels
    return "\n" + "- " * levels + "1"  # block lists, one level per "- "


@pytest.mark.parametrize("kind", ["flow list", "flow mapping", "unclosed", "block"])
def test_a_mission_nested_100000_levels_deep_is_refused_at_its_line(tmp_path, kind):
    # Before: 30-67 s in the parser, then SIGSEGV in libyaml's composer.
    path = mission_file(tmp_path, f"waypoints:\n  - [0, 0]\nx: {nested(kind, 100_000)}\n")
    message = one_message(navseq("validate", path, cwd=tmp_path, timeout=GENEROUS))
    assert f"{path.name}:4" in message or f"{path.name}:5" in message
    assert "nested more than 64 levels deep" in message


def test_maps_robots_and_rosparam_files_refuse_deep_nesting_too(tmp_path):
    deep = nested("flow mapping", 50_000)
    map_yaml = map_files(tmp_path, MAP_YAML + f"extra: {deep}\n", tiny_pgm())
    robot = tmp_path / "robot.yaml"
    robot.write_text(f"name: r\nfootprint: {deep}\n")
    params = tmp_path / "params.yaml"
    params.write_text(f"p_seq: {deep}\nyea_seq: [0]\n")
    mission = mission_file(tmp_path, "waypoints:\n  - [0.1, 0.1]\n")
    for args, where in [
        (("validate", mission, "--map", map_yaml), "map.yaml:4"),
        (("validate", mission, "--robot", robot), "robot.yaml:2"),
        (("validate", params), "params.yaml:1"),
    ]:
        message = one_message(navseq(*args, cwd=tmp_path, timeout=GENEROUS))
        assert where in message and "nested more than 64 levels deep" in message


def test_nesting_is_refused_before_the_parser_goes_deeper():
    from navseq.mission.yaml_doc import MAX_DEPTH, refuse_deep_nesting

    refuse_deep_nesting("x: " + "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1), "m.yaml")
    with pytest.raises(NavseqError, match="nested more than 64") as caught:
        refuse_deep_nesting("a: 1\nx: " + "[" * 1_000_000, "m.yaml", first_line=10)
    assert caught.value.source == "m.yaml:11"


# --- 9. a newline in a file's name -----------------------------------------------------


def no_raw_line_break_from(name: str, *outputs: str) -> None:
    """The name is shown escaped (``to\\nur``), never split over two lines."""
    escaped = printable(name)
    tail = name.split("\n")[-1]
    for output in outputs:
        assert not any(line.startswith(tail) for line in output.splitlines()), output
    assert any(escaped in output for output in outputs)


def test_a_newline_in_a_mission_files_name_is_printed_escaped(tmp_path):
    good = mission_file(tmp_path, "waypoints:\n  - [0.5, 0.5]\n  - [1.0, 0.5]\n", "to\nur.yaml")
    bad = mission_file(tmp_path, "waypoints:\n  - {x: 0, y: 0, bogus: 1}\n", "ba\nd.yaml")
    out = tmp_path / "o\nut"

    ok = navseq("validate", good, cwd=tmp_path, timeout=GENEROUS)
    assert ok.returncode == 0, ok.stderr
    no_raw_line_break_from("to\nur.yaml", ok.stdout)

    refused = navseq("validate", bad, cwd=tmp_path, timeout=GENEROUS)
    message = one_message(refused)
    assert message.count("\n") == 2  # the summary line and one problem
    no_raw_line_break_from("ba\nd.yaml", message)

    ran = navseq("run", good, "--navigator", "scripted", "--out", out, cwd=tmp_path, timeout=60)
    assert ran.returncode == 0, ran.stderr
    no_raw_line_break_from("o\nut", ran.stdout)
    no_raw_line_break_from("to\nur.yaml", ran.stdout)

    (out / "report.json").unlink()
    for args in (("report", out), ("run", "--resume", out / "journal.jsonl")):
        result = navseq(*args, cwd=tmp_path, timeout=60)
        no_raw_line_break_from("o\nut", result.stdout + result.stderr)

    converted = navseq("convert", good, tmp_path / "c\nv.yaml", cwd=tmp_path, timeout=GENEROUS)
    assert converted.returncode == 0, converted.stderr
    no_raw_line_break_from("c\nv.yaml", converted.stdout)
    no_raw_line_break_from("to\nur.yaml", converted.stdout)


def test_error_text_keeps_only_the_line_breaks_between_listed_problems():
    from navseq.errors import MissionErrors, error_text

    errors = [
        NavseqError("unknown key", source="a\nb.yaml:3", subject="field \x1b[2Jx"),
        NavseqError("the journal x\ny holds the run", source="run"),
    ]
    shown = error_text(MissionErrors(errors, context="map m\nap.yaml"))
    assert shown.splitlines() == [
        "2 problems found (map m\\nap.yaml):",
        "  - a\\nb.yaml:3, field \\x1b[2Jx: unknown key",
        "  - run: the journal x\\ny holds the run",
    ]
    rosmaster = NavseqError("could not start rosmaster", source="ROS", details="  one\n  two\x1b")
    assert error_text(rosmaster).splitlines() == [
        "ROS: could not start rosmaster:",
        "  one",
        "  two\\x1b",
    ]
