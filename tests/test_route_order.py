"""The shortest visiting order: as short as the best of every order, with what must stay put."""

from __future__ import annotations

import itertools
import math
import random
from dataclasses import replace

import numpy as np
import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.route.order import MAX_WAYPOINTS, shortest_order

Place = tuple[float, float]


def mission_of(
    points: list[Place], *, start: Place | None = None, loops: int | None = 1
) -> Mission:
    return Mission(
        waypoints=tuple(
            Waypoint(x, y, yaw_deg=0, name=f"w{i + 1}") for i, (x, y) in enumerate(points)
        ),
        start=Pose2D(start[0], start[1], 0.0) if start is not None else None,
        loops=loops,
    )


def driven(places: list[Place], closed: bool) -> float:
    ends = [*places[1:], places[0]] if closed else places[1:]
    return sum(math.dist(a, b) for a, b in zip(places, ends, strict=False))


def best_by_trying_all(
    points: list[Place], *, start: Place | None, closed: bool, keep_last: bool
) -> float:
    head = [start] if start is not None else [points[0]]
    free = points if start is not None else points[1:]
    tail: list[Place] = []
    if keep_last:
        free, tail = free[:-1], [points[-1]]
    return min(driven([*head, *middle, *tail], closed) for middle in itertools.permutations(free))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize(
    ("with_start", "loops", "keep_last"),
    [(False, 1, False), (True, 1, False), (False, None, False), (True, 1, True), (False, 3, True)],
)
def test_the_order_found_is_as_short_as_the_best_of_all_orders(
    seed: int, with_start: bool, loops: int | None, keep_last: bool
) -> None:
    rng = random.Random(seed)
    points = [(rng.uniform(-5, 5), rng.uniform(-5, 5)) for _ in range(7)]
    start = (rng.uniform(-5, 5), rng.uniform(-5, 5)) if with_start else None
    mission = mission_of(points, start=start, loops=loops)
    closed = loops != 1
    ordering = shortest_order(mission, time_limit_s=0.3, keep_last=keep_last)
    assert sorted(ordering.order) == list(range(7))  # every waypoint, once
    if not with_start or closed:
        assert ordering.order[0] == 0  # waypoint 1 stays first
    if keep_last:
        assert ordering.order[-1] == 6
    # A patrol starts from its start pose once; its laps are what the order changes.
    used_start = start if not closed else None
    visited = [points[i] for i in ordering.order]
    found = driven(([used_start] if used_start else []) + visited, closed)
    best = best_by_trying_all(points, start=used_start, closed=closed, keep_last=keep_last)
    assert found == pytest.approx(best, abs=0.01)


def test_a_file_already_in_the_best_order_or_a_tie_is_left_as_it_is() -> None:
    square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    assert not shortest_order(mission_of(square)).changed
    # A patrol the other way round is as long: no reason to change what the user wrote.
    assert not shortest_order(mission_of(square[:1] + square[:0:-1], loops=None)).changed


def test_a_leg_with_no_path_is_avoided_where_another_order_has_one() -> None:
    points = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (3.0, 0.0)]
    wall = {((1.0, 0.0), (2.0, 0.0))}  # 2 cannot be reached from 1 directly, nor 1 from 2

    def length(a: Place, b: Place) -> float | None:
        return None if (a, b) in wall or (b, a) in wall else math.dist(a, b)

    order = shortest_order(mission_of(points), length, time_limit_s=0.3).order
    pairs = {(points[a], points[b]) for a, b in itertools.pairwise(order)}
    assert not pairs & (wall | {(b, a) for a, b in wall})


def test_a_mission_too_long_to_order_is_refused_with_a_way_out() -> None:
    points = [(float(i), 0.0) for i in range(MAX_WAYPOINTS + 1)]
    with pytest.raises(NavseqError, match="in parts"):
        shortest_order(mission_of(points))


def test_the_reordered_mission_keeps_every_waypoint_and_setting() -> None:
    mission = replace(mission_of([(0.0, 0.0), (5.0, 0.0), (1.0, 0.0)]), frame="odom")
    reordered = shortest_order(mission, time_limit_s=0.2).apply(mission)
    assert [w.name for w in reordered.waypoints] == ["w1", "w3", "w2"]
    assert replace(reordered, waypoints=mission.waypoints) == mission


def test_a_time_limit_too_short_for_the_first_tour_still_gives_an_order() -> None:
    """The studio gives the solver 1 s; on a loaded machine the first tour of thousands of
    places can take longer, and the solver then had no order at all to give."""
    from navseq.route.order import shortest_tour, tour_length

    rng = np.random.default_rng(3)
    points = rng.random((600, 2)) * 50.0
    matrix = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    tour = shortest_tour(matrix, closed=False, time_limit_s=0.001)
    assert sorted(tour) == list(range(600)) and tour[0] == 0
    # A first tour by cheapest arc: far shorter than the places in the order drawn.
    assert tour_length(matrix, tour, False) < tour_length(matrix, list(range(600)), False) / 4
