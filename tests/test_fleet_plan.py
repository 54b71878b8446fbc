"""``navseq plan --fleet``: fleet files checked at once, the waypoints split among robots."""

from __future__ import annotations

import json
from pathlib import Path

from bench_support import load_benchmark
from cli_support import EXAMPLES, TURTLEBOT3_MAP, assert_clean_error, navseq
from navseq.mission import load_mission

FLEET = EXAMPLES / "fleet.yaml"
MISSION = EXAMPLES / "turtlebot3_world.yaml"


def write_fleet(path: Path, robots: str, extra: str = "", mission: Path = MISSION) -> Path:
    path.write_text(
        f"navseq_fleet: 1\nmission: {mission}\nmap: {TURTLEBOT3_MAP}\nrobots:\n{robots}{extra}"
    )
    return path


def plan_json(*args: object, cwd: Path) -> dict:
    done = navseq("plan", "--fleet", *args, "--json", cwd=cwd)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_the_example_fleet_is_split_with_every_waypoint_once_and_rules_kept(
    tmp_path: Path,
) -> None:
    out = tmp_path / "shares"
    done = navseq("plan", "--fleet", FLEET, "--out", out, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    for name in ("alpha", "beta", "gamma", "fleet makespan"):
        assert name in done.stdout
    original = load_mission(MISSION)
    shares = {path.stem: load_mission(path) for path in sorted(out.glob("*.yaml"))}
    assert set(shares) <= {"alpha", "beta", "gamma"}
    written = [w.name for mission in shares.values() for w in mission.waypoints]
    assert sorted(written) == sorted(w.name for w in original.waypoints)  # each once
    # The fleet file lets only beta take east-dock; each share starts at its robot.
    assert "east-dock" in [w.name for w in shares["beta"].waypoints]
    assert shares["beta"].start is not None and shares["beta"].start.x == 2.0
    assert shares["beta"].robot is not None and shares["beta"].robot.name == "turtlebot3_waffle"
    assert all(m.defaults == original.defaults for m in shares.values())
    # gamma's max_time is kept.
    result = plan_json(FLEET, cwd=tmp_path)
    gamma = next(row for row in result["robots"] if row["name"] == "gamma")
    assert gamma["time_s"] <= 120
    assert result["makespan_s"] == max(row["time_s"] for row in result["robots"])


def test_shares_are_never_written_over_existing_files(tmp_path: Path) -> None:
    out = tmp_path / "shares"
    assert navseq("plan", "--fleet", FLEET, "--out", out, cwd=tmp_path).returncode == 0
    before = {path: path.read_bytes() for path in out.iterdir()}
    next(iter(before)).write_text("mine")
    kept = {path: path.read_bytes() for path in out.iterdir()}
    again = navseq("plan", "--fleet", FLEET, "--out", out, cwd=tmp_path)
    assert_clean_error(again)
    assert "not overwriting" in again.stderr
    assert {path: path.read_bytes() for path in out.iterdir()} == kept
    forced = navseq("plan", "--fleet", FLEET, "--out", out, "--force", cwd=tmp_path)
    assert forced.returncode == 0, forced.stderr
    assert {path: path.read_bytes() for path in out.iterdir()} == before


def test_every_problem_of_a_fleet_file_is_named_at_once_and_nothing_is_written(
    tmp_path: Path,
) -> None:
    fleet = write_fleet(
        tmp_path / "fleet.yaml",
        "  - name: alpha\n"  # line 5
        "    start: {x: -2.0, y: -0.5, yaw: 0}\n"
        "  - name: alpha\n"  # line 7: the name again
        "    start: {x: 2.0, y: 0.5, yaw: 0}\n"
        "  - name: gamma\n"  # line 9: beta's namespace
        "    namespace: alpha\n"
        "    start: {x: 0.5, y: 2.0}\n"
        "    speed: 3\n",  # line 12: no such key
        "waypoints:\n"
        "  east-dock: {robots: [zeta]}\n"  # line 14: no such robot
        "  nowhere: {robots: [alpha]}\n",  # line 15: no such waypoint
    )
    out = tmp_path / "shares"
    done = navseq("plan", "--fleet", fleet, "--out", out, cwd=tmp_path)
    assert_clean_error(done)
    for where, what in (
        ("fleet.yaml:7", "has the name 'alpha'"),
        ("fleet.yaml:12", "unknown key"),
        ("fleet.yaml:14", "'zeta' is none of the fleet's robots"),
        ("fleet.yaml:15", "names no waypoint"),
    ):
        assert any(where in line and what in line for line in done.stderr.splitlines()), (
            where,
            done.stderr,
        )
    assert not out.exists()


def test_start_poses_in_walls_or_on_each_other_are_refused_together(tmp_path: Path) -> None:
    fleet = write_fleet(
        tmp_path / "fleet.yaml",
        "  - name: alpha\n"  # line 5
        "    start: {x: -2.0, y: -0.5, yaw: 0}\n"
        "  - name: beta\n"  # line 7: on alpha
        "    start: {x: -1.95, y: -0.5, yaw: 0}\n"
        "  - name: gamma\n"  # line 9: inside the centre pillar
        "    start: {x: 0.0, y: 0.0, yaw: 0}\n",
    )
    done = navseq("plan", "--fleet", fleet, cwd=tmp_path)
    assert_clean_error(done)
    assert "2 problems found" in done.stderr
    assert "fleet.yaml:7, robot 'beta', field start: starts on robot 'alpha'" in done.stderr
    assert "fleet.yaml:9, robot 'gamma', field start" in done.stderr
    assert "obstacle" in done.stderr


def test_a_waypoint_no_robot_may_take_is_refused(tmp_path: Path) -> None:
    mission = tmp_path / "mission.yaml"
    mission.write_text(
        "navseq: 1\nwaypoints:\n"
        "  - {name: open, x: -1.0, y: -1.6, yaw: 0}\n"
        "  - {name: outside, x: 6.0, y: 6.0, yaw: 0}\n"  # line 4: off the arena
    )
    fleet = write_fleet(
        tmp_path / "fleet.yaml",
        "  - name: alpha\n    start: {x: -2.0, y: -0.5, yaw: 0}\n"
        "  - name: beta\n    start: {x: 2.0, y: 0.5, yaw: 180}\n",
        "waypoints:\n  open: {robots: []}\n",
        mission=mission,
    )
    done = navseq("plan", "--fleet", fleet, cwd=tmp_path)
    assert_clean_error(done)
    assert "lists no robot" in done.stderr
    fleet.write_text(fleet.read_text().replace("robots: []", "robots: [beta]"))
    done = navseq("plan", "--fleet", fleet, cwd=tmp_path)
    assert_clean_error(done)
    assert "mission.yaml:4, waypoint 2 'outside': no robot may take this waypoint" in done.stderr


def test_a_mission_on_the_command_line_replaces_the_fleet_s(tmp_path: Path) -> None:
    mission = tmp_path / "two.yaml"
    mission.write_text(
        "navseq: 1\nwaypoints:\n  - {name: a, x: -1.0, y: -1.6}\n"
        "  - {name: east-dock, x: 1.0, y: 1.6}\n"
    )
    result = plan_json(FLEET, mission, cwd=tmp_path)
    assert sorted(n for row in result["robots"] for n in row["waypoints"]) == [1, 2]


def test_one_robot_s_options_are_refused_with_a_fleet(tmp_path: Path) -> None:
    done = navseq("plan", "--fleet", FLEET, "--order", "shortest", cwd=tmp_path)
    assert_clean_error(done)
    assert "--order" in done.stderr


def test_three_robots_finish_60_warehouse_waypoints_in_at_most_0_4_of_one_robot_s_time() -> None:
    bench = load_benchmark("bench_fleet_split")
    fleet, costmap = bench.warehouse_fleet(seed=0, waypoints=60, robots=3)
    alone = bench.makespan(bench.one_robot(fleet), costmap, time_limit_s=2.0)
    together = bench.makespan(fleet, costmap, time_limit_s=2.0)
    assert together <= 0.40 * alone, (together, alone)
