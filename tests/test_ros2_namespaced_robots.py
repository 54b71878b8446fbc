"""Two and three namespaced robots on the Nav2 stand-in, each driven by its own
``navseq run --navigator nav2 --ns robotN`` at the same time: one simulator node per
robot (Nav2's multi-robot convention, ``/robotN/tf``), each seeing the others, on one
simulated clock (robot1 publishes ``/clock`` at 4x, the others follow it)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from cli_support import NAVSEQ, TURTLEBOT3_MAP
from ros2_support import SimNode, ros2_environment, ros2_prefix

pytestmark = pytest.mark.ros2

# Each robot's start and its one waypoint, in parts of the arena of their own so that
# none waits for another: the west side northwards, the east side southwards, and from
# the north dock in between the northern pillars.
ROBOTS = {
    "robot1": ("-2.0,-0.5,90", (-1.75, 0.55, -90.0)),
    "robot2": ("2.0,0.5,-90", (1.75, -0.55, 90.0)),
    "robot3": ("0.0,1.75,-90", (0.55, 0.55, 180.0)),
}


@pytest.mark.flaky(reruns=1)  # several nodes in real time on a busy machine
@pytest.mark.parametrize("count", [2, 3])
def test_namespaced_robots_each_run_their_own_mission_at_once(tmp_path: Path, count: int):
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    names = list(ROBOTS)[:count]
    nodes: list[SimNode] = []
    runs: dict[str, subprocess.Popen[str]] = {}
    try:
        for name in names:
            start, _ = ROBOTS[name]
            others = ",".join(other for other in names if other != name)
            clock = ["--speed", "4"] if name == "robot1" else ["--follow-clock"]
            argv = ["--map", str(TURTLEBOT3_MAP), f"--start={start}", "--ns", name]
            nodes.append(SimNode(env, *argv, "--other-robots", others, *clock))
        for name in names:
            x, y, yaw = ROBOTS[name][1]
            start_x, start_y, start_yaw = ROBOTS[name][0].split(",")
            mission = tmp_path / f"{name}.yaml"
            mission.write_text(
                "navseq: 1\ndefaults: {goal_timeout: 120}\nwaypoints:\n"
                f"  - {{name: there, x: {x}, y: {y}, yaw: {yaw}}}\n"
                f"  - {{name: back, x: {start_x}, y: {start_y}, yaw: {start_yaw}}}\n"
            )
            runs[name] = subprocess.Popen(
                [NAVSEQ, "run", str(mission), "--navigator", "nav2", "--ns", name,
                 "--out", str(tmp_path / f"out-{name}")],
                env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                text=True,
            )  # fmt: skip
        outputs = {name: run.communicate(timeout=400) for name, run in runs.items()}
    finally:
        for run in runs.values():
            if run.poll() is None:
                run.kill()
                run.communicate()
        errors = [node.stop() for node in nodes]
    assert not [err for err in errors if "Traceback" in err]
    for name in names:
        assert runs[name].returncode == 0, (name, outputs[name][1][-3000:])
        report = json.loads((tmp_path / f"out-{name}" / "report.json").read_text())
        assert report["navigator"]["action"] == f"/{name}/navigate_to_pose"
        assert [visit["outcome"] for visit in report["visits"]] == ["reached", "reached"]
        # The robot's own pose (its /robotN/tf), where its own start is: not another's.
        start_x, start_y, _ = (float(value) for value in ROBOTS[name][0].split(","))
        assert report["start"]["x"] == pytest.approx(start_x, abs=0.05), (name, report["start"])
        assert report["start"]["y"] == pytest.approx(start_y, abs=0.05), (name, report["start"])
