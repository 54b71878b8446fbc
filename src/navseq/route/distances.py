"""Distances for ordering, kept per map and robot: a second Order… reuses the searches done.

Ordering measures the way between every two waypoints (one search per waypoint, see
:meth:`navseq.route.legs.LegPlanner.distances`): 400 arena waypoints take about two
seconds, 2000 warehouse waypoints much longer. The studio's Order… after a few edits, or
a second ``plan --order`` in one process, asks for nearly the same pairs again; what was
measured is kept here and only the pairs never measured are searched.

What a distance depends on is the costmap the planner searches (the map and the robot's
footprint and costmap settings: its planning costs), the grid's resolution and origin, and
the two cells the places fall in (places snap to cells as in the planner). The cache is
keyed by those: a changed map file, robot or inflation setting gives another key, so
nothing measured on the old one is used. A pair measured one way serves the other way too
(a path is as long both ways, but for the grid's tie-breaking).
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any
from weakref import WeakKeyDictionary

import numpy as np

if TYPE_CHECKING:
    from navseq.sim.costmap import Costmap

Place = tuple[float, float]
#: Metres from one place to each of others (``inf``: no path), one search.
Reach = Callable[["Costmap", Place, list[Place]], np.ndarray]
#: Cells whose distances are kept per costmap at most (the matrix is cells² floats:
#: 2500 cells, 50 MB); a request past it starts the table again with its own cells.
MAX_CELLS = 2500
#: Costmaps (maps x robots) whose distances are kept.
COSTMAPS_KEPT = 4


class KnownDistances:
    """Metres between cells of one costmap measured so far (NaN: not yet)."""

    def __init__(self) -> None:
        self._index: dict[int, int] = {}  # cell (row * width + col) -> row of the table
        self._metres = np.full((0, 0), np.nan)
        self.lock = threading.Lock()
        self.searched = 0  # searches made, for tests and benchmarks

    def rows_of(self, cells: Sequence[int]) -> np.ndarray:
        """The table's row of each cell, added (unmeasured) where new."""
        new = [cell for cell in dict.fromkeys(cells) if cell not in self._index]
        if len(self._index) + len(new) > MAX_CELLS:
            self._index, self._metres = {}, np.full((0, 0), np.nan)
            new = list(dict.fromkeys(cells))
        if new:
            size = len(self._index)
            for offset, cell in enumerate(new):
                self._index[cell] = size + offset
            grown = np.full((size + len(new), size + len(new)), np.nan)
            grown[:size, :size] = self._metres
            self._metres = grown
        return np.array([self._index[cell] for cell in cells], dtype=np.int64)

    def table(self, rows: np.ndarray) -> np.ndarray:
        """The metres known between ``rows``, each pair's either way (NaN: unknown)."""
        part = self._metres[np.ix_(rows, rows)]
        return np.where(np.isnan(part), part.T, part)

    def store(self, row: int, others: np.ndarray, metres: np.ndarray) -> None:
        self._metres[row, others] = metres


_KEPT: OrderedDict[tuple[Any, ...], KnownDistances] = OrderedDict()
_KEYS: WeakKeyDictionary[Costmap, tuple[Any, ...]] = WeakKeyDictionary()
_LOCK = threading.Lock()


def costmap_key(costmap: Costmap) -> tuple[Any, ...]:
    """What the distances on ``costmap`` depend on: its planning costs (a digest, worked
    out once per costmap), shape, resolution and origin."""
    with _LOCK:
        key = _KEYS.get(costmap)
    if key is None:
        grid, cost = costmap.grid, np.ascontiguousarray(costmap.planning_cost)
        digest = hashlib.blake2b(cost.tobytes(), digest_size=16).hexdigest()
        key = (digest, cost.shape, str(cost.dtype), grid.resolution, grid.origin)
        with _LOCK:
            _KEYS[costmap] = key
    return key


def known_distances(costmap: Costmap) -> KnownDistances:
    """The distances kept for ``costmap``'s map and robot (made empty the first time)."""
    key = costmap_key(costmap)
    with _LOCK:
        known = _KEPT.get(key)
        if known is None:
            known = _KEPT[key] = KnownDistances()
            while len(_KEPT) > COSTMAPS_KEPT:
                _KEPT.popitem(last=False)
        _KEPT.move_to_end(key)
        return known


def distance_table(
    costmap: Costmap, places: Sequence[Place], reach: Reach, *, workers: int = 1
) -> np.ndarray:
    """Metres between every two of ``places`` on ``costmap`` (``inf``: no path): the pairs
    measured before (by any caller, on the same map and robot) from the cache, the others
    by ``reach`` from each place to the places after it still unknown, on ``workers``
    threads."""
    from concurrent.futures import ThreadPoolExecutor

    known = known_distances(costmap)
    grid = costmap.grid
    width = costmap.planning_cost.shape[1]
    cells = [row * width + col for row, col in (grid.world_to_cell(*p) for p in places)]
    with known.lock:  # one ordering at a time fills a table (a second waits, then reuses)
        rows = known.rows_of(cells)
        table = known.table(rows)
        work = [(i, np.flatnonzero(row)) for i, row in enumerate(_searches(table)) if row.any()]

        def measure(item: tuple[int, np.ndarray]) -> np.ndarray:
            i, others = item
            return reach(costmap, places[i], [places[j] for j in others])

        with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
            for (i, others), metres in zip(work, pool.map(measure, work), strict=True):
                known.store(int(rows[i]), rows[others], metres)
                known.searched += 1
        table = known.table(rows)
    matrix = np.asarray(table, dtype=float)
    np.fill_diagonal(matrix, 0.0)
    return matrix


def _searches(table: np.ndarray) -> np.ndarray:
    """Which pairs to measure from which end: ``[a, b]`` True measures a to b. Each
    unknown pair once, from the end with more unknown pairs: with nothing known, each
    place to the places after it (as :func:`reach_lengths` was always asked); with one
    place moved, one search from it to all the others."""
    unknown = np.isnan(table)
    np.fill_diagonal(unknown, False)
    counts = unknown.sum(axis=1)
    upper = np.triu(unknown, 1)
    flip = upper & (counts[None, :] > counts[:, None])
    return (upper & ~flip) | flip.T


__all__ = ["MAX_CELLS", "KnownDistances", "costmap_key", "distance_table", "known_distances"]
