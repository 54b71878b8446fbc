"""The public Python API: what ``import navseq`` offers, and docs/api.md's examples."""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import pytest

import navseq
from cli_support import REPO, TURTLEBOT3_MAP, write_mission
from cli_support import navseq as navseq_cli

API_DOC = REPO / "docs" / "api.md"


def python_blocks(doc: Path) -> list[tuple[str, str]]:
    """``(name, code)`` of every fenced python block of ``doc``."""
    code = re.findall(r"^```python\n(.*?)^```", doc.read_text(), flags=re.S | re.M)
    return [(f"{doc.name}:block{number + 1}", text) for number, text in enumerate(code)]


BLOCKS = python_blocks(API_DOC) + python_blocks(REPO / "README.md")


@pytest.mark.parametrize("name,code", BLOCKS, ids=[name for name, _ in BLOCKS])
def test_every_python_example_in_the_docs_runs(name, code, tmp_path, monkeypatch, capsys):
    # Each block on its own, in a fresh folder holding the repository's examples and maps.
    for folder in ("examples", "maps"):
        (tmp_path / folder).symlink_to(REPO / folder)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, name, "exec"), {})
    assert capsys.readouterr().out  # every example shows something


def test_the_docs_have_the_examples_they_promise():
    assert len([name for name, _ in BLOCKS if name.startswith("api.md")]) >= 6
    assert any(name.startswith("README.md") for name, _ in BLOCKS)


def test_every_public_name_resolves_and_nothing_else_does():
    for name in navseq.__all__:
        assert getattr(navseq, name) is not None
    assert set(navseq.__all__) == {"__version__", *navseq._EXPORTS}
    with pytest.raises(AttributeError):
        navseq.no_such_thing  # noqa: B018


def test_a_yaw_without_a_unit_is_refused_with_a_clear_message():
    with pytest.raises(TypeError, match=r"yaw_deg= .* or yaw_rad="):
        navseq.Waypoint(1.0, 2.0, yaw=90)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="has no unit"):
        navseq.Waypoint(1.0, 2.0, 90)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="not both"):
        navseq.Waypoint(1.0, 2.0, yaw_deg=90, yaw_rad=1.0)
    assert navseq.Waypoint(1.0, 2.0, yaw_deg=90) == navseq.Waypoint(1.0, 2.0, yaw_rad=math.pi / 2)
    assert navseq.Waypoint(1.0, 2.0, yaw_rad=math.pi).yaw_deg == pytest.approx(180.0)


def test_a_policy_names_its_units_and_refuses_a_name_without_one():
    with pytest.raises(TypeError, match=r"yaw_tolerance_deg= \(degrees"):
        navseq.Policy(yaw_tolerance=10)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match=r"goal_timeout_s= \(seconds"):
        navseq.Policy(goal_timeout=60)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="not both"):
        navseq.Policy(yaw_tolerance_deg=10, yaw_tolerance_rad=0.2)
    # Degrees as in mission files, or radians; either way the same policy.
    by_degrees = navseq.Policy(yaw_tolerance_deg=10, xy_tolerance_m=0.1, dwell_s=2)
    assert by_degrees == navseq.Policy(
        yaw_tolerance_rad=math.radians(10), xy_tolerance_m=0.1, dwell_s=2
    )
    assert by_degrees.yaw_tolerance_deg == pytest.approx(10)
    # A waypoint's overrides use the same names, checked when the waypoint is made.
    with pytest.raises(TypeError, match="dwell_s="):
        navseq.Waypoint(1.0, 2.0, yaw_deg=0, overrides={"dwell": 5})
    waypoint = navseq.Waypoint(1.0, 2.0, yaw_deg=0, overrides={"yaw_tolerance_deg": 5})
    assert dict(waypoint.overrides) == {"yaw_tolerance_rad": pytest.approx(math.radians(5))}
    assert by_degrees.with_overrides(waypoint.overrides).yaw_tolerance_deg == pytest.approx(5)


def test_mission_files_keep_their_keys_and_degrees(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(
        "defaults: {goal_timeout: 30, yaw_tolerance: 10, xy_tolerance: 0.1}\n"
        "waypoints:\n  - {x: 1, y: 2, yaw: 0, dwell: 4, pass_through: 0.3}\n"
    )
    mission = navseq.load_mission(path)
    policy = mission.policy_for(0)
    assert (policy.goal_timeout_s, policy.xy_tolerance_m) == (30.0, 0.1)
    assert policy.yaw_tolerance_deg == pytest.approx(10.0)
    assert (policy.dwell_s, policy.pass_through_m) == (4.0, 0.3)
    from navseq.mission import dump_mission_yaml

    written = dump_mission_yaml(mission)
    assert "yaw_tolerance: 10" in written and "goal_timeout: 30" in written
    assert "dwell: 4" in written and "_s:" not in written and "_m:" not in written


def test_check_mission_lists_every_problem_and_simulate_refuses_to_start(tmp_path):
    mission = navseq.Mission(
        (
            navseq.Waypoint(0.5, -1.6, name="fine"),
            navseq.Waypoint(1.1, 1.1, name="in-a-pillar"),
            navseq.Waypoint(50.0, 0.0, name="off-the-map"),
        ),
        map=Path(TURTLEBOT3_MAP),
        start=navseq.Pose2D(-2.0, -0.5, 0.0),
    )
    found = navseq.check_mission(mission)
    assert [p.subject for p in found] == ["waypoint 2 'in-a-pillar'", "waypoint 3 'off-the-map'"]
    assert "outside the map" in found[1].message
    with pytest.raises(navseq.MissionErrors) as refused:
        navseq.simulate(mission)
    assert len(refused.value.errors) == 2


def test_validate_file_finds_what_navseq_validate_finds(tmp_path):
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {x: 0.5, y: -1.6, yaw: 0, retries: -1}\n  - {x: 1.1, y: 1.1}\n",
        f"map: {TURTLEBOT3_MAP}\n",
    )
    found = navseq.validate_file(mission)
    cli = navseq_cli("validate", mission, cwd=tmp_path)
    assert cli.returncode == 2 and len(found) == 2
    for problem in found:
        assert str(problem) in cli.stderr


def test_simulate_gives_the_run_navseq_run_gives(tmp_path):
    text = "  - {name: south, x: 0.5, y: -1.6, yaw: 0}\n  - {name: east, x: 1.6, y: 0.5, yaw: 90}\n"
    path = write_mission(
        tmp_path / "arena.yaml",
        text,
        f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n",
    )
    cli = navseq_cli("run", path, "--out", tmp_path / "out", cwd=tmp_path)
    assert cli.returncode == 0, cli.stderr
    written = json.loads((tmp_path / "out" / "report.json").read_text())
    records: list[dict] = []
    result = navseq.simulate(
        navseq.load_mission(path), on_event=lambda e: records.append(navseq.event_record(e))
    )
    assert result.success and result.exit_code == written["exit_code"] == 0
    assert [round(v.duration_s, 2) for v in result.visits] == [
        v["duration_s"] for v in written["visits"]
    ]
    assert round(result.distance_m, 3) == written["totals"]["distance_m"]
    assert records[0]["event"] == "MissionStarted" and records[-1]["event"] == "MissionFinished"


def test_leaving_a_mission_run_early_stops_the_robot():
    mission = navseq.load_mission(REPO / "examples" / "turtlebot3_world.yaml")
    navigator = navseq.sim_navigator(mission)
    run = navseq.MissionRun(mission, navigator)
    for event in run:
        if isinstance(event, navseq.events.WaypointProgress) and event.distance_driven > 0.3:
            break
    stopped_at = navigator.robot_pose()
    navigator.spin(5.0)  # five more simulated seconds: a robot still driving moves ~1 m
    after = navigator.robot_pose()
    assert math.hypot(after.x - stopped_at.x, after.y - stopped_at.y) < 0.05
    assert run.result is None
    with pytest.raises(RuntimeError, match="runs once"):
        next(iter(run))


def test_a_mission_run_to_its_end_has_a_result():
    mission = navseq.Mission(
        (navseq.Waypoint(-0.55, -1.75, yaw_deg=0),),
        map=Path(TURTLEBOT3_MAP),
        start=navseq.Pose2D(-2.0, -0.5, 0.0),
    )
    run = navseq.MissionRun(mission, navseq.sim_navigator(mission))
    kinds = [type(event).__name__ for event in run]
    assert kinds[0] == "MissionStarted" and kinds[-1] == "MissionFinished"
    assert run.result is not None and run.result.success


def test_importing_navseq_does_not_load_the_api_until_used():
    # The CLI imports navseq for every command; the API must not slow that down.
    import subprocess
    import sys

    code = "import sys, navseq; print('navseq.api' in sys.modules, 'numpy' in sys.modules)"
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert done.stdout.split() == ["False", "False"]
