"""``navseq plan``: the legs a robot will drive, and the order that drives the least."""

from __future__ import annotations

import json
from pathlib import Path

from cli_support import EXAMPLES, TURTLEBOT3_MAP, assert_clean_error, navseq, write_mission
from navseq.mission import load_mission

EXAMPLE = EXAMPLES / "turtlebot3_world.yaml"


def plan_json(*args: object, cwd: Path) -> dict:
    done = navseq("plan", *args, "--json", cwd=cwd)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_the_example_s_legs_are_planned_around_the_pillars(tmp_path: Path) -> None:
    route = plan_json(EXAMPLE, cwd=tmp_path)
    legs = route["legs"]
    assert [leg["to"] for leg in legs] == [1, 2, 3, 4, 5, 6, 7]
    assert legs[0]["from"] == "start"  # the example has a start pose
    # A planned leg is never shorter than the straight line, and pillars make some longer.
    assert all(leg["length_m"] >= leg["straight_m"] - 0.05 for leg in legs)
    assert any(leg["length_m"] > leg["straight_m"] + 0.3 for leg in legs)
    assert route["length_m"] == round(sum(leg["length_m"] for leg in legs), 3)
    assert route["duration_s"] == round(route["length_m"] / route["max_speed_m_s"], 1)
    assert route["order"] == [1, 2, 3, 4, 5, 6, 7]


def test_the_table_names_every_leg_and_the_route_s_total(tmp_path: Path) -> None:
    done = navseq("plan", EXAMPLE, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    total = plan_json(EXAMPLE, cwd=tmp_path)["length_m"]
    assert f"route: 7 waypoints, {total:.2f} m" in done.stdout
    assert "north-dock" in done.stdout and "start → 1" in done.stdout


def test_the_shortest_order_is_shorter_and_is_written_only_where_asked(tmp_path: Path) -> None:
    out = tmp_path / "ordered.yaml"
    done = navseq("plan", EXAMPLE, "--order", "shortest", "--out", out, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    route = plan_json(EXAMPLE, "--order", "shortest", cwd=tmp_path)
    assert route["length_m"] < route["length_in_file_order_m"]
    original, ordered = load_mission(EXAMPLE), load_mission(out)
    # The same waypoints and settings, in the order shown.
    assert [w.name for w in ordered.waypoints] == [
        original.waypoints[number - 1].name for number in route["order"]
    ]
    assert sorted(ordered.waypoints, key=lambda w: w.name or "") == sorted(
        original.waypoints, key=lambda w: w.name or ""
    )
    assert ordered.start == original.start and ordered.defaults == original.defaults
    # The written file's own route is the one shown.
    assert plan_json(out, cwd=tmp_path)["length_m"] == route["length_m"]
    # Never over a file that exists, unless asked.
    before = out.read_bytes()
    again = navseq("plan", EXAMPLE, "--order", "shortest", "--out", out, cwd=tmp_path)
    assert_clean_error(again)
    assert "exists already" in again.stderr
    assert out.read_bytes() == before


def test_keep_last_ends_the_route_at_the_file_s_last_waypoint(tmp_path: Path) -> None:
    route = plan_json(EXAMPLE, "--order", "shortest", "--keep-last", cwd=tmp_path)
    assert route["order"][-1] == 7
    free = plan_json(EXAMPLE, "--order", "shortest", cwd=tmp_path)
    assert free["length_m"] <= route["length_m"] <= route["length_in_file_order_m"]


def test_without_a_map_legs_are_straight_lines(tmp_path: Path) -> None:
    mission = write_mission(
        tmp_path / "line.yaml",
        "  - {x: 0, y: 0, yaw: 0}\n  - {x: 3, y: 4, yaw: 0}\n  - {x: 1, y: 0, yaw: 0}\n",
    )
    route = plan_json(mission, "--order", "shortest", cwd=tmp_path)
    assert route["map"] is None
    assert route["order"] == [1, 3, 2]
    assert route["length_m"] == round(1.0 + (2.0**2 + 4.0**2) ** 0.5, 3)


def test_a_leg_with_no_path_is_shown_and_the_exit_says_so(tmp_path: Path) -> None:
    # The centre of a pillar: no path leads there.
    mission = write_mission(
        tmp_path / "pillar.yaml",
        "  - {x: -0.55, y: -1.75, yaw: 0}\n  - {x: 1.1, y: 1.1, yaw: 0}\n",
        header=f"map: {TURTLEBOT3_MAP}\n",
    )
    done = navseq("plan", mission, cwd=tmp_path)
    assert done.returncode == 1, done.stderr
    assert "no path" in done.stdout and "navseq validate" in done.stdout
    assert "Traceback" not in done.stderr


def test_bad_options_are_one_clear_message(tmp_path: Path) -> None:
    for args, named in [
        (("--time-limit", "0"), "--time-limit"),
        (("--map", tmp_path / "none.yaml"), "--map"),
        (("--keep-last",), "--order shortest"),
    ]:
        done = navseq("plan", EXAMPLE, *args, cwd=tmp_path)
        assert_clean_error(done)
        assert named in done.stderr
    missing = navseq("plan", tmp_path / "none.yaml", cwd=tmp_path)
    assert_clean_error(missing)
    assert "none.yaml" in missing.stderr
