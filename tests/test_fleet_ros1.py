"""``navseq run --fleet FLEET --navigator ros1``: ``multi_robot.launch``'s two namespaced
move_base stand-ins (robots that see each other but know no right of way), driven from
one navseq process whose fleet coordinator gives way among them, against a real
rosmaster. The ROS 2 twin, and the cases without the coordinator: tests/test_fleet_ros.py,
tests/test_fleet_coordinator.py."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from mcap.reader import make_reader

from cli_support import NAVSEQ
from navseq.sim.mapgen import save_map
from ros_support import RosMaster
from test_right_of_way import corridor_between_rooms

pytestmark = pytest.mark.ros

FLEET = """\
navseq_fleet: 1
map: corridor.yaml
mission:
  defaults: {{goal_timeout: 240}}
  waypoints:
{waypoints}
robots:
  - {{name: robot1, start: {{x: {robot1[0]}, y: 1.2, yaw: 0}}}}
  - {{name: robot2, start: {{x: {robot2[0]}, y: 1.2, yaw: 180}}}}
waypoints:
{rules}
"""

# name: robot1's start x, robot2's start x, waypoints (name, x, yaw in degrees, robot)
SCENARIOS = {
    "swap": (2.6, 4.8, [("east", 4.8, 0, "robot1"), ("west", 2.6, 180, "robot2")]),
    # robot2 has no share: it is parked on robot1's first waypoint
    "parked": (1.2, 3.7, [("middle", 3.7, 0, "robot1"), ("far", 6.2, 0, "robot1")]),
}


@pytest.mark.flaky(reruns=1)  # two robots on real ROS 1 in real time: a loaded machine
@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_the_robots_give_way_and_every_waypoint_is_reached(
    ros_master: RosMaster, tmp_path: Path, scenario: str
) -> None:
    robot1_x, robot2_x, waypoints = SCENARIOS[scenario]
    corridor = save_map(corridor_between_rooms(), tmp_path / "corridor.yaml")
    fleet = tmp_path / "fleet.yaml"
    fleet.write_text(
        FLEET.format(
            robot1=(robot1_x,),
            robot2=(robot2_x,),
            waypoints="\n".join(
                f"    - {{name: {n}, x: {x}, y: 1.2, yaw: {yaw}}}" for n, x, yaw, _ in waypoints
            ),
            rules="\n".join(f"  {n}: {{robots: [{robot}]}}" for n, _, _, robot in waypoints),
        )
    )
    ros_master.start(
        [
            "roslaunch",
            "navseq",
            "multi_robot.launch",
            f"map:={corridor}",
            "speed:=2",
            f"robot1_x:={robot1_x}",
            "robot1_y:=1.2",
            "robot1_yaw:=0",
            f"robot2_x:={robot2_x}",
            "robot2_y:=1.2",
            "robot2_yaw:=3.14159",
        ],
        label="roslaunch",
    )
    for robot in ("robot1", "robot2"):
        ros_master.wait_for_action_server(f"/{robot}/move_base", timeout=60)
    out = tmp_path / "run"
    navseq = ros_master.start(
        [
            *(NAVSEQ, "run", "--fleet", fleet, "--navigator", "ros1", "--out", out),
            # Recorded as ROS 1 tools read it, with each robot's stack's footprint.
            *("--record", "--record-format", "ros1", "--record-topics", "/footprint"),
        ],
        cwd=tmp_path,
        label="navseq",
    )
    assert navseq.wait(timeout=300) == 0, navseq.output()
    report = json.loads((out / "fleet-report.json").read_text())
    assert (report["reached"], report["failed"], report["skipped"]) == (2, 0, 0), report
    assert report["robot_overlaps"] == 0, report
    assert report["coordinator"]["sent_aside"] >= 1, report
    for row in report["robots"]:
        if row["waypoints"]:
            assert "blocked" not in (out / row["name"] / "journal.jsonl").read_text()
    assert "Traceback" not in navseq.output()
    with (out / "fleet.mcap").open("rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert reader.get_header().profile == "ros1"
    assert summary is not None and summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    channels = {c.topic: c for c in summary.channels.values()}
    schemas = {c.topic: summary.schemas[c.schema_id].name for c in channels.values() if c.schema_id}
    assert counts[channels["/robot1/navseq/pose"].id] > 10
    assert schemas["/robot1/footprint"] == "geometry_msgs/PolygonStamped"
    assert counts[channels["/robot1/footprint"].id] > 0
    assert {"/map", "/tf", "/robot1/odom", "/robot1/plan"} <= set(channels)
