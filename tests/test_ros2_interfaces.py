"""The interfaces `navseq sim --ros2` serves against those of a default Nav2 Jazzy
bringup (navigation + localization + docking), kept as test data with its source in
``tests/data/nav2_bringup_interfaces.yaml``: every action, topic and service there is
served with the same type, except the data's short list of known gaps, each with its
reason — the list docs/ros2.md prints. A gap the stand-in serves after all fails too,
so the list stays true."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path
from typing import Any

import pytest
import yaml

from ros2_support import ros2_environment, ros2_prefix
from test_ros2_sim import MAP, REPO, SPEED, START, SimProcess

DATA = Path(__file__).with_name("data") / "nav2_bringup_interfaces.yaml"
DOCS = REPO / "docs" / "ros2.md"
DOCKS = REPO / "examples" / "turtlebot3_docks.yaml"
KINDS = ("actions", "topics", "services")
# `ros2 action list` has no --no-daemon; the daemon is stopped at the end.
LIST_COMMANDS = {
    "actions": ["ros2", "action", "list", "-t"],
    "topics": ["ros2", "topic", "list", "-t", "--no-daemon", "--spin-time", "3"],
    "services": ["ros2", "service", "list", "-t", "--no-daemon", "--spin-time", "3"],
}


def _data() -> dict[str, Any]:
    return dict(yaml.safe_load(DATA.read_text()))


def test_every_gap_is_an_interface_of_the_bringup_with_a_reason() -> None:
    data = _data()
    for kind in KINDS:
        for name, reason in data["gaps"][kind].items():
            assert name in data[kind], f"{kind} gap {name!r} is not in the bringup's list"
            assert isinstance(reason, str) and len(reason) > 10, name


def test_gaps_served_where_a_package_is_installed_are_gaps() -> None:
    data = _data()
    for kind, names in data.get("served_where_installed", {}).items():
        for name in names:
            assert name in data["gaps"][kind], f"{name!r} is served everywhere: not a gap"


def test_docs_print_every_gap_with_its_reason() -> None:
    text = DOCS.read_text()
    for kind in KINDS:
        for name, reason in _data()["gaps"][kind].items():
            row = f"| `{name}` | {kind[:-1]} | {reason} |"
            assert row in text, f"docs/ros2.md lacks the gap row {row!r}"


def _listed(output: str) -> dict[str, str]:
    found: dict[str, str] = {}
    for line in output.splitlines():
        match = re.fullmatch(r"/(\S+) \[(\S+)\]", line.strip())
        if match:
            found[match.group(1)] = match.group(2)
    return found


@pytest.mark.ros2
def test_the_stand_in_serves_a_default_bringups_interfaces_but_the_known_gaps() -> None:
    prefix = ros2_prefix()
    assert prefix is not None
    data = _data()
    sim = SimProcess(
        ros2_environment(prefix),
        "--map",
        str(MAP),
        f"--start={START}",
        "--speed",
        SPEED,  # /clock is published off wall-clock speed, as a simulated bringup has it
        "--docks",
        str(DOCKS),
    )
    served: dict[str, dict[str, str]] = {}
    try:
        for kind, command in LIST_COMMANDS.items():
            done = subprocess.run(command, env=sim.env, capture_output=True, text=True, timeout=60)
            assert done.returncode == 0, done.stderr
            served[kind] = _listed(done.stdout)
    finally:
        subprocess.run(["ros2", "daemon", "stop"], env=sim.env, capture_output=True, timeout=30)
        err = sim.stop()
    assert "Traceback" not in err
    for kind in KINDS:
        gaps = data["gaps"][kind]
        expected = {name: kind_ for name, kind_ in data[kind].items() if name not in gaps}
        missing = {
            name: wanted for name, wanted in expected.items() if served[kind].get(name) != wanted
        }
        assert not missing, f"{kind} not served with Nav2's type: {missing}"
        optional = data.get("served_where_installed", {}).get(kind, {})
        closed = sorted(
            name
            for name in gaps
            if served[kind].get(name) == data[kind][name] and name not in optional
        )
        wrong_type = {
            name: served[kind][name]
            for name in optional
            if name in served[kind] and served[kind][name] != data[kind][name]
        }
        assert not wrong_type, f"{kind} served without Nav2's type: {wrong_type}"
        assert not closed, f"{kind} served now: remove them from the gaps: {closed}"
