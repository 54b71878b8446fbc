"""The best route through a few places, found exactly (Held–Karp dynamic programming).

For a handful of waypoints a routing solver's answer depends on how much of its time
limit the machine lets it use; the exact answer costs less than a millisecond and does
not. :func:`exact_route` is used below :data:`EXACT_UP_TO` places between the ends.
"""

from __future__ import annotations

import itertools

import numpy as np

#: Places between the two ends up to which the route is found exactly (2**n * n**2 steps).
EXACT_UP_TO = 9


def exact_route(costs: np.ndarray, end: int) -> list[int]:
    """The cheapest route over ``costs`` (from each node to each) from node 0 through
    every other node once to ``end`` (0: back to the start), as ``[0, ..., end]``."""
    middle = [node for node in range(len(costs)) if node not in (0, end)]
    if len(middle) > EXACT_UP_TO:
        raise ValueError(f"{len(middle)} places are too many to try every route")
    if not middle:
        return [0, end]
    # best[(subset, last)]: the cheapest way from 0 through `subset` (bits of `middle`)
    # ending at middle[last], and the node before it.
    best: dict[tuple[int, int], tuple[float, int]] = {
        (1 << i, i): (float(costs[0, node]), -1) for i, node in enumerate(middle)
    }
    for size in range(2, len(middle) + 1):
        for chosen in itertools.combinations(range(len(middle)), size):
            subset = sum(1 << i for i in chosen)
            for last in chosen:
                before = subset & ~(1 << last)
                best[(subset, last)] = min(
                    (best[(before, k)][0] + float(costs[middle[k], middle[last]]), k)
                    for k in chosen
                    if k != last
                )
    full = (1 << len(middle)) - 1
    _, last = min(
        (best[(full, k)][0] + float(costs[middle[k], end]), k) for k in range(len(middle))
    )
    order, subset = [], full
    while last != -1:
        order.append(middle[last])
        subset, last = subset & ~(1 << last), best[(subset, last)][1]
    return [0, *reversed(order), end]
