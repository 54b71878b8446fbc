"""The iterated local search over a route: never longer than the route it was given, its
ends kept, the C search and its Python twin making the same moves."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.route import order
from navseq.route.order import shortest_tour, tour_length
from navseq.route.search import compiled, search


def cost_of(costs: np.ndarray, path: list[int]) -> int:
    return int(sum(costs[a, b] for a, b in itertools.pairwise(path)))


@settings(max_examples=80, deadline=None)
@given(
    size=st.integers(2, 30),
    seed=st.integers(0, 2**32 - 1),
    kicks=st.integers(0, 40),
)
def test_the_searched_route_is_never_longer_and_keeps_its_ends(
    size: int, seed: int, kicks: int
) -> None:
    rng = np.random.default_rng(seed)
    costs = rng.integers(0, 1000, size=(size, size))  # one way dearer than the other
    given_path = rng.permutation(size).tolist()
    twins = [False, True] if compiled() else [False]
    settled = kicks % 2 == 0  # a path said to be settled skips the first descent
    answers = [
        search(costs, given_path, 0, kicks=kicks, seed=seed, settled=settled, use_compiled=use)
        for use in twins
    ]
    for path, _ in answers:
        assert sorted(path) == list(range(size))  # every node, once
        assert path[0] == given_path[0] and path[-1] == given_path[-1]
        assert cost_of(costs, path) <= cost_of(costs, given_path)
    assert all(answer == answers[0] for answer in answers)  # the same moves in C and Python


def test_a_route_already_best_is_given_back_as_it_is() -> None:
    costs = np.full((5, 5), 10)
    for a in range(4):
        costs[a, a + 1] = 1
    assert search(costs, [0, 1, 2, 3, 4], 0, kicks=20) == ([0, 1, 2, 3, 4], True)


def test_a_path_that_is_not_every_node_once_is_refused() -> None:
    with pytest.raises(ValueError, match="every node"):
        search(np.zeros((4, 4), dtype=np.int64), [0, 1, 1, 3], 0, kicks=1)


@pytest.mark.parametrize("use_compiled", [True, False])
@pytest.mark.parametrize(("closed", "last"), [(False, None), (True, None), (False, 39), (True, 39)])
def test_long_tours_keep_what_stays_put_with_and_without_the_c_search(
    monkeypatch: pytest.MonkeyPatch, use_compiled: bool, closed: bool, last: int | None
) -> None:
    """Past the exact solver's size, with the C search or (without it) OR-tools."""
    if use_compiled and not compiled():
        pytest.skip("navseq.route._tour is not built")
    if not use_compiled:
        monkeypatch.setattr("navseq.route.search._compiled", None)
    rng = np.random.default_rng(5)
    points = rng.random((40, 2)) * 20.0
    matrix = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    matrix += rng.uniform(0.0, 2.0, matrix.shape)  # turns: one way dearer
    heard: list[float] = []
    tour = shortest_tour(
        matrix, closed=closed, last=last, time_limit_s=0.3, on_solution=heard.append
    )
    assert sorted(tour) == list(range(40)) and tour[0] == 0
    if last is not None:
        assert tour[-1] == last
    assert heard == sorted(heard, reverse=True)  # each order heard of is better
    drawn = list(range(40))
    assert tour_length(matrix, tour, closed) < tour_length(matrix, drawn, closed) / 2
    if use_compiled:
        # What was reported last is the order given (a fixed last node's way back aside).
        way_back = matrix[last, 0] if closed and last is not None else 0.0
        assert heard[-1] == pytest.approx(tour_length(matrix, tour, closed) - way_back, abs=0.05)


def test_a_search_told_to_settle_still_gives_a_whole_order() -> None:
    rng = np.random.default_rng(8)
    points = rng.random((60, 2)) * 20.0
    matrix = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    tour = shortest_tour(matrix, closed=False, time_limit_s=5.0, settle_s=order.SLICE_S)
    assert sorted(tour) == list(range(60)) and tour[0] == 0


def test_ctrl_c_ends_a_long_search_with_keyboard_interrupt() -> None:
    """``navseq plan``'s Ctrl-C: the search stops at its next slice, not at its limit."""
    import os
    import signal
    import threading

    rng = np.random.default_rng(9)
    points = rng.random((300, 2)) * 50.0
    matrix = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            shortest_tour(matrix, closed=False, time_limit_s=60.0)
    finally:
        timer.cancel()
