"""A good first route for the solver: nearest neighbour, then 2-opt and Or-opt moves.

OR-tools' guided local search given one second on 200 waypoints ended 2 to 5 % above
what it found in 30 s when it started from its own first route (cheapest arc). Starting
it from a route already locally optimal for the two classic moves, found here with numpy
in a fraction of the time, gets it closer in the same second
(``benchmarks/bench_route.py`` measures it). The costs may differ each way (the turns at
the waypoints make them), so every move is priced with the arcs it really drives:

- **2-opt** drives a stretch of the route backwards: its inner arcs are priced the
  other way round (prefix sums of both directions make every candidate O(1));
- **Or-opt** moves a run of one to three waypoints, in its own direction, elsewhere.

Each step takes the best move of all (one n x n array per kind); the first and last
place of the path stay where they are.
"""

from __future__ import annotations

import time

import numpy as np

#: Or-opt moves runs of this many waypoints at most.
LONGEST_RUN = 3


def nearest_neighbour(costs: np.ndarray, first: int, last: int) -> np.ndarray:
    """A path from ``first`` to ``last`` (the same node: a closed tour) through every
    node, always on to the cheapest node not yet visited."""
    count = len(costs)
    left = np.ones(count, bool)
    left[[first, last]] = False
    path = [first]
    for _ in range(int(left.sum())):
        row = np.where(left, costs[path[-1]], np.inf)
        chosen = int(np.argmin(row))
        path.append(chosen)
        left[chosen] = False
    path.append(last)
    return np.array(path, dtype=np.int64)


def _best_two_opt(path: np.ndarray, costs: np.ndarray) -> tuple[float, int, int]:
    """The best reversal of ``path[a : b + 1]`` (its saving is negative): delta, a, b."""
    forward = np.concatenate(([0.0], np.cumsum(costs[path[:-1], path[1:]])))
    backward = np.concatenate(([0.0], np.cumsum(costs[path[1:], path[:-1]])))
    inner = np.arange(1, len(path) - 1)
    a, b = inner[:, None], inner[None, :]
    before = costs[path[a - 1], path[a]] + costs[path[b], path[b + 1]] + forward[b] - forward[a]
    after = costs[path[a - 1], path[b]] + costs[path[a], path[b + 1]] + backward[b] - backward[a]
    delta = np.where(b > a, after - before, 0.0)
    at = int(np.argmin(delta))
    row, col = divmod(at, delta.shape[1])
    return float(delta[row, col]), row + 1, col + 1


def _best_or_opt(path: np.ndarray, costs: np.ndarray, run: int) -> tuple[float, int, int]:
    """The best move of a run of ``run`` nodes ``path[s : s + run]`` to between
    ``path[t]`` and ``path[t + 1]``: delta, s, t."""
    count = len(path)
    starts = np.arange(1, count - run)  # the run never holds the first or last node
    ends = starts + run - 1
    saved = (
        costs[path[starts - 1], path[starts]]
        + costs[path[ends], path[ends + 1]]
        - costs[path[starts - 1], path[ends + 1]]
    )
    gaps = np.arange(count - 1)
    added = (
        costs[path[gaps][None, :], path[starts][:, None]]
        + costs[path[ends][:, None], path[gaps + 1][None, :]]
        - costs[path[gaps], path[gaps + 1]][None, :]
    )
    inside = (gaps[None, :] >= starts[:, None] - 1) & (gaps[None, :] <= ends[:, None])
    delta = np.where(inside, np.inf, added - saved[:, None])
    at = int(np.argmin(delta))
    row, col = divmod(at, delta.shape[1])
    return float(delta[row, col]), int(starts[row]), int(gaps[col])


def improve(path: np.ndarray, costs: np.ndarray, deadline: float) -> np.ndarray:
    """``path`` after the best 2-opt or Or-opt move, again and again, until none saves
    anything or ``time.perf_counter()`` passes ``deadline``."""
    path = np.array(path, dtype=np.int64)
    if len(path) < 4:
        return path
    tiny = 1e-9 * max(1.0, float(np.abs(costs).max()))
    while time.perf_counter() < deadline:
        delta, a, b = _best_two_opt(path, costs)
        if delta < -tiny:
            path[a : b + 1] = path[a : b + 1][::-1]
            continue
        runs = range(1, min(LONGEST_RUN, len(path) - 3) + 1)
        moves = [_best_or_opt(path, costs, run) for run in runs]
        run = int(np.argmin([move[0] for move in moves])) + 1
        delta, start, gap = moves[run - 1]
        if delta >= -tiny:
            break
        moved = path[start : start + run].copy()
        rest = np.concatenate((path[:start], path[start + run :]))
        at = gap + 1 if gap < start else gap + 1 - run
        path = np.concatenate((rest[:at], moved, rest[at:]))
    return path


__all__ = ["improve", "nearest_neighbour"]
