"""Every fenced block of the README and docs/ runs in the tests, or says why it cannot.

How each kind of block is run:

- shell (``bash``, ``sh``, ``console``): each command by its rule in
  ``tests/test_docs_examples.py``; a block whose commands all need ROS (rule ``ros``:
  only a named test runs the same thing) must say so with a marker;
- ``python``: executed by ``tests/test_api.py`` (README.md and docs/api.md);
  ``python ros1``: executed here against ``navseq sim --ros1`` on a private rosmaster;
- ``yaml``, ``xml``, ``csv`` holding a mission (navseq YAML, rosparam, the tutorial's
  launch file, recorded poses): loaded here by ``navseq.load_mission``; a ``yaml``
  block of only a ``robot:`` section is read as a robot file (``--robot FILE``), one
  starting with ``navseq_fleet:`` as a fleet file (docs/fleet.md);
- ``json``: a report (``schema_version`` and ``mission``) is checked here against
  ``docs/schemas/report.schema.json``, one event per line against the events schema.

Anything else — output shown as an illustration, a fragment, a command for a machine
the tests do not have — is preceded by ``<!-- not run here: REASON -->``.
"""

from __future__ import annotations

import json
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest

from docs_examples import Block, blocks_in, examples_in
from test_docs_examples import DOC_FILES, REPO, rule_for

SHELL = {"bash", "sh", "shell", "console"}
MISSION_SUFFIXES = {"yaml": ".yaml", "xml": ".launch", "csv": ".csv"}
SCHEMAS = REPO / "docs" / "schemas"
ALL_BLOCKS = [block for doc in DOC_FILES for block in blocks_in(doc)]


def _executed_python() -> set[str]:
    from test_api import BLOCKS

    return {code for _, code in BLOCKS}


def _shell_block_runs(block: Block) -> bool:
    commands = [
        example
        for example in examples_in(block.path)
        if block.line < example.line <= block.line + block.text.count("\n") + 1
    ]
    return any(rule_for(example.command).kind != "ros" for example in commands)


def why_not_run(block: Block) -> str | None:
    """None when the tests run the block, else what is missing."""
    if block.language in SHELL:
        return None if _shell_block_runs(block) else "every command needs ROS"
    if block.language == "python":
        if block.info == "ros1" or block.text in _executed_python():
            return None
        return "tests/test_api.py does not execute it"
    if block.language in MISSION_SUFFIXES or block.language == "json":
        return None
    return f"nothing runs a {block.language or 'plain'} block"


def test_every_block_is_run_or_says_why_not() -> None:
    unrun = [
        f"{block.where} ({reason})"
        for block in ALL_BLOCKS
        if block.not_run_because is None and (reason := why_not_run(block))
    ]
    assert unrun == [], (
        "blocks that no test runs: run them, or put `<!-- not run here: REASON -->` "
        "on the line before"
    )


def test_a_not_run_marker_gives_a_reason_and_the_tests_it_names_exist() -> None:
    for block in ALL_BLOCKS:
        if block.not_run_because is not None:
            assert len(block.not_run_because.split()) >= 3, f"{block.where}: say why"
            for test_file in re.findall(r"tests/\w+\.py", block.not_run_because):
                assert (REPO / test_file).is_file(), f"{block.where}: no {test_file}"


def _blocks(*languages: str) -> list[Block]:
    return [
        block
        for block in ALL_BLOCKS
        if block.language in languages and block.not_run_because is None
    ]


@pytest.mark.parametrize("block", _blocks(*MISSION_SUFFIXES), ids=lambda block: block.where)
def test_a_mission_block_loads(block: Block, tmp_path: Path) -> None:
    import navseq

    # Beside the examples, as the docs' relative map paths (../maps/...) expect.
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    (tmp_path / "examples").mkdir()
    path = tmp_path / "examples" / f"doc{MISSION_SUFFIXES[block.language]}"
    path.write_text(block.text, encoding="utf-8")
    if block.text.startswith("navseq_fleet:"):  # a fleet file, its mission beside it
        from navseq.fleet.fleet_format import load_fleet

        shutil.copytree(REPO / "examples", tmp_path / "examples", dirs_exist_ok=True)
        assert load_fleet(path).robots
        return
    if block.text.startswith("robot:\n"):  # a robot file (`--robot FILE`), not a mission
        from navseq.mission.robot_format import read_robot_file

        assert read_robot_file(path).footprint
        return
    mission = navseq.load_mission(path)
    assert len(mission.waypoints) >= 1


@pytest.mark.parametrize("block", _blocks("json"), ids=lambda block: block.where)
def test_a_json_block_follows_its_schema(block: Block) -> None:
    try:
        records = [json.loads(block.text)]
    except json.JSONDecodeError:
        records = [json.loads(line) for line in block.text.splitlines() if line.strip()]
    for record in records:
        kind = "report" if "mission" in record and "event" not in record else "events"
        schema = json.loads((SCHEMAS / f"{kind}.schema.json").read_text())
        jsonschema.validate(record, schema)


ROS1_BLOCKS = [block for block in ALL_BLOCKS if (block.language, block.info) == ("python", "ros1")]


@pytest.mark.ros
@pytest.mark.parametrize("block", ROS1_BLOCKS, ids=lambda block: block.where)
def test_a_ros1_python_block_completes_on_the_ros1_simulator(
    block: Block, ros_master, tmp_path: Path
) -> None:
    for folder in ("examples", "maps"):
        (tmp_path / folder).symlink_to(REPO / folder)
    navseq = [str(Path(sys.executable).parent / "navseq"), "sim", "--ros1"]
    sim = subprocess.Popen(
        [*navseq, "--map", str(REPO / "maps/turtlebot3_world.yaml"), "--start", "-2,-0.5,0"],
        env=ros_master.env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        ros_master.wait_for_action_server("/move_base", timeout=60)
        done = subprocess.run(
            [sys.executable, "-c", block.text],
            cwd=tmp_path,
            env=ros_master.env,
            capture_output=True,
            text=True,
            timeout=300,
        )
    finally:
        sim.send_signal(signal.SIGINT)
        sim.wait(timeout=30)
    assert done.returncode == 0, f"{block.where}:\n{done.stdout[-2000:]}{done.stderr[-3000:]}"
    assert done.stdout.splitlines()[-1].startswith("True ")  # every waypoint reached
