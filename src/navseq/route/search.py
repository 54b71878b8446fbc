"""Iterated local search over a route: how the visiting order is found (OR-tools without it).

OR-tools' guided local search given one second on 200 waypoints spread over a
2000 x 2000 map ended 1.6 to 2.8 % above what it found in 30 s, even when it started
from a route made locally optimal by :mod:`navseq.route.improve`. An iterated local
search does better in the same second (``benchmarks/bench_route.py``):

- **local search**: Or-opt (a run of one to three waypoints moved elsewhere, either way
  round) and 2-opt (a stretch of the route driven backwards), each priced with the arcs
  it really drives (the costs differ each way: the turns at the waypoints make them).
  Only the waypoints at arcs a move changed are looked at again ("don't-look bits");
- **kicks**: two neighbouring stretches of the route (up to 35 waypoints each) swap
  places, which keeps each stretch's direction; the local search then starts from the
  waypoints at the three arcs the kick changed, and the result is kept when it is no
  longer than the route before the kick (otherwise that route is taken back).

The route's first and last node stay where they are. The search runs in a small C
extension (``navseq.route._tour``) when it is built, thousands of kicks a second;
otherwise in :func:`_search_python`, which makes the same moves (the same answer for the
same kicks and seed) far more slowly: :mod:`navseq.route.order` then uses OR-tools
instead, and the tests check the two against each other.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Sequence

import numpy as np

try:
    from navseq.route import _tour as _compiled  # type: ignore[attr-defined]
except ImportError:  # no C compiler at install time
    _compiled = None

#: Or-opt moves runs of this many nodes at most.
LONGEST_RUN = 3
#: A kick swaps two stretches of this many nodes at most.
LONGEST_KICK = 35
_MASK = (1 << 64) - 1


def compiled() -> bool:
    """Whether the C search is there (the Python one is far slower)."""
    return _compiled is not None


def search(
    costs: np.ndarray,
    path: Sequence[int],
    seconds: float,
    *,
    kicks: int = -1,
    seed: int = 0,
    settled: bool = False,
    use_compiled: bool = True,
) -> tuple[list[int], bool]:
    """The shortest route found from ``path`` (every node of the integer ``costs`` once,
    its first and last staying put) in ``seconds`` (<= 0: no limit) or ``kicks`` kicks
    (< 0: no limit), whichever ends first; never longer than ``path``. ``settled``: the
    path is a search's answer that was settled, so the first descent over every node
    (tens of milliseconds on 2000) is skipped. With the route comes whether it is settled
    (its local search ran to the end, not cut short by the time limit)."""
    arcs = np.ascontiguousarray(costs, dtype=np.int64)
    route = np.ascontiguousarray(path, dtype=np.int64)
    if arcs.shape != (len(route), len(route)) or sorted(route.tolist()) != list(range(len(route))):
        raise ValueError("path must hold every node of the n x n costs once")
    if seconds <= 0 and kicks < 0:
        raise ValueError("a search needs a time limit or a number of kicks")
    if use_compiled and _compiled is not None:
        found, done = _compiled.search(
            arcs, route, float(seconds), int(kicks), int(seed), bool(settled)
        )
        return list(found), bool(done)
    return _search_python(arcs, route.tolist(), seconds, kicks, seed, settled)


class _Path:
    """A route with the prefix sums that price 2-opt moves, and the queue of nodes to
    look at (:c:func:`improve_node` and friends in ``_tour.c``, move for move)."""

    def __init__(self, costs: np.ndarray, path: list[int], deadline: float) -> None:
        self.cost = costs.tolist()
        self.n = len(path)
        self.path = list(path)
        self.pos = [0] * self.n
        self.fwd = [0] * self.n
        self.bwd = [0] * self.n
        self.queue: deque[int] = deque()
        self.queued = [False] * self.n
        self.deadline = deadline
        self.sums()

    def sums(self) -> None:
        cost, path = self.cost, self.path
        for k in range(1, self.n):
            self.fwd[k] = self.fwd[k - 1] + cost[path[k - 1]][path[k]]
            self.bwd[k] = self.bwd[k - 1] + cost[path[k]][path[k - 1]]
        for k, node in enumerate(path):
            self.pos[node] = k

    @property
    def length(self) -> int:
        return self.fwd[self.n - 1]

    def push(self, node: int) -> None:
        at = self.pos[node]
        if 0 < at < self.n - 1 and not self.queued[node]:
            self.queued[node] = True
            self.queue.append(node)

    def push_around(self, at: int) -> None:
        for k in range(at - 1, at + 2):
            if 0 <= k < self.n:
                self.push(self.path[k])

    def improve_node(self, v: int) -> bool:
        n, p, c, path = self.n, self.pos[v], self.cost, self.path
        best, kind, reversed_, ba, bb, bg = 0, 0, False, 0, 0, 0
        for run in range(1, LONGEST_RUN + 1):
            for side in range(1 if run == 1 else 2):
                a = p - run + 1 if side else p
                b = a + run - 1
                if a < 1 or b > n - 2:
                    continue
                s0, sk, prev, nxt = path[a], path[b], path[a - 1], path[b + 1]
                inner = (self.bwd[b] - self.bwd[a]) - (self.fwd[b] - self.fwd[a])
                saved = c[prev][s0] + c[sk][nxt] - c[prev][nxt]
                for g in range(n - 1):
                    if a - 1 <= g <= b:
                        continue
                    x, y = path[g], path[g + 1]
                    base = c[x][y]
                    d = c[x][s0] + c[sk][y] - base - saved
                    if d < best:
                        best, kind, reversed_, ba, bb, bg = d, 1, False, a, b, g
                    if run > 1:
                        d = c[x][sk] + c[s0][y] - base - saved + inner
                        if d < best:
                            best, kind, reversed_, ba, bb, bg = d, 1, True, a, b, g
        for other in range(1, n - 1):
            if other == p:
                continue
            i, j = (other, p) if other < p else (p, other)
            d = (
                c[path[i - 1]][path[j]]
                + c[path[i]][path[j + 1]]
                - c[path[i - 1]][path[i]]
                - c[path[j]][path[j + 1]]
                + (self.bwd[j] - self.bwd[i])
                - (self.fwd[j] - self.fwd[i])
            )
            if d < best:
                best, kind, ba, bb = d, 2, i, j
        if kind == 0:
            return False
        if kind == 1:
            run = bb - ba + 1
            at = bg if bg < ba else bg - run
            self.push_around(max(ba - 1, 0))
            self.push_around(min(bb + 1, n - 1))
            moved = path[ba : bb + 1]
            if reversed_:
                moved.reverse()
            rest = path[:ba] + path[bb + 1 :]
            self.path = rest[: at + 1] + moved + rest[at + 1 :]
            self.sums()
            self.push_around(at)
            self.push_around(at + run)
            self.push_around(min(at + run + 1, n - 1))
        else:
            path[ba : bb + 1] = path[ba : bb + 1][::-1]
            self.sums()
            self.push_around(ba)
            self.push_around(bb)
        return True

    def local_search(self) -> None:
        looked = 0
        while self.queue:
            looked += 1
            if self.deadline > 0 and looked % 64 == 0 and time.perf_counter() >= self.deadline:
                return
            v = self.queue.popleft()
            self.queued[v] = False
            if self.improve_node(v):
                self.push(v)


def _next_random(state: int) -> int:
    state ^= (state << 13) & _MASK
    state ^= state >> 7
    state ^= (state << 17) & _MASK
    return state


def _search_python(
    costs: np.ndarray, path: list[int], seconds: float, kicks: int, seed: int, settled: bool
) -> tuple[list[int], bool]:
    """The C search's twin (the queue is a deque, not a ring: the same order)."""
    n = len(path)
    if n < 4:
        return list(path), True
    began = time.perf_counter()
    route = _Path(costs, path, began + seconds if seconds > 0 else 0.0)
    if not settled:
        for k in range(1, n - 1):
            route.push(route.path[k])
    route.local_search()
    best_settled = not route.queue
    length = best = route.length
    current, best_path = list(route.path), list(route.path)
    state = (seed * 2654435761 + 88172645463325252) & _MASK
    kick = 0
    while n >= 5 and (kicks < 0 or kick < kicks):
        kick += 1
        if seconds > 0 and time.perf_counter() - began >= seconds:
            break
        state = _next_random(state)
        a = 1 + state % (n - 3)
        most = min((n - 1 - a) // 2, LONGEST_KICK)
        if most < 1:
            continue
        state = _next_random(state)
        l1 = 1 + state % most
        state = _next_random(state)
        l2 = 1 + state % most
        b, c = a + l1, a + l1 + l2
        route.path[a:c] = route.path[b:c] + route.path[a:b]
        route.sums()
        for at in (a, a + l2, c - 1, c):
            route.push_around(at)
        route.local_search()
        if route.length <= length:
            length, current = route.length, list(route.path)
            if length < best:
                best, best_path, best_settled = length, list(route.path), not route.queue
        else:
            route.path = list(current)
            route.sums()
    return best_path, best_settled


__all__ = ["LONGEST_KICK", "LONGEST_RUN", "compiled", "search"]
