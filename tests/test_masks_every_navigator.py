"""GPS and keepout missions on every navigator: ``examples/gps.yaml`` and
``examples/keepout.yaml`` run on the embedded simulator, on ROS 1 (``navseq sim --ros1``,
its move_base stand-in given the masks) and on Nav2 (``navseq sim --ros2``). What a user
notices: every waypoint reached, the robot's trail never inside the keepout zone, and
slower in the speed zone. The ROS 2 stand-in also publishes Nav2's filter topics."""

from __future__ import annotations

import json
import math
import signal
import statistics
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest
from PIL import Image

from cli_support import EXAMPLES, NAVSEQ, REPO, TURTLEBOT3_MAP, navseq
from navseq.mission.robot import DEFAULT_PROFILE

KEEPOUT_MASK = REPO / "maps" / "turtlebot3_world_keepout.yaml"
START = "-2,-0.5,0"  # the examples' start:
TOP_SPEED = DEFAULT_PROFILE.max_linear_speed
SPEED_ZONE_SHARE = 0.4  # examples/keepout.yaml's speed zone: 40 % of the top speed
# s of the navigator's clock over which a speed is measured: over a ROS navigator's
# feedback, positions and stamps jitter by a sample; over 2 s that is a few percent.
SPEED_WINDOW = 2.0


def in_keepout_zone(x: float, y: float) -> bool:
    """The example keepout zone: x 0.15 .. 0.95, y below -1.35 (the south corridor)."""
    return 0.15 <= x <= 0.95 and y <= -1.35


def in_speed_zone(x: float, y: float) -> bool:
    """Well inside the example speed zone, |x|, |y| <= 0.75 (a cell's margin kept)."""
    return abs(x) < 0.65 and abs(y) < 0.65


def progress(stdout: str) -> list[dict[str, Any]]:
    """The ``--json`` WaypointProgress records: the robot's trail, in the run's time."""
    records = [json.loads(line) for line in stdout.splitlines() if line.startswith("{")]
    return [record for record in records if record["event"] == "WaypointProgress"]


def speeds(trail: list[dict[str, Any]], inside: bool) -> list[float]:
    """Speeds over SPEED_WINDOW stretches of one visit, wholly inside (or outside) the
    speed zone."""
    found = []
    for first, record in enumerate(trail):
        for later in trail[first + 1 :]:
            if later["index"] != record["index"]:
                break
            elapsed = later["t_s"] - record["t_s"]
            if elapsed < SPEED_WINDOW:
                continue
            stretch = [r for r in trail[first:] if r["t_s"] <= later["t_s"]]
            if all(in_speed_zone(r["x"], r["y"]) == inside for r in stretch):
                found.append((later["distance_m"] - record["distance_m"]) / elapsed)
            break
    return found


def assert_keepout_mission_as_nav2_would(stdout: str, report: dict[str, Any]) -> None:
    """Every waypoint reached, never in the keepout zone, slowed in the speed zone."""
    assert report["success"] is True, report["visits"]
    assert [visit["outcome"] for visit in report["visits"]] == ["reached"] * 4
    trail = progress(stdout)
    assert len(trail) > 100
    assert not [(r["x"], r["y"]) for r in trail if in_keepout_zone(r["x"], r["y"])]
    inside, outside = speeds(trail, inside=True), speeds(trail, inside=False)
    assert inside and outside
    limit = SPEED_ZONE_SHARE * TOP_SPEED
    assert statistics.median(inside) <= limit * 1.05, inside
    assert max(inside) <= limit * 1.2, inside
    assert max(outside) > 0.75 * TOP_SPEED, outside


def assert_gps_mission_reached(report: dict[str, Any]) -> None:
    assert report["success"] is True, report["visits"]
    visits = {visit["name"]: visit for visit in report["visits"]}
    assert all(visit["outcome"] == "reached" for visit in visits.values())
    # east-dock's latitude / longitude lands at (1.75, -0.55) in the map frame
    assert (visits["east-dock"]["x"], visits["east-dock"]["y"]) == (
        pytest.approx(1.75, abs=0.02),
        pytest.approx(-0.55, abs=0.02),
    )


def run_example(name: str, tmp_path: Path, *options: str, env: dict[str, str] | None = None):
    """``navseq run examples/NAME --json`` (with ``options``); its stdout and report."""
    out = tmp_path / f"run-{name}"
    done = subprocess.run(
        [NAVSEQ, "run", str(EXAMPLES / name), "--json", "--out", str(out), *options],
        env=env, cwd=tmp_path, capture_output=True, text=True, timeout=400,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout, json.loads((out / "report.json").read_text())


# -- the embedded simulator -------------------------------------------------------------


def test_the_keepout_mission_on_the_embedded_simulator(tmp_path: Path) -> None:
    stdout, report = run_example("keepout.yaml", tmp_path)
    assert_keepout_mission_as_nav2_would(stdout, report)


def test_the_gps_mission_on_the_embedded_simulator(tmp_path: Path) -> None:
    _, report = run_example("gps.yaml", tmp_path)
    assert_gps_mission_reached(report)


# -- the simulator's options ------------------------------------------------------------


def sim_config(*argv: str, ros1: bool = False):
    import argparse

    from navseq.commands.sim_options import add_arguments, config_from_args

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return config_from_args(parser.parse_args(["--map", str(TURTLEBOT3_MAP), *argv]), ros1=ros1)


def test_the_simulator_takes_masks_by_option_and_from_a_missions_filters() -> None:
    from navseq.mission.costmap_filters import FilterType

    from_mission = sim_config("--filters", str(EXAMPLES / "keepout.yaml")).filters
    assert [(f.mask.name, f.type, f.base, f.multiplier) for f in from_mission] == [
        ("turtlebot3_world_keepout.yaml", FilterType.KEEPOUT, 0.0, 1.0),
        ("turtlebot3_world_speed.yaml", FilterType.SPEED_PERCENT, 100.0, -1.0),
    ]
    by_option = sim_config(
        "--keepout",
        str(KEEPOUT_MASK),
        "--speed-mask",
        str(REPO / "maps" / "turtlebot3_world_speed.yaml"),
    ).filters
    assert [f.type for f in by_option] == [FilterType.KEEPOUT, FilterType.SPEED_PERCENT]
    assert by_option[1].multiplier == -1.0  # Nav2's speed-filter tutorial's filter info
    assert sim_config().filters == ()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--keepout", "missing.yaml"], "--keepout: "),
        (["--filters", "missing.yaml"], "--filters: "),
        (["--filters", str(EXAMPLES / "gps.yaml")], "the mission has no filters:"),
    ],
)
def test_a_bad_mask_option_of_navseq_sim_is_one_clear_error(
    tmp_path: Path, argv: list[str], message: str
) -> None:
    done = navseq("sim", "--ros2", "--map", TURTLEBOT3_MAP, *argv, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr
    assert "Traceback" not in done.stderr


def test_a_mask_that_cannot_be_read_is_refused_before_a_node_starts(tmp_path: Path) -> None:
    broken = tmp_path / "broken.yaml"
    broken.write_text("image: nowhere.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    done = navseq("sim", "--ros1", "--map", TURTLEBOT3_MAP, "--keepout", broken, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert "the mask cannot be read" in done.stderr and "nowhere.pgm" in done.stderr
    assert "Traceback" not in done.stderr


# -- ROS 2: navseq sim --ros2 (the Nav2 stand-in) -----------------------------------------

FILTER_WATCHER = textwrap.dedent(
    """
    import json, signal, sys
    import rclpy
    from nav2_msgs.msg import CostmapFilterInfo, SpeedLimit
    from nav_msgs.msg import OccupancyGrid
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                         reliability=ReliabilityPolicy.RELIABLE)
    rclpy.init()
    node = Node("filter_watcher")
    seen = {"info": {}, "masks": {}, "speed_limits": []}

    def on_info(topic):
        def callback(msg):
            seen["info"][topic] = [msg.type, msg.filter_mask_topic, msg.base, msg.multiplier]
        return callback

    def on_mask(topic):
        def callback(msg):
            seen["masks"][topic] = [msg.info.width, msg.info.height, msg.header.frame_id]
        return callback

    for kind in ("keepout", "speed"):
        node.create_subscription(CostmapFilterInfo, f"/{kind}_costmap_filter_info",
                                 on_info(kind), latched)
        node.create_subscription(OccupancyGrid, f"/{kind}_filter_mask", on_mask(kind), latched)
    node.create_subscription(
        SpeedLimit, "/speed_limit",
        lambda msg: seen["speed_limits"].append([msg.percentage, msg.speed_limit]), 10)
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    print("watching", flush=True)
    while not stop:
        rclpy.spin_once(node, timeout_sec=0.05)
    print(json.dumps(seen), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    """
)


def ros2_env() -> dict[str, str]:
    from ros2_support import ros2_environment, ros2_prefix

    prefix = ros2_prefix()
    if prefix is None:
        pytest.skip("no ROS 2 here")
    return ros2_environment(prefix)


@pytest.mark.ros2
def test_the_keepout_mission_on_nav2_with_the_filter_topics(tmp_path: Path) -> None:
    """The stand-in given the mission's filters (``--filters``): the mission as on the
    embedded simulator, and the masks, their filter info and ``speed_limit`` published
    as a bringup with Nav2's keepout and speed filters does."""
    from test_ros2_sim import SPEED, SimProcess

    env = ros2_env()
    sim = SimProcess(
        env, "--map", str(TURTLEBOT3_MAP), f"--start={START}", "--speed", SPEED,
        "--filters", str(EXAMPLES / "keepout.yaml"),
    )  # fmt: skip
    watcher = subprocess.Popen(
        [sys.executable, "-c", FILTER_WATCHER], env=env, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert watcher.stdout is not None and watcher.stdout.readline().strip() == "watching"
        stdout, report = run_example("keepout.yaml", tmp_path, "--navigator", "nav2", env=env)
    finally:
        if watcher.poll() is None:
            watcher.send_signal(signal.SIGINT)
        seen_out, watcher_err = watcher.communicate(timeout=30)
        err = sim.stop()
    assert_keepout_mission_as_nav2_would(stdout, report)
    assert "keepout zones of turtlebot3_world_keepout.yaml" in "".join(sim.stdout)
    assert "Traceback" not in err
    assert seen_out.strip(), watcher_err
    seen = json.loads(seen_out.strip().splitlines()[-1])
    assert seen["info"] == {
        "keepout": [0, "/keepout_filter_mask", 0.0, 1.0],
        "speed": [1, "/speed_filter_mask", 100.0, -1.0],
    }
    assert seen["masks"] == {"keepout": [100, 100, "map"], "speed": [100, 100, "map"]}
    # Into the centre square (40 %) and out of it again (0: no limit), as the SpeedFilter.
    assert [True, pytest.approx(40.0)] in seen["speed_limits"], seen
    assert seen["speed_limits"][-1] == [True, 0.0], seen


@pytest.mark.ros2
def test_the_filter_servers_are_lifecycle_nodes_under_their_managers_as_in_nav2(
    tmp_path: Path,
) -> None:
    """The mask and filter info servers are lifecycle nodes of nav2_bringup's names, one
    manager per kind: pausing the keepout zone's manager deactivates its two servers
    (the mask service answers empty) and leaves navigation active; resuming activates
    them, and they publish the mask and its filter info again, as Nav2's on_activate."""
    from test_ros2_sim import SPEED, SimProcess

    env = ros2_env()
    sim = SimProcess(
        env, "--map", str(TURTLEBOT3_MAP), f"--start={START}", "--speed", SPEED,
        "--filters", str(EXAMPLES / "keepout.yaml"),
    )  # fmt: skip
    try:
        nodes = subprocess.run(
            ["ros2", "node", "list", "--no-daemon"],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        seen = sim.client("filters")
        navigation = sim.client("manage", "resume")  # changes nothing: says the state
    finally:
        err = sim.stop()
    assert "Traceback" not in err
    listed = set(nodes.stdout.split())
    assert {
        "/keepout_filter_mask_server",
        "/keepout_costmap_filter_info_server",
        "/lifecycle_manager_keepout_zone",
        "/speed_filter_mask_server",
        "/speed_costmap_filter_info_server",
        "/lifecycle_manager_speed_zone",
    } <= listed, nodes.stdout
    active = {
        "is_active": True,
        "keepout_filter_mask_server": "active",
        "keepout_costmap_filter_info_server": "active",
        "map_service": [100, 100],
    }
    assert seen["at_start"] == active
    assert seen["pause"] == {
        "success": True,
        "is_active": False,
        "keepout_filter_mask_server": "inactive",
        "keepout_costmap_filter_info_server": "inactive",
        "map_service": [0, 0],
    }
    assert seen["resume"] == {"success": True, **active}
    assert seen["masks"] == [[100, 100, "map"]] * 2
    assert seen["infos"] == [[0, "/keepout_filter_mask"]] * 2
    assert navigation["bt_navigator"] == "active" and navigation["spin_accepted"]


@pytest.mark.ros2
def test_a_goal_deep_in_a_keepout_zone_is_refused_by_nav2s_planner(tmp_path: Path) -> None:
    """A keepout square 1.3 m wide: its centre is further from any allowed cell than the
    planner's tolerance (0.5 m), so compute_path_to_pose fails as NavFn does on Nav2's
    keepout filter's lethal cells; without the mask the same goal is planned."""
    from test_ros2_sim import SPEED, SimProcess

    mask = tmp_path / "square.yaml"
    Image.new("L", (26, 26), 0).save(tmp_path / "square.pgm")  # black: keepout
    mask.write_text(
        "image: square.pgm\nmode: trinary\nresolution: 0.05\norigin: [-2.3, -0.1, 0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    env = ros2_env()
    goal = "-1.65,0.55,0"
    results = {}
    for masked in (False, True):
        extra = ["--keepout", str(mask)] if masked else []
        sim = SimProcess(
            env, "--map", str(TURTLEBOT3_MAP), f"--start={START}", "--speed", SPEED, *extra
        )
        try:
            results[masked] = sim.client("path", goal)
        finally:
            assert "Traceback" not in sim.stop()
    assert results[False]["status"] == "SUCCEEDED", results
    assert results[True]["status"] == "ABORTED", results
    assert results[True]["points"] == 0, results


@pytest.mark.ros2
def test_the_gps_mission_on_nav2(tmp_path: Path) -> None:
    from test_ros2_sim import SPEED, SimProcess

    env = ros2_env()
    sim = SimProcess(env, "--map", str(TURTLEBOT3_MAP), f"--start={START}", "--speed", SPEED)
    try:
        _, report = run_example("gps.yaml", tmp_path, "--navigator", "nav2", env=env)
    finally:
        assert "Traceback" not in sim.stop()
    assert_gps_mission_reached(report)


# -- ROS 1: navseq sim --ros1 (the move_base stand-in) -------------------------------------


@pytest.mark.ros
@pytest.mark.parametrize("example", ["keepout.yaml", "gps.yaml"])
def test_the_examples_on_ros1(ros_master, tmp_path: Path, example: str) -> None:
    from test_ros1_sim_cli import SimCommand

    filters = ["--filters", str(EXAMPLES / "keepout.yaml")] if example == "keepout.yaml" else []
    sim = SimCommand(ros_master.env, "--start", START, "--speed", "5", *filters)
    try:
        ready = sim.wait_ready()
        stdout, report = run_example(example, tmp_path, "--navigator", "ros1", env=ros_master.env)
        sim.popen.send_signal(signal.SIGINT)
        assert sim.wait() == 0, sim.output()
    finally:
        sim.kill()
    assert "Traceback" not in sim.output()
    if example == "keepout.yaml":
        assert "speed zones of turtlebot3_world_speed.yaml" in ready
        assert_keepout_mission_as_nav2_would(stdout, report)
    else:
        assert_gps_mission_reached(report)


def test_the_trail_checks_can_fail() -> None:
    """The helpers see a trail through the zone and a fast one in the speed zone."""
    trail = [
        {"event": "WaypointProgress", "index": 0, "t_s": t, "x": -0.5 + 0.2 * t, "y": 0.0,
         "distance_m": 0.2 * t}
        for t in range(6)
    ]  # fmt: skip
    assert max(speeds(trail, inside=True)) == pytest.approx(0.2)  # |x| < 0.65: t 0 .. 5
    assert in_keepout_zone(0.55, -1.75) and not in_keepout_zone(-0.55, -1.75)
    assert math.isclose(SPEED_ZONE_SHARE * TOP_SPEED, 0.088)
