"""Distances for ordering from one search per place (navseq.sim.planner.reach_lengths,
LegPlanner.distances): the same metres as planning every pair, and no path where there
is none."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from cli_support import TURTLEBOT3_MAP
from navseq.route.legs import LegPlanner, StraightLegs
from navseq.route.order import distances_between, straight_line
from navseq.sim.costmap import Costmap
from navseq.sim.occupancy import load_map
from navseq.sim.planner import compiled_search_available, plan_path, reach_lengths

BACKENDS = [False, *([True] if compiled_search_available() else [])]


@pytest.fixture(scope="module")
def costmap() -> Costmap:
    return Costmap.from_grid(load_map(TURTLEBOT3_MAP))


def free_places(costmap: Costmap, count: int, seed: int) -> list[tuple[float, float]]:
    rng = random.Random(seed)
    grid = costmap.grid
    places: list[tuple[float, float]] = []
    while len(places) < count:
        x, y = rng.uniform(-2.2, 2.2), rng.uniform(-2.2, 2.2)
        if costmap.is_free(x, y) and plan_path(costmap, (-2.0, -0.5), (x, y)) is not None:
            places.append((round(x, 2), round(y, 2)))
    assert grid is not None
    return places


@pytest.mark.parametrize("compiled", BACKENDS, ids=lambda c: "compiled" if c else "python")
def test_one_search_gives_the_lengths_of_the_plans_to_every_place(
    costmap: Costmap, compiled: bool
) -> None:
    places = free_places(costmap, 8, seed=3)
    start, goals = places[0], places[1:]
    lengths = reach_lengths(costmap, start, goals, use_compiled=compiled)
    for goal, metres in zip(goals, lengths, strict=True):
        plan = plan_path(costmap, start, goal)
        assert plan is not None
        # Equal-cost routes may differ in cells; their lengths hardly.
        assert metres == pytest.approx(plan.length, rel=0.02)


def test_a_place_with_no_path_is_infinitely_far_and_so_is_everything_from_a_wall(
    costmap: Costmap,
) -> None:
    free = (-2.0, -0.5)
    pillar = (1.1, 0.0)  # inside a pillar: not a place the robot can be
    off_map = (50.0, 50.0)
    lengths = reach_lengths(costmap, free, [pillar, off_map, free])
    assert math.isinf(lengths[0]) and math.isinf(lengths[1]) and lengths[2] == 0.0
    assert np.isinf(reach_lengths(costmap, pillar, [free])).all()


def test_the_planners_matrix_is_symmetric_and_matches_its_legs(costmap: Costmap) -> None:
    planner = LegPlanner(costmap)
    places = free_places(costmap, 6, seed=11)
    matrix = planner.distances(places)
    assert np.allclose(matrix, matrix.T) and np.allclose(np.diag(matrix), 0.0)
    for i in range(len(places)):
        for j in range(i + 1, len(places)):
            leg = planner.leg(places[i], places[j]).length_m
            assert leg is not None and matrix[i, j] == pytest.approx(leg, rel=0.02, abs=0.01)


def test_orders_get_the_same_distances_either_way(costmap: Costmap) -> None:
    places = [(-2.0, -0.5), (1.1, 0.0), (0.5, 1.5)]  # the pillar: no path either way
    planner = LegPlanner(costmap)
    at_once = distances_between(places, planner)
    per_pair = distances_between(places, lambda a, b: planner.leg(a, b).length_m)
    assert np.allclose(at_once, per_pair, rtol=0.02)
    straight = distances_between(places, StraightLegs())
    assert np.allclose(straight, distances_between(places, straight_line))


def test_distances_measured_once_are_reused_by_another_planner_on_the_same_map_and_robot(
    costmap: Costmap,
) -> None:
    """The studio's second Order… (or a second ``plan --order`` in one process) searches
    only from places it never measured, and finds the same metres as a fresh search."""
    from navseq.route.distances import known_distances

    places = free_places(costmap, 12, seed=11)
    first = LegPlanner(costmap).distances(places)
    known = known_distances(costmap)
    searched = known.searched
    # Another costmap built alike (the same map and robot): the same kept distances.
    again = Costmap.from_grid(load_map(TURTLEBOT3_MAP), costmap.params)
    reordered = places[::-1]
    assert LegPlanner(again).distances(reordered) == pytest.approx(first[::-1, ::-1])
    assert known.searched == searched  # not one search more
    # One place moved: one search, from it to the others.
    moved = [*places[:-1], free_places(costmap, 13, seed=11)[-1]]
    assert moved[-1] not in places
    measured = LegPlanner(again).distances(moved)
    assert known.searched == searched + 1
    assert measured[:-1, :-1] == pytest.approx(first[:-1, :-1])
    assert measured[-1, :-1] == pytest.approx(reach_lengths(costmap, moved[-1], moved[:-1]))


def test_another_robot_on_the_same_map_measures_anew(costmap: Costmap) -> None:
    from dataclasses import replace

    from navseq.route.distances import known_distances

    places = free_places(costmap, 6, seed=5)
    LegPlanner(costmap).distances(places)
    wider = Costmap.from_grid(
        costmap.grid,
        replace(costmap.params, circumscribed_radius=costmap.params.circumscribed_radius + 0.05),
    )
    LegPlanner(wider).distances(places)
    assert known_distances(wider) is not known_distances(costmap)
    assert known_distances(wider).searched == len(places) - 1
