"""The first route handed to the solver: every place once, ends kept, no longer than
nearest neighbour's, and as short as the best order on small cases."""

from __future__ import annotations

import itertools
import time

import numpy as np
import pytest

from navseq.route.improve import improve, nearest_neighbour


def length(costs: np.ndarray, path: np.ndarray) -> float:
    return float(costs[path[:-1], path[1:]].sum())


def best_length(costs: np.ndarray, first: int, last: int) -> float:
    middle = [node for node in range(len(costs)) if node not in (first, last)]
    return min(
        length(costs, np.array([first, *order, last])) for order in itertools.permutations(middle)
    )


@pytest.mark.parametrize("closed", [False, True])
def test_the_improved_route_visits_every_place_once_and_keeps_its_ends(closed: bool) -> None:
    rng = np.random.default_rng(1)
    costs = rng.uniform(1.0, 50.0, (60, 60))  # one way dearer than the other
    last = 0 if closed else 59
    start = nearest_neighbour(costs, 0, last)
    better = improve(start, costs, time.perf_counter() + 10.0)
    assert better[0] == 0 and better[-1] == last
    assert sorted(better[:-1] if closed else better) == list(range(60))
    assert length(costs, better) < length(costs, start)


def test_on_small_cases_the_moves_find_the_best_route_mostly() -> None:
    rng = np.random.default_rng(7)
    found = []
    for _ in range(20):
        points = rng.uniform(0.0, 10.0, (8, 2))
        costs = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
        costs[:, 0] += 0.5  # coming back to the start costs more (asymmetric)
        better = improve(nearest_neighbour(costs, 0, 7), costs, time.perf_counter() + 5.0)
        found.append(length(costs, better) / best_length(costs, 0, 7))
    assert min(found) == pytest.approx(1.0)
    assert np.median(found) == pytest.approx(1.0) and max(found) < 1.1


def test_a_reversed_stretch_is_priced_the_way_it_is_driven() -> None:
    """Four places on a line driven out and back: reversing a stretch that is cheap one
    way and dear the other is no saving, and is not made."""
    costs = np.array(
        [[0, 1, 9, 9], [9, 0, 1, 9], [9, 9, 0, 1], [9, 9, 9, 0]], dtype=float
    )  # only forwards is cheap
    path = np.array([0, 1, 2, 3])
    assert improve(path, costs, time.perf_counter() + 1.0).tolist() == [0, 1, 2, 3]
