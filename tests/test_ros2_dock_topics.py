"""The docking topics of the ROS 2 simulator node while ``dock_robot`` runs
(``tests/ros2_route_clients.py dockposes``): the simulated detector's
``detected_dock_pose`` (the dock seen from the robot, ``base_link``), the docking
server's ``filtered_dock_pose`` (``odom``) and the controller's ``docking_trajectory``.
Robot at (-2, -0.5) facing +x, where odometry starts: the odom frame's origin; the
``home_dock`` of ``examples/turtlebot3_docks.yaml`` at (-0.5, -0.5) facing +x."""

from __future__ import annotations

import math

import pytest

from test_ros2_route_server import run_client, start_sim
from test_ros2_sim import REPO

pytestmark = pytest.mark.ros2

DOCKS = REPO / "examples" / "turtlebot3_docks.yaml"


def test_dock_poses_and_the_approach_are_published_while_docking() -> None:
    sim = start_sim("--docks", str(DOCKS))
    try:
        seen = run_client(sim, "dockposes", "home_dock")
    finally:
        err = sim.stop()
    assert "Traceback" not in err
    assert seen["status"] == "SUCCEEDED"
    detected, filtered, trajectory = seen["detected"], seen["filtered"], seen["trajectory"]
    assert len(detected) >= 3 and len(filtered) >= 3 and len(trajectory) >= 3
    # Seen from the robot: straight ahead, 0.7 m away at the staging pose, closing in.
    assert {frame for frame, *_ in detected} == {"base_link"}
    first, last = detected[0], detected[-1]
    assert first[1] == pytest.approx(0.7, abs=0.15) and abs(first[2]) < 0.2
    assert last[1] < first[1]
    # The estimate stays on the dock: (1.5, 0) from where odometry started.
    assert {frame for frame, *_ in filtered} == {"odom"}
    assert all(math.dist(f[1:], [1.5, 0.0]) < 0.05 for f in filtered)
    # The controller's projection leads from the robot to the dock.
    frame, points = trajectory[0]
    assert frame == "base_link" and points[0] == pytest.approx([0.0, 0.0])
    assert math.dist(points[-1], first[1:]) < 0.15 or len(points) == 51
