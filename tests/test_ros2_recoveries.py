"""A retry's recoveries on ``--navigator nav2``: Nav2's behaviour actions (spin, backup,
wait) and both costmaps' clear services, against the ROS 2 stand-in over real rclpy.

As in test_ros2_navigator: the sim node and navseq run as subprocesses on a private
ROS_DOMAIN_ID; nothing imports rclpy in pytest's process.
"""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cli_support import NAVSEQ, REPO, journal_events, write_mission
from ros2_support import SimNode, ros2_environment, ros2_prefix

pytestmark = pytest.mark.ros2

MAP = REPO / "maps" / "turtlebot3_world.yaml"


@pytest.fixture
def env() -> dict[str, str]:
    prefix = ros2_prefix()
    assert prefix is not None
    return ros2_environment(prefix)


@pytest.fixture
def sim(env: dict[str, str]) -> Iterator[SimNode]:
    node = SimNode(env, "--map", str(MAP), "--start=-2,-0.5,0", "--speed", "4")
    yield node
    assert "Traceback" not in node.stop()


def run_nav2(env: dict[str, str], mission: Path, out: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [NAVSEQ, "run", mission, "--navigator", "nav2", "--out", out, "--no-preflight"],
        env=env,
        cwd=out.parent,
        capture_output=True,
        text=True,
        timeout=180,
    )


def sim_log_sequence(log: str) -> list[str]:
    """The sim node's goals and clear-costmap calls, in the order it logged them."""
    kinds = {
        "navigate_to_pose: goal to": "goal",
        "global_costmap: cleared": "clear_global",
        "local_costmap: cleared": "clear_local",
    }
    return [kind for line in log.splitlines() for text, kind in kinds.items() if text in line]


def test_recoveries_run_on_nav2s_behaviour_server_before_the_retry(
    sim: SimNode, env: dict[str, str], tmp_path: Path
) -> None:
    # A goal beyond the arena's wall (pre-flight off): Nav2's planner aborts it, and the
    # retry too; between them the recoveries turn, back and wait the robot in the open.
    mission = write_mission(
        tmp_path / "wall.yaml",
        "  - {name: wall, x: -2.3, y: -2.3, yaw: 0}\n",
        "defaults: {retries: 1, on_failure: skip, goal_timeout: 60, "
        "recovery: [spin: 90, backup: 0.1, wait: 1, clear_costmaps]}\n",
    )
    done = run_nav2(env, mission, tmp_path / "out")
    assert done.returncode == 1, done.stderr
    report: dict[str, Any] = json.loads((tmp_path / "out" / "report.json").read_text())
    (visit,) = report["visits"]
    assert [a["status"] for a in visit["attempts"]] == ["ABORTED", "ABORTED"]
    runs = [(r["kind"], r["amount"], r["outcome"], r["attempt"]) for r in visit["recoveries_run"]]
    assert runs == [
        ("spin", 90, "succeeded", 2),
        ("backup", 0.1, "succeeded", 2),
        ("wait", 1, "succeeded", 2),
        ("clear_costmaps", None, "succeeded", 2),
    ]
    spin, backup, wait = visit["recoveries_run"][:3]
    assert wait["duration_s"] >= 1.0  # Nav2's wait ran its time, on the stack's clock
    journaled = journal_events(tmp_path / "out" / "journal.jsonl", "RecoveryFinished")
    assert [e["recovery_kind"] for e in journaled] == ["spin", "backup", "wait", "clear_costmaps"]
    # The clear services were called between the two goals.
    sequence = sim_log_sequence(sim.stop())
    assert sequence[0] == "goal" and sequence[-1] == "goal", sequence
    assert sorted(sequence[1:-1]) == ["clear_global", "clear_local"], sequence
    assert "Traceback" not in done.stderr
    assert spin["duration_s"] > 0 and backup["duration_s"] > 0
