"""Right of way in a simulated fleet: conflicts that leave two servers waiting for each
other (a swap in a corridor, a doorway, a junction, a robot parked on a goal) all
complete, and no two footprints ever overlap (checked after every step)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.sim.fleet_world import FleetRobot, FleetWorld
from navseq.sim.footprint import footprints_overlap
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import OccupancyGrid

RESOLUTION = 0.05


def canvas(width: float, height: float) -> np.ndarray:
    """All occupied: scenarios carve free space out of it."""
    return np.full((round(height / RESOLUTION), round(width / RESOLUTION)), 100, np.int8)


def carve(data: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> None:
    data[
        round(y0 / RESOLUTION) : round(y1 / RESOLUTION),
        round(x0 / RESOLUTION) : round(x1 / RESOLUTION),
    ] = 0


def grid_of(data: np.ndarray, name: str) -> OccupancyGrid:
    return OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0), name)


def corridor_between_rooms(corridor_width: float = 0.4) -> OccupancyGrid:
    """Two 2 m x 2 m rooms joined by a corridor 3 m long, one robot wide."""
    data = canvas(7.4, 2.4)
    carve(data, 0.2, 0.2, 2.2, 2.2)
    carve(data, 5.2, 0.2, 7.2, 2.2)
    carve(data, 2.2, 1.2 - corridor_width / 2, 5.2, 1.2 + corridor_width / 2)
    return grid_of(data, "corridor")


def rooms_with_one_door() -> OccupancyGrid:
    """Two 3 m x 3 m rooms side by side joined by a 0.4 m door in the wall between."""
    data = canvas(6.4, 3.4)
    carve(data, 0.2, 0.2, 3.1, 3.2)
    carve(data, 3.3, 0.2, 6.2, 3.2)
    carve(data, 3.1, 1.5, 3.3, 1.9)
    return grid_of(data, "doorway")


def junction() -> OccupancyGrid:
    """A plus of 0.5 m wide corridors, 6 m across, with a 1.2 m square bay at each end."""
    data = canvas(7.0, 7.0)
    carve(data, 0.2, 3.25, 6.8, 3.75)
    carve(data, 3.25, 0.2, 3.75, 6.8)
    for x, y in ((0.2, 2.9), (5.6, 2.9), (2.9, 0.2), (2.9, 5.6)):
        carve(data, x, y, x + 1.2, y + 1.2)
    return grid_of(data, "junction")


def drive(fleet: FleetWorld, limit: float = 400.0) -> dict[str, Pose2D]:
    """Step until no robot is busy, checking after every step that no footprints overlap;
    where each robot was when its goal SUCCEEDED (an idle robot may be sent aside later)."""
    footprints = fleet.footprints
    end = fleet.steps + round(limit / fleet.dt)
    arrived: dict[str, Pose2D] = {}
    while fleet.busy():
        assert fleet.steps < end, f"still busy after {limit} s: {states(fleet)}"
        fleet.step()
        poses = [world.robot.pose for world in fleet.worlds]
        for i, j in itertools.combinations(range(len(poses)), 2):
            assert not footprints_overlap(footprints[i], poses[i], footprints[j], poses[j]), (
                fleet.now,
                fleet.names[i],
                fleet.names[j],
            )
        for name, world, pose in zip(fleet.names, fleet.worlds, poses, strict=True):
            if world.server.state is NavState.SUCCEEDED and name not in arrived:
                arrived[name] = pose
    assert fleet.collisions == 0
    return arrived


def states(fleet: FleetWorld) -> dict[str, str]:
    return {
        name: f"{world.server.state.value} {world.server.status_text}"
        for name, world in zip(fleet.names, fleet.worlds, strict=True)
    }


def near(pose: Pose2D | None, goal: Pose2D) -> bool:
    return pose is not None and math.hypot(pose.x - goal.x, pose.y - goal.y) < 0.1


def test_two_robots_swap_the_ends_of_a_one_robot_corridor() -> None:
    west, east = Pose2D(2.6, 1.2, 0.0), Pose2D(4.8, 1.2, math.pi)
    fleet = FleetWorld(corridor_between_rooms(), [FleetRobot("a", west), FleetRobot("b", east)])
    fleet.set_goal("a", Pose2D(4.8, 1.2, 0.0))
    fleet.set_goal("b", Pose2D(2.6, 1.2, math.pi))
    arrived = drive(fleet)
    assert near(arrived.get("a"), east) and near(arrived.get("b"), west), states(fleet)
    assert fleet.right_of_way is not None and fleet.right_of_way.yields_started >= 1


def test_without_right_of_way_the_same_swap_ends_aborted() -> None:
    west, east = Pose2D(2.6, 1.2, 0.0), Pose2D(4.8, 1.2, math.pi)
    fleet = FleetWorld(
        corridor_between_rooms(),
        [FleetRobot("a", west), FleetRobot("b", east)],
        right_of_way=False,
    )
    fleet.set_goal("a", Pose2D(4.8, 1.2, 0.0))
    fleet.set_goal("b", Pose2D(2.6, 1.2, math.pi))
    drive(fleet)
    assert {world.server.state for world in fleet.worlds} == {NavState.ABORTED}


def test_two_robots_through_one_doorway_at_once() -> None:
    left, right = Pose2D(2.2, 1.7, 0.0), Pose2D(4.2, 1.7, math.pi)
    fleet = FleetWorld(rooms_with_one_door(), [FleetRobot("a", left), FleetRobot("b", right)])
    fleet.set_goal("a", Pose2D(5.5, 1.7, 0.0))
    fleet.set_goal("b", Pose2D(0.9, 1.7, math.pi))
    arrived = drive(fleet)
    assert near(arrived.get("a"), Pose2D(5.5, 1.7, 0.0)), states(fleet)
    assert near(arrived.get("b"), Pose2D(0.9, 1.7, 0.0)), states(fleet)


def test_four_robots_cross_a_junction_to_the_opposite_ends() -> None:
    ends = {
        "west": Pose2D(0.8, 3.5, 0.0),
        "east": Pose2D(6.2, 3.5, math.pi),
        "south": Pose2D(3.5, 0.8, math.pi / 2),
        "north": Pose2D(3.5, 6.2, -math.pi / 2),
    }
    opposite = {"west": "east", "east": "west", "south": "north", "north": "south"}
    fleet = FleetWorld(junction(), [FleetRobot(name, pose) for name, pose in ends.items()])
    for name, other in opposite.items():
        fleet.set_goal(name, ends[other])
    arrived = drive(fleet)
    for name, other in opposite.items():
        assert near(arrived.get(name), ends[other]), (name, states(fleet))


def dead_end() -> OccupancyGrid:
    """A 2 m x 2 m room with a corridor one robot wide, 3 m long, closed at its end."""
    data = canvas(5.6, 2.4)
    carve(data, 0.2, 0.2, 2.2, 2.2)
    carve(data, 2.2, 1.0, 5.2, 1.4)
    return grid_of(data, "dead end")


def test_a_robot_in_a_dead_end_gets_out_before_the_first_robot_goes_in() -> None:
    deep, room = Pose2D(4.9, 1.2, math.pi), Pose2D(1.0, 1.2, 0.0)
    fleet = FleetWorld(dead_end(), [FleetRobot("first", room), FleetRobot("inside", deep)])
    fleet.set_goal("first", Pose2D(4.9, 1.2, 0.0))  # where "inside" is now
    fleet.set_goal("inside", Pose2D(1.0, 0.6, math.pi))
    arrived = drive(fleet)
    assert near(arrived.get("first"), deep), states(fleet)
    assert near(arrived.get("inside"), Pose2D(1.0, 0.6, 0.0)), states(fleet)


def test_an_idle_robot_parked_on_a_goal_moves_aside() -> None:
    goal = Pose2D(3.7, 1.2, 0.0)  # in the middle of the corridor
    fleet = FleetWorld(
        corridor_between_rooms(),
        [FleetRobot("busy", Pose2D(1.2, 1.2, 0.0)), FleetRobot("parked", goal)],
    )
    fleet.set_goal("busy", goal)
    arrived = drive(fleet)
    assert near(arrived.get("busy"), goal), states(fleet)
    assert fleet.world("parked").server.state is NavState.IDLE  # it kept no goal of its own


def test_a_waffle_and_a_burger_swap_ends_each_with_its_own_footprint() -> None:
    from navseq.mission.robot import BUILTIN_PROFILES

    waffle = BUILTIN_PROFILES["turtlebot3_waffle"]
    west, east = Pose2D(2.7, 1.2, 0.0), Pose2D(4.7, 1.2, math.pi)
    fleet = FleetWorld(
        corridor_between_rooms(corridor_width=0.7),
        [FleetRobot("burger", west), FleetRobot("waffle", east, waffle)],
    )
    assert fleet.world("waffle").footprint.circumscribed_radius > 0.25
    fleet.set_goal("burger", east)
    fleet.set_goal("waffle", west)
    arrived = drive(fleet)
    assert near(arrived.get("burger"), east) and near(arrived.get("waffle"), west), states(fleet)


def test_robots_that_start_overlapping_are_refused() -> None:
    with pytest.raises(NavseqError, match="a and b start overlapping"):
        FleetWorld(
            rooms_with_one_door(),
            [FleetRobot("a", Pose2D(1.0, 1.0, 0.0)), FleetRobot("b", Pose2D(1.1, 1.0, 0.0))],
        )


def test_two_robots_almost_touching_do_not_send_each_other_aside_over_and_over() -> None:
    """The livelock of issue 21 (seed 8 of the fleet benchmark, from where it began): two
    robots 0.28 m apart in an office, the second sent aside for the first, find each
    other in their ways aside. The rule used to send them aside for each other at every
    decision, four times a second, each new way aside replacing the last before either
    could move (64 ways aside in this scenario); a robot sent aside for another now
    waits for it rather than sending it aside in turn."""
    from navseq.sim.mapgen import office_map

    first, second = Pose2D(3.467, 7.105, -1.756), Pose2D(3.661, 6.909, -2.864)
    fleet = FleetWorld(office_map(8), [FleetRobot("a", first), FleetRobot("b", second)])
    goals = {"a": Pose2D(4.875, 6.325, -0.694), "b": Pose2D(15.025, 8.825, 2.559)}
    for name, goal in goals.items():
        fleet.set_goal(name, goal)
    arrived = drive(fleet)
    for name, goal in goals.items():
        assert near(arrived.get(name), goal), states(fleet)
    assert fleet.right_of_way is not None and fleet.right_of_way.yields_started <= 10
