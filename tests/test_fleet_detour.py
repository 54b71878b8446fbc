"""How a fleet's robot deals with robots near its plan without searching the whole map
each time (:mod:`navseq.sim.detour`), and who a blocked robot sends aside: the plan is
kept while it is clear, a detour goes round a robot and rejoins the plan, and a robot
far along a blocked robot's route is left where it is."""

from __future__ import annotations

import itertools
import math

import numpy as np

from navseq.geometry import Pose2D
from navseq.sim.costmap import INSCRIBED, Costmap
from navseq.sim.detour import blocked_stretch, local_detour
from navseq.sim.fleet_world import FleetRobot, FleetWorld
from navseq.sim.footprint import TURTLEBOT3_BURGER, footprint_cells, footprints_overlap
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.planner import plan_path
from navseq.sim.right_of_way import FleetNavigationServer

RESOLUTION = 0.05


def open_room(width: float = 8.0, height: float = 4.0) -> OccupancyGrid:
    """A free room with its corner at the origin and one-cell walls all round."""
    data = np.zeros((round(height / RESOLUTION), round(width / RESOLUTION)), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    return OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0), "room")


def with_robot_at(costmap: Costmap, pose: Pose2D) -> Costmap:
    cells = footprint_cells(costmap.grid, TURTLEBOT3_BURGER, pose)
    assert cells is not None
    return costmap.with_obstacles(*cells, padding=0.05)


def test_a_detour_goes_round_a_robot_on_the_plan_and_rejoins_it() -> None:
    costmap = Costmap.from_grid(open_room(24.0, 8.0))
    plan = plan_path(costmap, (1.0, 4.0), (7.0, 4.0))
    assert plan is not None
    crowded = with_robot_at(costmap, Pose2D(3.0, 4.0, math.pi / 2))
    blocked = blocked_stretch(crowded, plan.points)
    assert blocked.any() and not blocked[0] and not blocked[-1]
    assert not blocked_stretch(costmap, plan.points).any()

    detour = local_detour(crowded, (1.0, 4.0), plan.points, blocked)

    assert detour is not None  # found in a window of the (large) room, not the whole of it
    assert tuple(detour.points[0]) == (1.0, 4.0)
    assert not blocked_stretch(crowded, detour.points).any()  # round the robot
    # It rejoins the plan a metre or so past the robot and follows it from there on.
    tail = plan.points[plan.points[:, 0] > 4.6]
    assert np.array_equal(detour.points[-len(tail) :], tail)
    steps = np.hypot(*np.diff(detour.points, axis=0).T)
    assert detour.length == float(steps.sum())
    whole_map = plan_path(crowded, (1.0, 4.0), (7.0, 4.0))  # what it saves searching for
    assert whole_map is not None and detour.length < 1.05 * whole_map.length


def test_no_detour_reaches_a_goal_another_robot_stands_on() -> None:
    costmap = Costmap.from_grid(open_room(24.0, 8.0))
    plan = plan_path(costmap, (1.0, 4.0), (7.0, 4.0))
    assert plan is not None
    crowded = with_robot_at(costmap, Pose2D(7.0, 4.0, 0.0))
    blocked = blocked_stretch(crowded, plan.points)
    assert blocked[-1]
    assert local_detour(crowded, (1.0, 4.0), plan.points, blocked) is None


def server_following_a_plan(others: list[Pose2D]) -> tuple[FleetNavigationServer, Pose2D]:
    costmap = Costmap.from_grid(open_room())
    server = FleetNavigationServer(costmap)
    start = Pose2D(1.0, 2.0, 0.0)
    server.set_other_robots([(pose, TURTLEBOT3_BURGER) for pose in others])
    server.set_goal(Pose2D(7.0, 2.0, 0.0))
    server.compute_velocity(start, 0.0, 0.0, 0.05)
    assert server.plan is not None and server.state is NavState.ACTIVE
    return server, start


def step_for(server: FleetNavigationServer, pose: Pose2D, seconds: float) -> None:
    for _ in range(round(seconds / 0.05)):
        server.compute_velocity(pose, 0.0, 0.0, 0.05)


def test_a_robot_passing_near_the_plan_leaves_it_as_it_is_while_it_is_clear() -> None:
    server, start = server_following_a_plan([Pose2D(3.0, 3.6, 0.0)])
    plan, version = server.plan, server.plan_version
    # The other robot comes within robot_near_plan of the plan, but leaves it clear.
    beside = Pose2D(3.0, 2.45, 0.0)
    assert plan is not None
    assert float(np.hypot(*(plan.points - (beside.x, beside.y)).T).min()) < 0.5
    server.set_other_robots([(beside, TURTLEBOT3_BURGER)])
    step_for(server, start, 1.5)
    assert server.plan is plan and server.plan_version == version

    # On the plan, it makes the server go round it.
    on_it = Pose2D(3.0, 2.0, math.pi / 2)
    server.set_other_robots([(on_it, TURTLEBOT3_BURGER)])
    step_for(server, start, 1.5)
    assert server.plan is not plan and server.plan is not None
    assert server.plan_version > version
    assert not blocked_stretch(server.planning_costmap, server.plan.points).any()
    assert (
        server.planning_costmap.planning_cost[
            server.planning_costmap.grid.world_to_cell(on_it.x, on_it.y)
        ]
        >= INSCRIBED
    )


def corridor_into_a_hall() -> OccupancyGrid:
    """A 2 m room, a corridor one robot wide and 3 m long, then a hall 6 m x 2 m."""
    data = np.full((round(2.4 / RESOLUTION), round(11.4 / RESOLUTION)), 100, np.int8)

    def carve(x0: float, y0: float, x1: float, y1: float) -> None:
        data[
            round(y0 / RESOLUTION) : round(y1 / RESOLUTION),
            round(x0 / RESOLUTION) : round(x1 / RESOLUTION),
        ] = 0

    carve(0.2, 0.2, 2.2, 2.2)
    carve(2.2, 1.0, 5.2, 1.4)
    carve(5.2, 0.2, 11.2, 2.2)
    return OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0), "corridor and hall")


def test_a_robot_far_along_a_blocked_robots_route_is_not_sent_aside() -> None:
    """``a`` and ``b`` meet in the corridor; ``c`` stands idle in the hall, on ``a``'s way
    but metres beyond what ``a`` sees: ``b`` makes way, ``c`` is left alone (``a`` goes
    round it when it gets there), and nothing ever overlaps."""
    idle_at = Pose2D(9.4, 1.2, 0.0)
    fleet = FleetWorld(
        corridor_into_a_hall(),
        [
            FleetRobot("a", Pose2D(1.2, 1.2, 0.0)),
            FleetRobot("b", Pose2D(6.0, 1.2, math.pi)),
            FleetRobot("c", idle_at),
        ],
    )
    fleet.set_goal("a", Pose2D(10.6, 1.2, 0.0))
    fleet.set_goal("b", Pose2D(1.0, 1.2, math.pi))
    c = fleet.servers[2]
    footprints = fleet.footprints
    end = round(400.0 / fleet.dt)
    while fleet.busy() and fleet.steps < end:
        fleet.step()
        assert not c.giving_way, f"c sent aside at {fleet.now:.1f} s"
        poses = [world.robot.pose for world in fleet.worlds]
        for i, j in itertools.combinations(range(3), 2):
            assert not footprints_overlap(footprints[i], poses[i], footprints[j], poses[j])
    assert [server.state for server in fleet.servers[:2]] == [NavState.SUCCEEDED] * 2
    assert fleet.right_of_way is not None and fleet.right_of_way.yields_started >= 1
    assert fleet.world("c").robot.pose == idle_at
