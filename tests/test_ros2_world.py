"""The Nav2 stand-in's world under ROS 2, as a Nav2 user sees it (issue 20): map_server
(``map``, ``map_server/map``, ``map_server/load_map`` and nav2_simple_commander's
``changeMap()``), the laser on ``scan``, amcl's ``initialpose`` / ``amcl_pose`` /
``particle_cloud``, the ``cmd_vel_nav`` -> ``cmd_vel_smoothed`` -> ``cmd_vel`` chain with
``speed_limit``, teleop, and Nav2's multi-robot TF convention."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from nav2_real_support import nav2_missing_reason, nav2_prefix
from navseq.sim.mapgen import office_map, save_map
from ros2_support import SimNode, ros2_environment, ros2_prefix
from test_ros2_sim import MAP, SPEED, START

pytestmark = pytest.mark.ros2

NAV2_SCRIPTS = Path(__file__).with_name("nav2")
GOAL = (-1.5, -0.5)
PARAM_GET = ["ros2", "param", "get", "--no-daemon", "--spin-time", "5", "--hide-type"]
INITIAL_POSE = (-1.0, 0.0)  # beside the robot: the estimate moves there, the robot stays
SERVICE_POSE = (-1.2, 0.1)  # set_initial_pose's: the same, through amcl's service


def run_script(env: dict[str, str], script: str, *args: str) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, str(NAV2_SCRIPTS / script), *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def maps(tmp_path: Path) -> dict[str, str]:
    """load_map's URLs: Nav2's three failures and a good map of another size."""
    office = save_map(office_map(3), tmp_path / "office.yaml")
    no_image = tmp_path / "no_image.yaml"
    no_image.write_text(
        "image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return {
        "empty": "",
        "missing_yaml": str(tmp_path / "nowhere.yaml"),
        "missing_image": str(no_image),
        "office": str(office),
    }


def test_the_world_a_nav2_user_sees(tmp_path: Path):
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    sim = SimNode(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED)
    setup = {
        "goal": GOAL,
        "speed_limit": 0.1,
        "initial_pose": INITIAL_POSE,
        "service_pose": SERVICE_POSE,
        "maps": maps(tmp_path),
    }
    try:
        seen = run_script(env, "world_client.py", json.dumps(setup))
        smoother = subprocess.run(
            [*PARAM_GET, "/velocity_smoother", "max_velocity"],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
    finally:
        err = sim.stop()
    assert sim.process.returncode == 0, err
    assert "Traceback" not in err
    # The limits the chain smooths with, where Nav2 keeps them (nav2_bringup's values).
    assert smoother.stdout.split() == ["[0.5,", "0.0,", "2.0]"], smoother
    # map_server: the arena, latched, and on map_server/map.
    assert seen["map"] == [384, 384, "map"]
    assert seen["get_map"] == [384, 384]
    # The LDS-01 on base_scan, which the static tree places on base_link.
    scan = seen["scan"]
    assert scan["frame"] == "base_scan" and scan["beams"] == 360
    assert scan["range"] == pytest.approx([0.12, 3.5])
    assert scan["finite"] > 100 and 0.12 <= scan["nearest"] <= 3.5
    assert "base_link->base_scan" in seen["static"]
    assert {"map->odom", "odom->base_footprint"} <= set(seen["tf"])
    # The goal drove through the chain, at the speed limit, smoothed within Nav2's limits.
    assert seen["goal_status"] == 4  # SUCCEEDED
    for stage in ("cmd_vel_nav", "cmd_vel_smoothed", "cmd_vel"):
        assert seen[stage]["count"] > 20, seen
        assert seen[stage]["max_v"] <= 0.1 + 1e-6, seen  # speed_limit 0.1 m/s
        assert seen[stage]["last"] == [0.0, 0.0], seen  # stopped at the goal
    assert seen["cmd_vel_smoothed"]["max_w"] <= 2.0 + 1e-6  # nav2_bringup's max_velocity
    # Teleop: cmd_vel from outside drives the robot while no goal runs.
    assert seen["teleop_moved"] > 0.1, seen
    # initialpose moved the estimate (amcl_pose, particle cloud, map -> odom), not the robot.
    assert seen["amcl_pose"][:2] == pytest.approx(list(INITIAL_POSE), abs=0.01)
    assert seen["amcl_pose"][2] == "map" and seen["particles"] == 200
    assert seen["odom_moved_on_initialpose"] < 0.01
    assert seen["map_to_odom"] != pytest.approx([-2.0, -0.5], abs=0.05)
    # amcl's services: set_initial_pose moves the estimate as initialpose does.
    assert seen["set_initial_pose"] == pytest.approx(list(SERVICE_POSE), abs=0.01)
    assert seen["empty_services"] == {
        "request_nomotion_update": True,
        "reinitialize_global_localization": True,
    }
    # load_map: Nav2's codes, and a good map replaces the published one.
    loads = seen["load_map"]
    assert loads["empty"]["result"] == 1  # RESULT_MAP_DOES_NOT_EXIST
    assert loads["missing_yaml"]["result"] == 3  # RESULT_INVALID_MAP_METADATA
    assert loads["missing_image"]["result"] == 2  # RESULT_INVALID_MAP_DATA
    for failed in ("empty", "missing_yaml", "missing_image"):
        assert loads[failed]["published"] is None  # the old map stays
    office = loads["office"]
    assert office["result"] == 0 and office["width"] not in (0, 384)
    assert office["published"] == office["width"]
    assert "load_map" in err and "failed (result 3)" in err


def test_nav2_simple_commanders_change_map_replaces_the_map(tmp_path: Path):
    reason = nav2_missing_reason()
    if reason is not None:
        pytest.skip(reason)
    prefix = nav2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    office = save_map(office_map(3), tmp_path / "office.yaml")
    sim = SimNode(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED)
    try:
        seen = run_script(env, "commander_change_map.py", str(office))
    finally:
        err = sim.stop()
    assert sim.process.returncode == 0, err
    assert seen["before"] == 384
    assert seen["after"] not in (None, 384)


def test_namespaced_robots_publish_nav2s_tf_convention_by_default():
    """``--ns robot1``: transforms on /robot1/tf and /robot1/tf_static with plain frames,
    as nav2_bringup's multi-robot launch; the topics under /robot1."""
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    sim = SimNode(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED, "--ns", "robot1")
    setup = {
        "ns": "robot1",
        "tf_topic": "/robot1/tf",
        "goal": GOAL,
        "speed_limit": 0.0,
        "initial_pose": INITIAL_POSE,
        "service_pose": SERVICE_POSE,
        "maps": {},
    }
    try:
        seen = run_script(env, "world_client.py", json.dumps(setup))
    finally:
        err = sim.stop()
    assert sim.process.returncode == 0, err
    assert {"map->odom", "odom->base_footprint"} <= set(seen["tf"])
    assert {"base_footprint->base_link", "base_link->base_scan"} <= set(seen["static"])
    assert seen["goal_status"] == 4 and seen["scan"]["frame"] == "base_scan"
    assert seen["cmd_vel"]["max_v"] > 0.2  # no speed limit: the burger's 0.22 m/s
