"""The exact route of a few places is the best of all routes, whatever the machine's load."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.route.exact import exact_route


def cost_of(costs: np.ndarray, route: list[int]) -> float:
    return float(sum(costs[a, b] for a, b in itertools.pairwise(route)))


def best_of_all(costs: np.ndarray, end: int) -> float:
    middle = [node for node in range(len(costs)) if node not in (0, end)]
    return min(cost_of(costs, [0, *order, end]) for order in itertools.permutations(middle))


@settings(max_examples=60, deadline=None)
@given(
    size=st.integers(2, 7),
    seed=st.integers(0, 2**32 - 1),
    end_kind=st.sampled_from(["back", "last"]),
)
def test_the_exact_route_is_the_best_of_all_routes(size: int, seed: int, end_kind: str) -> None:
    costs = np.random.default_rng(seed).integers(0, 1000, size=(size, size))  # one-way costs
    end = 0 if end_kind == "back" else size - 1
    route = exact_route(costs, end)
    assert route[0] == 0 and route[-1] == end
    assert sorted(set(route)) == list(range(size))  # every place, once
    assert len(route) == size + (1 if end == 0 else 0)
    assert cost_of(costs, route) == best_of_all(costs, end)
