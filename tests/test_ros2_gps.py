"""GPS waypoints on the ROS 2 simulator node: nav2_simple_commander's
``followGpsWaypoints()`` (from the real Nav2 tree) unchanged, converted with the node's
``--datum``, and navsat_transform's ``fromLL`` with the same datum."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from cli_support import EXAMPLES, NAVSEQ
from nav2_real_support import nav2_missing_reason, nav2_prefix
from ros2_support import ros2_environment
from test_ros2_sim import MAP, SPEED, START, SimProcess

pytestmark = pytest.mark.ros2

COMMANDER = Path(__file__).with_name("nav2") / "commander_gps.py"
# examples/gps.yaml's datum and two of its gates: south-gate (-0.55, -1.75) and
# east-dock (1.75, -0.55) in the map frame.
DATUM = "52.0116,4.3571,0"
SOUTH_GATE, EAST_DOCK = "52.01158427,4.35709199", "52.01159506,4.3571255"


def test_nav2_simple_commander_follows_gps_waypoints_unchanged() -> None:
    reason = nav2_missing_reason()
    if reason is not None:
        pytest.skip(reason)
    prefix = nav2_prefix()
    assert prefix is not None
    node = SimProcess(
        ros2_environment(prefix),
        "--map",
        str(MAP),
        f"--start={START}",
        "--speed",
        SPEED,
        "--datum",
        DATUM,
    )
    try:
        done = subprocess.run(
            [sys.executable, str(COMMANDER), SOUTH_GATE, EAST_DOCK],
            env=node.env,
            capture_output=True,
            text=True,
            timeout=180,
        )
    finally:
        err = node.stop()
    assert done.returncode == 0, done.stderr[-3000:]
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert seen["result"] == "SUCCEEDED", seen
    assert seen["feedback"] > 0
    x, y = seen["pose"]
    assert abs(x - 1.75) < 0.1 and abs(y + 0.55) < 0.1  # at east-dock
    assert seen["fromLL"] == [pytest.approx(-0.55, abs=0.01), pytest.approx(-1.75, abs=0.01)]
    assert "Traceback" not in err


@pytest.mark.parametrize("from_ll", [False, True], ids=["mission datum", "stack fromLL"])
def test_a_gps_mission_runs_on_nav2_converted_by_navseq_or_by_the_stack(
    tmp_path: Path, from_ll: bool
) -> None:
    """examples/gps.yaml on ``--navigator nav2``: converted with the mission's datum, or
    by the stack's fromLL (the stand-in's, with its datum 0.5 m east of the mission's:
    the robot then drives to the stack's idea of each position, 0.5 m west of navseq's)."""
    reason = nav2_missing_reason()
    if reason is not None:
        pytest.skip(reason)
    prefix = nav2_prefix()
    assert prefix is not None
    # 0.5 m of longitude at 52 N is 0.0000071 degrees.
    stack_datum = "52.0116,4.3571071,0" if from_ll else DATUM
    node = SimProcess(
        ros2_environment(prefix), "--map", str(MAP), f"--start={START}", "--speed", SPEED,
        "--datum", stack_datum,
    )  # fmt: skip
    extra = ["--from-ll", "fromLL"] if from_ll else []
    mission = tmp_path / "gps.yaml"
    text = (EXAMPLES / "gps.yaml").read_text().replace("../maps/", f"{MAP.parent}/")
    mission.write_text(text)
    try:
        done = subprocess.run(
            [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--json", "--out",
             str(tmp_path / "run"), *extra],
            env=node.env, cwd=tmp_path, capture_output=True, text=True, timeout=300,
        )  # fmt: skip
    finally:
        err = node.stop()
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    east_dock = report["visits"][1]
    assert (east_dock["name"], east_dock["outcome"]) == ("east-dock", "reached")
    expected_x = 1.263 if from_ll else 1.75  # the stack's datum is 0.487 m east
    assert east_dock["x"] == pytest.approx(expected_x, abs=0.02)
    assert "Traceback" not in err
