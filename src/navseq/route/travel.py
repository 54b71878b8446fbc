"""Travel times for ordering: the way between every two places in seconds, turns included.

A robot that stops at a waypoint turns there twice: to the waypoint's yaw when it
arrives (the goal's heading), then to the direction its next path leaves in before it
drives off. Which way it arrives depends on the waypoint it came from, so the exact turn
at a waypoint depends on two legs, which a routing solver's arc costs cannot hold. Each
turn is charged to one arc instead, and that is exact for waypoints the robot stops at:

    seconds(i -> j) = metres(i -> j) / top speed
                      + turn from yaw(i) to the path's heading leaving i
                      + turn from the path's heading arriving at j to yaw(j)

Turns take :func:`navseq.eta.drive.turn_until`'s time (the robot's turn rate, its
angular acceleration and braking; the start turn only when the path leaves more than the
controller's ``rotate_above`` off the heading, as :mod:`navseq.eta.drive` does). The
approximation: at a pass-through waypoint the robot neither stops nor turns to its yaw,
so no turn is charged there (the bend it drives through is not either); a start pose's
yaw is the heading the robot leaves it with. A path's heading is the direction to its
cell one lookahead along (:func:`navseq.sim.planner.reach_routes`).

The headings are kept per map and robot beside the distances
(:mod:`navseq.route.distances`), so a second ordering searches only what is new.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:
    from navseq.eta.drive import DriveModel
    from navseq.sim.costmap import Costmap

Place = tuple[float, float]
#: Searches done and searches in all, after each search (for a progress display).
SearchProgress = Callable[[int, int], None]


@dataclass(frozen=True)
class RouteTable:
    """Between every two places: metres (``inf``: no path), and the heading (rad) the
    path leaves the first with and arrives at the second with (NaN: none, or the same
    place)."""

    metres: np.ndarray
    depart: np.ndarray
    arrive: np.ndarray


@runtime_checkable
class Routes(Protocol):
    """What measures every route with its headings at once (a
    :class:`~navseq.route.legs.LegPlanner`, :class:`~navseq.route.legs.StraightLegs`)."""

    def routes(
        self, places: Sequence[Place], anchor_m: float, *, progress: SearchProgress | None = None
    ) -> RouteTable:
        """Every route between ``places``, headings taken ``anchor_m`` along them."""
        ...


def straight_routes(places: Sequence[Place]) -> RouteTable:
    """Straight lines: each leaves and arrives in the direction from one place to the other."""
    points = np.asarray(places, dtype=float).reshape(-1, 2)
    dx = points[None, :, 0] - points[:, None, 0]
    dy = points[None, :, 1] - points[:, None, 1]
    metres = np.hypot(dx, dy)
    heading = np.where(metres > 0, np.arctan2(dy, dx), np.nan)
    return RouteTable(metres, heading, heading.copy())


class _KnownHeadings:
    """Headings between cells of one costmap measured so far (``measured`` False: not yet)."""

    def __init__(self) -> None:
        self.index: dict[int, int] = {}
        self.depart = np.zeros((0, 0), np.float32)
        self.arrive = np.zeros((0, 0), np.float32)
        self.measured = np.zeros((0, 0), bool)

    def rows_of(self, cells: Sequence[int], max_cells: int) -> np.ndarray:
        new = [cell for cell in dict.fromkeys(cells) if cell not in self.index]
        if len(self.index) + len(new) > max_cells:
            self.__init__()  # type: ignore[misc]
            new = list(dict.fromkeys(cells))
        if new:
            size, grown = len(self.index), len(self.index) + len(new)
            for offset, cell in enumerate(new):
                self.index[cell] = size + offset
            for name, fill in (("depart", np.nan), ("arrive", np.nan), ("measured", False)):
                old = getattr(self, name)
                table = np.full((grown, grown), fill, dtype=old.dtype)
                table[:size, :size] = old
                setattr(self, name, table)
        return np.array([self.index[cell] for cell in cells], dtype=np.int64)

    def tables(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Depart, arrive and measured between ``rows``; a pair measured the other way
        round serves reversed (a path driven backwards leaves the way it arrived, turned
        by half a turn)."""
        grid = np.ix_(rows, rows)
        measured, depart, arrive = self.measured[grid], self.depart[grid], self.arrive[grid]
        flipped = ~measured & measured.T
        depart = np.where(flipped, _opposite(arrive.T), depart).astype(float)
        arrive = np.where(flipped, _opposite(depart.T), arrive).astype(float)
        return depart, arrive, measured | measured.T


def _opposite(heading: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * (heading.astype(float) + math.pi)))


_KEPT: OrderedDict[tuple[Any, ...], _KnownHeadings] = OrderedDict()
_LOCK = threading.Lock()


def route_table(
    costmap: Costmap,
    places: Sequence[Place],
    anchor_m: float,
    *,
    workers: int = 1,
    progress: SearchProgress | None = None,
) -> RouteTable:
    """Every route between ``places`` on ``costmap`` with its headings: what was measured
    before (metres by any caller, headings by orderings) from the caches, the rest by one
    search per place (:func:`navseq.sim.planner.reach_routes`) on ``workers`` threads.
    A KeyboardInterrupt drops the searches not started and waits only for the running
    ones."""
    import queue
    from concurrent.futures import Future, ThreadPoolExecutor

    from navseq.route import distances

    known = distances.known_distances(costmap)
    key = (*distances.costmap_key(costmap), round(anchor_m, 6))
    with _LOCK:
        headings = _KEPT.setdefault(key, _KnownHeadings())
        _KEPT.move_to_end(key)
        while len(_KEPT) > distances.COSTMAPS_KEPT:
            _KEPT.popitem(last=False)
    width = costmap.planning_cost.shape[1]
    cells = [row * width + col for row, col in (costmap.grid.world_to_cell(*p) for p in places)]
    with known.lock:
        rows = known.rows_of(cells)
        heading_rows = headings.rows_of(cells, distances.MAX_CELLS)
        _, _, measured = headings.tables(heading_rows)
        unknown = np.where(measured, known.table(rows), np.nan)
        work = [
            (i, np.flatnonzero(row))
            for i, row in enumerate(distances._searches(unknown))
            if row.any()
        ]

        pool = ThreadPoolExecutor(max_workers=max(1, workers))
        try:
            measure = _measure(costmap, places, anchor_m, work, pool)
            # Each search says it is over on a queue: waiting on all the pending ones
            # at once (concurrent.futures.wait) cost the main thread a waiter per
            # future per search, and 2000 places took more CPU than the searches did.
            finished: queue.SimpleQueue[Future[np.ndarray]] = queue.SimpleQueue()
            pending: dict[Future[np.ndarray], tuple[int, np.ndarray]] = {}
            for item in work:
                future = pool.submit(measure, item)
                pending[future] = item
                future.add_done_callback(finished.put)
            done_count = 0
            if progress is not None:
                progress(0, len(work))
            while pending:
                try:  # with a timeout: Ctrl-C is heard while searches run
                    future = finished.get(timeout=0.5)
                except queue.Empty:
                    continue
                i, others = pending.pop(future)
                found = future.result()
                known.store(int(rows[i]), rows[others], found[:, 0])
                known.searched += 1
                at, to = int(heading_rows[i]), heading_rows[others]
                headings.depart[at, to] = found[:, 1]
                headings.arrive[at, to] = found[:, 2]
                headings.measured[at, to] = True
                done_count += 1
                if progress is not None:
                    progress(done_count, len(work))
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        metres = np.asarray(known.table(rows), dtype=float)
        depart, arrive, _ = headings.tables(heading_rows)
    np.fill_diagonal(metres, 0.0)
    np.fill_diagonal(depart, np.nan)
    np.fill_diagonal(arrive, np.nan)
    return RouteTable(metres, depart, arrive)


def _measure(
    costmap: Costmap,
    places: Sequence[Place],
    anchor_m: float,
    work: list[tuple[int, np.ndarray]],
    pool: Any,
) -> Callable[[tuple[int, np.ndarray]], np.ndarray]:
    """What measures one search of ``work`` (a place, the places it goes to): the exact
    search per place, or on a big map the coarse routes (:mod:`navseq.route.coarse`),
    whose searches near each place are made first on ``pool``."""
    from navseq.route import coarse
    from navseq.sim.planner import compiled_search_available, reach_routes

    if not (compiled_search_available() and coarse.worth_it(costmap, len(work))):

        def exact(item: tuple[int, np.ndarray]) -> np.ndarray:
            i, others = item
            return reach_routes(costmap, places[i], [places[j] for j in others], anchor_m)

        return exact
    routes = coarse.CoarseRoutes(costmap, places, anchor_m)
    ends = {i for i, _ in work} | {int(j) for _, others in work for j in others}
    for _ in pool.map(routes.prepare, sorted(ends)):
        pass
    return lambda item: routes.reach(*item)


def _turn_seconds(angle: np.ndarray, within: float, model: DriveModel) -> np.ndarray:
    """:func:`navseq.eta.drive.turn_until` of many angles (NaN: no turn)."""
    angle = np.abs(np.nan_to_num(angle, nan=0.0))
    up, down, top = model.turn_accel, model.turn_decel, model.turn_rate
    if top <= 0:
        return np.zeros_like(angle)
    ramps = top * top / (2.0 * up) + top * top / (2.0 * down)
    peak = np.sqrt(2.0 * np.minimum(angle, ramps) * up * down / (up + down))
    whole = np.where(
        angle >= ramps, top / up + top / down + (angle - ramps) / top, peak / up + peak / down
    )
    last = math.sqrt(2.0 * within / down)
    return np.where(angle <= within, 0.0, np.maximum(whole - last, 0.0))


def _turn(from_heading: np.ndarray, to_heading: np.ndarray) -> np.ndarray:
    return np.abs(np.angle(np.exp(1j * (to_heading - from_heading))))


def travel_seconds(
    table: RouteTable, yaws: Sequence[float | None], model: DriveModel
) -> np.ndarray:
    """Seconds from every place to every other (``inf``: no path): driving at top speed
    plus the turns of the module doc. ``yaws[i]`` is the heading the robot has at place
    ``i`` (None: it does not stop there, nothing is turned)."""
    speed = model.max_speed if model.max_speed > 0 else 1.0
    seconds = table.metres / speed
    yaw = np.array([math.nan if y is None else y for y in yaws], dtype=float)
    leave = _turn(yaw[:, None], table.depart)
    arrive = _turn(table.arrive, yaw[None, :])
    seconds = seconds + _turn_seconds(
        np.where(leave > model.rotate_above, leave, 0.0), model.rotate_until, model
    )
    seconds = seconds + _turn_seconds(arrive, model.yaw_tolerance, model)
    np.fill_diagonal(seconds, 0.0)
    return seconds


__all__ = ["RouteTable", "Routes", "route_table", "straight_routes", "travel_seconds"]
