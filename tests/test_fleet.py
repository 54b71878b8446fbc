"""Robots that see each other: exact robot-robot overlap, bodies that refuse to bump into
another robot, and navigation servers that plan around robots and wait for one that
blocks the only way."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.geometry import Pose2D
from navseq.sim.base import SimulatedBase
from navseq.sim.costmap import LETHAL, Costmap
from navseq.sim.footprint import TURTLEBOT3_BURGER, Footprint, footprint_cells, footprints_overlap
from navseq.sim.navserver import NavParams, NavState
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.world import SimWorld

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
BURGER = TURTLEBOT3_BURGER
HALF_WIDTH = 0.105  # the burger spans y in [-0.105, 0.105], x in [-0.105, 0.041]
PATIENCE = NavParams().blocked_patience


# -- maps and helpers ---------------------------------------------------------------------------


def open_room(size_m: float = 4.0) -> OccupancyGrid:
    """A free square room centred on the origin with one-cell walls all round."""
    cells = round(size_m / 0.05)
    data = np.zeros((cells, cells), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    return OccupancyGrid(data, 0.05, Pose2D(-size_m / 2, -size_m / 2))


def two_rooms(door_m: float = 0.4) -> OccupancyGrid:
    """Two 3 m x 3 m rooms side by side (x < 0 and x > 0), joined by one door at y = 0 in
    the wall x = 0: wide enough for one robot, not for one robot to pass another."""
    data = np.zeros((60, 120), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    data[:, 60] = 100  # the wall between the rooms, x in [0, 0.05)
    half = round(door_m / 0.05 / 2)
    data[30 - half : 30 + half, 60] = 0
    return OccupancyGrid(data, 0.05, Pose2D(-3.0, -1.5))


OtherAt = Callable[[float], Pose2D]  # sim time -> where the other robot is


def drive_among(world: SimWorld, other_at: OtherAt, seconds: float = 120.0) -> list[Pose2D]:
    """Step ``world`` with one other robot where ``other_at`` says, until the goal ends.

    Asserts at every step that the two footprints never overlap; returns the poses.
    """
    poses = [world.robot.pose]
    while world.server.state is NavState.ACTIVE:
        assert world.time < seconds, f"goal still active after {seconds} s"
        other = other_at(world.time)
        world.set_other_robots([(other, BURGER)])
        world.step()
        pose = world.robot.pose
        assert not footprints_overlap(BURGER, pose, BURGER, other), (world.time, pose, other)
        poses.append(pose)
    return poses


def parked(pose: Pose2D) -> OtherAt:
    return lambda _time: pose


def leaves_at(departure: float, before: Pose2D, after: Pose2D) -> OtherAt:
    return lambda time: before if time < departure else after


# -- reference geometry for the overlap test ---------------------------------------------------


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * ab)))


def _inside(p: np.ndarray, polygon: np.ndarray) -> bool:
    """Strictly inside a counter-clockwise or clockwise convex polygon."""
    signs = [_cross(a, b, p) for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True)]
    return all(s > 0 for s in signs) or all(s < 0 for s in signs)


def _segments_cross(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    return (_cross(a, b, c) * _cross(a, b, d) < 0) and (_cross(c, d, a) * _cross(c, d, b) < 0)


def polygon_gap(p: np.ndarray, q: np.ndarray) -> float:
    """0 if two convex polygons overlap, else the least distance between them (brute force)."""
    p_edges = list(zip(p, np.roll(p, -1, axis=0), strict=True))
    q_edges = list(zip(q, np.roll(q, -1, axis=0), strict=True))
    if any(_inside(v, q) for v in p) or any(_inside(v, p) for v in q):
        return 0.0
    if any(_segments_cross(a, b, c, d) for (a, b), (c, d) in itertools.product(p_edges, q_edges)):
        return 0.0
    return min(
        min(_point_segment_distance(v, a, b) for v in p for a, b in q_edges),
        min(_point_segment_distance(v, a, b) for v in q for a, b in p_edges),
    )


# -- two footprints -----------------------------------------------------------------------------


def test_footprints_overlap_side_by_side_touching_and_apart() -> None:
    here = Pose2D(0.0, 0.0, 0.0)
    assert footprints_overlap(BURGER, here, BURGER, Pose2D(0.0, 0.2, 0.0))
    # Side by side with their long edges exactly touching: no overlap, as with cells.
    assert not footprints_overlap(BURGER, here, BURGER, Pose2D(0.0, 2 * HALF_WIDTH, 0.0))
    assert footprints_overlap(BURGER, here, BURGER, Pose2D(0.0, 2 * HALF_WIDTH - 1e-6, 0.0))
    # Nose to nose: the front edges are 0.041 m ahead of the centres.
    assert not footprints_overlap(BURGER, here, BURGER, Pose2D(0.082, 0.0, math.pi))
    assert footprints_overlap(BURGER, here, BURGER, Pose2D(0.08, 0.0, math.pi))
    assert not footprints_overlap(BURGER, here, BURGER, Pose2D(1.0, 1.0, 0.3))


def test_footprints_overlap_is_exact_for_rotated_robots_where_circles_would_not_be() -> None:
    here = Pose2D(0.0, 0.0, 0.0)
    # Both circumscribed circles overlap by far, yet the robots do not touch: the other
    # one, turned -45 degrees, points a rear corner at this one's front edge, 1 cm short.
    corner = BURGER.circumscribed_radius  # the rear corners are the farthest
    clear = Pose2D(0.041 + 0.01 + corner, 0.0, -math.pi / 4)
    dent = Pose2D(0.041 - 0.01 + corner, 0.0, -math.pi / 4)
    assert math.dist((0, 0), (clear.x, clear.y)) < 2 * corner
    assert not footprints_overlap(BURGER, here, BURGER, clear)
    assert footprints_overlap(BURGER, here, BURGER, dent)
    # Symmetric in its two arguments.
    assert footprints_overlap(BURGER, dent, BURGER, here)
    assert not footprints_overlap(BURGER, clear, BURGER, here)


@settings(max_examples=300, deadline=None)
@given(
    x=st.floats(-0.4, 0.4),
    y=st.floats(-0.4, 0.4),
    yaw_a=st.floats(-math.pi, math.pi),
    yaw_b=st.floats(-math.pi, math.pi),
)
def test_footprints_overlap_agrees_with_brute_force_geometry(
    x: float, y: float, yaw_a: float, yaw_b: float
) -> None:
    square = Footprint(np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]))
    for a, b in ((BURGER, BURGER), (BURGER, square), (Footprint.circle(0.12, 7), BURGER)):
        pose_a, pose_b = Pose2D(0.0, 0.0, yaw_a), Pose2D(x, y, yaw_b)
        gap = polygon_gap(a.at(pose_a), b.at(pose_b))
        # Touching, up to rounding: a gap under 1e-7, or none where a tenth of a micrometre
        # either way decides (the brute force counts touching edges as overlapping).
        touching = footprints_overlap(a, pose_a, b, pose_b, 1e-7) and not footprints_overlap(
            a, pose_a, b, pose_b, -1e-7
        )
        if 0.0 < gap < 1e-7 or (gap == 0.0 and touching):
            continue
        assert footprints_overlap(a, pose_a, b, pose_b) == (gap == 0.0), gap
        # A margin m counts robots closer than m, and never robots much farther
        # (the grown outline has sharp corners: at most sqrt(2) m at right angles).
        margin = 0.05
        if gap < margin - 1e-7:
            assert footprints_overlap(a, pose_a, b, pose_b, margin), gap
        elif gap > math.sqrt(2) * margin + 1e-7:
            assert not footprints_overlap(a, pose_a, b, pose_b, margin), gap


# -- the body -----------------------------------------------------------------------------------


def test_the_body_refuses_to_drive_into_a_parked_robot() -> None:
    base = SimulatedBase(Pose2D(-1.0, 0.0, 0.0), open_room())
    other = Pose2D(0.0, 0.0, math.pi / 2)  # across the way, 1 m ahead
    base.set_other_robots([(other, BURGER)])
    for _ in range(200):  # 10 s at full speed: far enough to pass through it
        base.command(0.22, 0.0)
        base.step(0.05)
        assert not footprints_overlap(BURGER, base.pose, BURGER, other)
    assert base.refused_steps > 0
    assert base.robot.v == 0.0
    # It got close: the other robot's side is at x = -0.105, this one's nose 0.041 ahead.
    assert -0.105 - 0.041 - 0.02 < base.pose.x < -0.105 - 0.041


def test_teleport_onto_another_robot_is_refused() -> None:
    base = SimulatedBase(Pose2D(-1.0, 0.0, 0.0), open_room())
    base.set_other_robots([(Pose2D(0.5, 0.5, 0.0), BURGER)])
    assert not base.teleport(Pose2D(0.55, 0.45, 1.0))
    assert base.pose == Pose2D(-1.0, 0.0, 0.0)
    assert base.collides(Pose2D(0.55, 0.45, 1.0))
    assert base.teleport(Pose2D(0.5, -0.5, 0.0))


def test_robots_that_already_overlap_may_only_move_apart() -> None:
    base = SimulatedBase(Pose2D(0.0, 0.0, 0.0), open_room())
    other = Pose2D(0.1, 0.0, 0.0)  # put there from a stale pose, say
    base.set_other_robots([(other, BURGER)])
    base.command(0.2, 0.0)
    assert not base.step(0.05)  # deeper in: refused
    base.command(-0.2, 0.0)
    for _ in range(20):
        assert base.step(0.05)  # backing away is allowed
    assert not footprints_overlap(BURGER, base.pose, BURGER, other)


def test_a_map_set_after_start_is_collided_with() -> None:
    base = SimulatedBase(Pose2D(1.0, 0.0, 0.0), None)  # the ROS node's map comes later
    grid = open_room()
    base.grid = grid
    assert base.collides(Pose2D(1.98, 0.0, 0.0))


# -- the costmap with other robots -----------------------------------------------------------


def test_costmap_with_obstacles_equals_inflating_them_with_the_map() -> None:
    grid = load_map(MAP)
    costmap = Costmap.from_grid(grid)
    robots = [Pose2D(-1.5, -0.5, 0.3), Pose2D(0.55, -1.7, 2.0)]
    cells = [footprint_cells(grid, BURGER, pose) for pose in robots]
    rows = np.concatenate([c[0] for c in cells if c is not None])
    cols = np.concatenate([c[1] for c in cells if c is not None])
    data = grid.data.copy()
    data[rows, cols] = 100
    reference = Costmap.from_grid(OccupancyGrid(data, grid.resolution, grid.origin))
    with_robots = costmap.with_obstacles(rows, cols)
    assert np.array_equal(with_robots.cost, reference.cost)
    # Where the planner may put the robot, recomputed near the robots only, is as if
    # the whole costmap had been made with them.
    rebuilt = Costmap(grid, costmap.params, with_robots.cost.copy(), with_robots.clearance.copy())
    assert np.array_equal(with_robots.free_mask(), rebuilt.free_mask())
    assert np.array_equal(with_robots.planning_cost, rebuilt.planning_cost)
    assert not with_robots.free_mask()[rows, cols].any()
    assert with_robots.grid is grid  # the map itself is untouched
    assert costmap.with_obstacles(np.array([], int), np.array([], int)) is costmap
    # Padding grows them: cells within it are lethal too, and the inflation starts there.
    padded = costmap.with_obstacles(rows, cols, padding=0.1)
    near = np.zeros(grid.data.shape, bool)
    near[rows, cols] = True
    assert (padded.cost[near] == LETHAL).all()
    row, col = rows[0], cols[0]
    assert (padded.cost >= with_robots.cost).all()
    assert padded.cost[row, col - 2] == LETHAL or padded.cost[row, col + 2] == LETHAL


# -- the navigation server --------------------------------------------------------------------


def test_plans_around_a_robot_parked_on_the_straight_way_and_never_touches_it() -> None:
    world = SimWorld(open_room(), Pose2D(-1.5, 0.0, 0.0))
    other = Pose2D(0.0, 0.0, math.pi / 2)
    world.set_other_robots([(other, BURGER)])
    goal = Pose2D(1.5, 0.0, 0.0)
    world.server.set_goal(goal)
    poses = drive_among(world, parked(other))
    assert world.server.state is NavState.SUCCEEDED
    assert world.robot.pose.distance_to(goal) <= 0.05
    assert world.collisions == 0
    plan = world.server.plan
    assert plan is not None
    # The plan goes round: no plan point within the other robot plus this one's width.
    assert np.hypot(plan.points[:, 0] - other.x, plan.points[:, 1] - other.y).min() > 0.25
    assert min(p.distance_to(other) for p in poses) > 0.25
    # The map's own costmap is untouched; the planning one has the robot in it.
    assert world.server.costmap.cost_at(other.x, other.y) == 0
    assert world.server.planning_costmap.cost_at(other.x, other.y) == LETHAL


def test_gets_past_a_robot_parked_between_two_pillars_of_the_arena() -> None:
    """The plan keeps the margin the safety test wants, so the robot can drive it."""
    world = SimWorld(load_map(MAP), Pose2D(-2.0, -0.5, 0.0))
    goal = Pose2D(0.5, -0.5, 0.0)
    world.server.set_goal(goal)
    drive_among(world, parked(Pose2D(-1.0, -0.5, math.pi / 2)))
    assert world.server.state is NavState.SUCCEEDED, world.server.status_text
    assert world.collisions == 0


def test_replans_around_a_robot_that_stops_on_the_plan_ahead() -> None:
    world = SimWorld(open_room(), Pose2D(-1.5, 0.0, 0.0))
    goal = Pose2D(1.5, 0.0, 0.0)
    world.server.set_goal(goal)
    away, on_the_way = Pose2D(1.5, -1.5, 0.0), Pose2D(0.3, 0.0, math.pi / 2)
    drive_among(world, leaves_at(3.0, away, on_the_way))
    assert world.server.state is NavState.SUCCEEDED
    assert world.server.plan_version >= 2
    assert world.collisions == 0


def test_make_plan_and_clear_costmaps_keep_the_other_robots() -> None:
    server = SimWorld(open_room(), Pose2D(-1.5, 0.0, 0.0)).server
    other = Pose2D(0.0, 0.0, 0.0)
    server.set_other_robots([(other, BURGER)])
    plan = server.make_plan(Pose2D(-1.5, 0.0, 0.0), Pose2D(1.5, 0.0, 0.0))
    assert plan is not None
    assert np.hypot(plan.points[:, 0], plan.points[:, 1]).min() > 0.25
    server.clear_costmaps()
    assert server.planning_costmap.cost_at(other.x, other.y) == LETHAL
    assert server.costmap.cost_at(other.x, other.y) == 0
    server.set_other_robots([])  # it left: the next plan is straight again
    plan = server.make_plan(Pose2D(-1.5, 0.0, 0.0), Pose2D(1.5, 0.0, 0.0))
    assert plan is not None and np.abs(plan.points[:, 1]).max() < 0.05


IN_THE_DOOR = Pose2D(0.0, 0.0, 0.0)
ELSEWHERE = Pose2D(1.5, -1.0, 0.0)  # in the far room, off the way to the goal


def test_a_robot_in_the_only_door_makes_the_goal_wait_not_abort() -> None:
    world = SimWorld(two_rooms(), Pose2D(-2.0, 0.0, 0.0))
    world.server.set_goal(Pose2D(2.0, 0.0, 0.0))
    for _ in range(round(5.0 / world.dt)):
        world.set_other_robots([(IN_THE_DOOR, BURGER)])
        world.step()
        assert world.server.state is NavState.ACTIVE
    assert world.robot.pose == Pose2D(-2.0, 0.0, 0.0)  # waiting at rest
    assert world.server.plan is None


def test_a_robot_that_leaves_the_door_within_the_patience_lets_the_goal_succeed() -> None:
    world = SimWorld(two_rooms(), Pose2D(-2.0, 0.0, 0.0))
    goal = Pose2D(2.0, 0.0, 0.0)
    world.server.set_goal(goal)
    drive_among(world, leaves_at(0.8 * PATIENCE, IN_THE_DOOR, ELSEWHERE))
    assert world.server.state is NavState.SUCCEEDED
    assert world.robot.pose.distance_to(goal) <= 0.05


def test_a_robot_that_stays_in_the_door_aborts_the_goal_after_the_patience() -> None:
    world = SimWorld(two_rooms(), Pose2D(-2.0, 0.0, 0.0))
    world.server.set_goal(Pose2D(2.0, 0.0, 0.0))
    drive_among(world, parked(IN_THE_DOOR))
    assert world.server.state is NavState.ABORTED
    assert "blocked by another robot" in world.server.status_text
    # Not at once: after the patience, within one replanning period.
    assert PATIENCE < world.time <= PATIENCE + NavParams().robot_replan_period + world.dt


def test_a_robot_that_stops_in_the_door_ahead_aborts_after_the_patience() -> None:
    world = SimWorld(two_rooms(), Pose2D(-2.0, 0.0, 0.0))
    world.server.set_goal(Pose2D(2.0, 0.0, 0.0))
    arrival = 3.0
    drive_among(world, leaves_at(arrival, ELSEWHERE, IN_THE_DOOR))
    assert world.server.state is NavState.ABORTED
    assert "blocked by another robot" in world.server.status_text
    assert world.time > arrival + PATIENCE
    assert world.collisions == 0


def test_a_goal_inside_another_robot_waits_for_it_to_move_away() -> None:
    world = SimWorld(two_rooms(), Pose2D(-2.0, 0.0, 0.0))
    goal = Pose2D(2.0, 0.0, 0.0)
    world.server.set_goal(goal)
    drive_among(world, leaves_at(0.5 * PATIENCE, Pose2D(2.0, 0.05, 1.0), ELSEWHERE))
    assert world.server.state is NavState.SUCCEEDED
    assert world.robot.pose.distance_to(goal) <= 0.05


def test_a_goal_the_map_itself_rules_out_still_aborts_at_once() -> None:
    grid = two_rooms()
    grid.data[:, 60] = 100  # the door walled up
    world = SimWorld(grid, Pose2D(-2.0, 0.0, 0.0))
    world.set_other_robots([(ELSEWHERE, BURGER)])
    world.server.set_goal(Pose2D(2.0, 0.0, 0.0))
    world.step()
    assert world.server.state is NavState.ABORTED
    assert "unreachable" in world.server.status_text


def test_two_robots_crossing_each_with_the_others_pose_one_step_old_never_overlap() -> None:
    """As with ROS nodes, each robot sees where the other was, not where it is."""
    grid = open_room()
    costmap = Costmap.from_grid(grid)
    first = SimWorld(grid, Pose2D(-1.5, 0.0, 0.0), costmap=costmap)
    second = SimWorld(grid, Pose2D(-0.3, -1.5, math.pi / 2), costmap=costmap)
    first.server.set_goal(Pose2D(1.5, 0.0, 0.0))
    second.server.set_goal(Pose2D(-0.3, 1.5, math.pi / 2))
    while NavState.ACTIVE in (first.server.state, second.server.state):
        assert first.time < 120.0
        first_was, second_was = first.robot.pose, second.robot.pose
        first.set_other_robots([(second_was, BURGER)])
        second.set_other_robots([(first_was, BURGER)])
        first.step()
        second.step()
        assert not footprints_overlap(BURGER, first.robot.pose, BURGER, second.robot.pose)
    assert first.server.state is NavState.SUCCEEDED
    assert second.server.state is NavState.SUCCEEDED
    assert first.collisions == second.collisions == 0


def test_without_other_robots_the_run_is_the_same_pose_by_pose() -> None:
    grid = load_map(MAP)
    costmap = Costmap.from_grid(grid)
    goals = [Pose2D(1.6, 0.5, math.pi / 2), Pose2D(-0.5, -1.8, 0.0)]

    def run(set_no_others: bool) -> list[tuple[float, float, float, float, float]]:
        world = SimWorld(grid, Pose2D(-2.0, -0.5, 0.0), costmap=costmap)
        trajectory = []
        for goal in goals:
            world.server.set_goal(goal)
            while world.server.state is NavState.ACTIVE:
                if set_no_others:
                    world.set_other_robots([])
                world.step()
                robot = world.robot
                trajectory.append((robot.pose.x, robot.pose.y, robot.pose.yaw, robot.v, robot.w))
            assert world.server.state is NavState.SUCCEEDED
        return trajectory

    assert run(set_no_others=True) == run(set_no_others=False)
