"""The shortest order to visit a mission's waypoints in.

A travelling-salesman problem over the lengths the robot would drive: the planned path
between every two waypoints on the robot's costmap (the planner the simulator drives
with), or straight lines when no map is known. The order: a first tour by nearest
neighbour, then the iterated local search of :mod:`navseq.route.search` (Or-opt and 2-opt
moves, kicks) for ``time_limit_s``; without that search's C extension, 2-opt and Or-opt
in numpy, then OR-tools' routing solver (guided local search) for the rest. It comes
with the ``navseq[plan]`` extra.

What stays where it is, so that the new order is a mission the user still recognises:

- a mission with a ``start:`` pose starts there, and any waypoint may come first;
- without one, waypoint 1 stays first (it is where the user put the robot to work);
- a patrol (``loops`` other than 1) is a closed tour back to its first waypoint, and
  since a cycle has no beginning, waypoint 1 stays first there too;
- with ``keep_last``, the file's last waypoint stays last (a dock the robot ends at).

Pairs with no path between them cost :data:`NO_PATH_M` each: the solver avoids them
where it can, and the caller says which legs have no path.

Given the robot, the order is the one that takes the least time: the planned lengths at
its top speed plus the turns at each waypoint (:mod:`navseq.route.travel` says how a
turn, which depends on the waypoint before, is put on one leg). Without it, the one
that drives the fewest metres.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from navseq.errors import NavseqError
from navseq.extras import require_extra
from navseq.route.exact import EXACT_UP_TO, exact_route

if TYPE_CHECKING:
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile

#: Waypoints at most: the distances take one search per waypoint over the map, and the
#: solver a matrix of n² of them.
MAX_WAYPOINTS = 2000
#: The cost of a leg with no path, in metres: more than any route on any map.
NO_PATH_M = 1.0e6
#: Without the C extension of navseq.route.search: the share of the solver's time a first
#: route gets from 2-opt and Or-opt moves in numpy before OR-tools' guided local search
#: starts from it (its own first route plus the search did worse in the same second:
#: benchmarks/bench_route.py).
IMPROVE_SHARE = 0.6
#: Seconds of each slice of the iterated local search (navseq.route.search): the best
#: route so far is reported between slices, and a Ctrl-C heard.
SLICE_S = 0.1
#: Places at most for the numpy first route (each move weighs every pair of places).
IMPROVE_UP_TO = 500
#: Distances go to the solver in millimetres (it works in integers).
_MM = 1000.0
#: An order must be this much shorter than the file's to replace it.
_SHORTER_BY_M = 0.01

Place = tuple[float, float]
#: The length (m) a robot drives from one place to another, None when there is no path.
LegLength = Callable[[Place, Place], float | None]


@dataclass(frozen=True)
class Ordering:
    """The order found: ``order[k]`` is the index (in the file) of the k-th waypoint."""

    order: tuple[int, ...]

    @property
    def changed(self) -> bool:
        return self.order != tuple(range(len(self.order)))

    def apply(self, mission: Mission) -> Mission:
        """The mission with its waypoints in this order, everything else as it was."""
        return replace(mission, waypoints=tuple(mission.waypoints[i] for i in self.order))


def straight_line(a: Place, b: Place) -> float:
    return math.dist(a, b)


def distance_matrix(
    places: Sequence[Place], length: LegLength, *, workers: int | None = None
) -> np.ndarray:
    """Metres from every place to every other (``NO_PATH_M`` where there is no path).

    Each pair is measured once and used both ways: a path planned on a costmap is as
    long one way as the other, but for the grid's tie-breaking. The pairs are measured
    on ``workers`` threads (default: one per core): the compiled A* search lets go of
    the GIL, so plans run side by side.
    """
    from concurrent.futures import ThreadPoolExecutor

    count = len(places)
    pairs = [(i, j) for i in range(count) for j in range(i + 1, count)]
    matrix = np.zeros((count, count))
    with ThreadPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
        measured = pool.map(lambda pair: length(places[pair[0]], places[pair[1]]), pairs)
        for (i, j), metres in zip(pairs, measured, strict=True):
            matrix[i, j] = matrix[j, i] = NO_PATH_M if metres is None else metres
    return matrix


class OrderProgress(Protocol):
    """What shows a long ordering's progress (``navseq plan``'s bar)."""

    def searching(self, done: int, total: int) -> None:
        """``done`` of ``total`` searches for the distances are over."""

    def solving(self, best: float | None, limit_s: float) -> None:
        """The solver searches (for ``limit_s`` at most); ``best`` is the cost of the
        best order so far (None: none yet)."""


@runtime_checkable
class Distances(Protocol):
    """What measures every distance at once (a :class:`~navseq.route.legs.LegPlanner`:
    one search per place, not one plan per pair)."""

    def distances(self, places: Sequence[Place]) -> np.ndarray: ...


def distances_between(places: Sequence[Place], length: LegLength | Distances) -> np.ndarray:
    """Metres from every place to every other, ``NO_PATH_M`` where there is no path."""
    if isinstance(length, Distances):
        matrix = np.asarray(length.distances(places), dtype=float)
        return np.where(np.isfinite(matrix), matrix, NO_PATH_M)
    return distance_matrix(places, length)


def shortest_order(
    mission: Mission,
    length: LegLength | Distances = straight_line,
    time_limit_s: float = 2.0,
    *,
    keep_last: bool = False,
    robot: RobotProfile | None = None,
    progress: OrderProgress | None = None,
    settle_s: float | None = None,
) -> Ordering:
    """The order of ``mission``'s waypoints that drives the least (see the module doc).

    ``keep_last``: the file's last waypoint stays last (the robot ends at its dock).
    ``length`` measures a leg, or (a :class:`Distances`, such as a leg planner) all of
    them at once. ``robot``: order by the time that robot takes, turns included, where
    ``length`` measures routes with their headings (:class:`navseq.route.travel.Routes`);
    otherwise by metres. ``progress`` hears of the searches and the solver. ``settle_s``:
    the solver also stops once it found no better order for that long (see
    :func:`shortest_tour`).
    """
    require_extra("plan", "the shortest order")
    waypoints = [(w.x, w.y) for w in mission.waypoints]
    if len(waypoints) > MAX_WAYPOINTS:
        raise NavseqError(
            f"{len(waypoints)} waypoints: ordering measures the way between every two of "
            f"them and takes at most {MAX_WAYPOINTS}; order the mission in parts "
            "(navseq run --from/--to take parts of a file)",
            source=mission.source,
        )
    closed = mission.loops != 1
    start = None if closed else mission.start
    from_start = start is not None
    places = ([(start.x, start.y)] if start is not None else []) + waypoints
    fixed = (0 if from_start else 1) + (1 if keep_last else 0)
    if len(places) - fixed <= 1:
        return Ordering(tuple(range(len(waypoints))))  # nothing to choose
    matrix = _costs(mission, places, length, robot, progress)
    last = len(places) - 1 if keep_last else None
    shown = None if progress is None else (lambda best: progress.solving(best, time_limit_s))
    if shown is not None:
        shown(None)
    tour = shortest_tour(
        matrix,
        closed=closed,
        last=last,
        time_limit_s=time_limit_s,
        on_solution=shown,
        settle_s=settle_s,
    )
    as_in_file = list(range(len(places)))
    # An order no shorter than the file's (a patrol run the other way round, a tie) is
    # no reason to change what the user wrote.
    if tour_length(matrix, tour, closed) >= tour_length(matrix, as_in_file, closed) - _SHORTER_BY_M:
        tour = as_in_file
    shift = 1 if from_start else 0
    return Ordering(tuple(node - shift for node in tour if node >= shift))


def _costs(
    mission: Mission,
    places: Sequence[Place],
    length: LegLength | Distances,
    robot: RobotProfile | None,
    progress: OrderProgress | None,
) -> np.ndarray:
    """The solver's arc costs: seconds with turns when the robot is known and ``length``
    gives headings, metres otherwise."""
    from navseq.route.travel import Routes, travel_seconds

    searching = None if progress is None else progress.searching
    if robot is None or not isinstance(length, Routes):
        if searching is not None:
            searching(0, 1)
        matrix = distances_between(places, length)
        if searching is not None:
            searching(1, 1)
        return matrix
    from navseq.eta.drive import DriveModel

    model = DriveModel.of(robot)
    table = length.routes(places, model.lookahead, progress=searching)
    yaws: list[float | None] = [mission.start.yaw] if len(places) > len(mission.waypoints) else []
    for index, waypoint in enumerate(mission.waypoints):
        stops = mission.policy_for(index).pass_through_m is None
        yaws.append(waypoint.yaw_rad if stops or index == len(mission.waypoints) - 1 else None)
    seconds = travel_seconds(table, yaws, model)
    return np.where(np.isfinite(seconds), seconds, NO_PATH_M)


def _routing_model(costs: np.ndarray, end: int) -> tuple[Any, Any]:
    """OR-tools' model of one vehicle from node 0 to ``end`` over the arc ``costs``."""
    from ortools.constraint_solver import pywrapcp

    manager = pywrapcp.RoutingIndexManager(len(costs), 1, [0], [end])
    routing = pywrapcp.RoutingModel(manager)
    rows = costs.tolist()
    if hasattr(routing, "RegisterTransitMatrix"):
        # The costs handed over whole (OR-tools 9.9 on): the solver reads them in C++,
        # where a Python callback per arc made the first tour of 2000 places outlast 1 s.
        transit = routing.RegisterTransitMatrix(rows)
    else:
        # Plain lists and the index -> node table made once: the solver calls this for
        # every arc it considers (hundreds of thousands for 400 waypoints).
        node_of = [manager.IndexToNode(index) for index in range(routing.Size() + 1)]

        def arc_cost(from_index: int, to_index: int) -> int:
            return int(rows[node_of[from_index]][node_of[to_index]])

        transit = routing.RegisterTransitCallback(arc_cost)
    routing.SetArcCostEvaluatorOfAllVehicles(transit)
    return manager, routing


@contextlib.contextmanager
def _interruptible(routing: Any, on_solution: Callable[[float], None] | None) -> Iterator[None]:
    """The solve with each order found reported and Ctrl-C caught: the solver runs in C++,
    where Python's KeyboardInterrupt cannot reach it, and an exception raised in its
    callback would not unwind it cleanly. A SIGINT is noted instead, the search finished
    at the next order found, and KeyboardInterrupt raised once the solver returned."""
    interrupted = threading.Event()
    best = [math.inf]

    def found() -> None:
        if interrupted.is_set():
            routing.solver().FinishCurrentSearch()
            return
        cost = routing.CostVar().Value() / _MM
        if on_solution is not None and cost < best[0]:  # guided local search wanders
            best[0] = cost
            on_solution(cost)

    routing.AddAtSolutionCallback(found)
    main = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGINT) if main else None
    if main:
        signal.signal(signal.SIGINT, lambda *_: interrupted.set())
    try:
        yield
    finally:
        if main:
            signal.signal(signal.SIGINT, previous if previous is not None else signal.SIG_DFL)
    if interrupted.is_set():
        raise KeyboardInterrupt


def tour_length(matrix: np.ndarray, tour: Sequence[int], closed: bool) -> float:
    """Metres along ``tour`` (indices into ``matrix``), back to its first when ``closed``."""
    ends = [*tour[1:], tour[0]] if closed else tour[1:]
    return float(sum(matrix[a, b] for a, b in zip(tour, ends, strict=False)))


def _first_route(costs: np.ndarray, end: int, deadline: float) -> np.ndarray | None:
    """Without the C search: a first route from node 0 to ``end`` (0 again for a patrol)
    for OR-tools, improved by 2-opt and Or-opt (:mod:`navseq.route.improve`) until
    ``deadline``; None for more than :data:`IMPROVE_UP_TO` places (one move would take
    longer than the solver's whole search)."""
    from navseq.route.improve import improve, nearest_neighbour

    if not 4 <= len(costs) <= IMPROVE_UP_TO:
        return None
    arcs = costs.astype(float)
    return improve(nearest_neighbour(arcs, 0, end), arcs, deadline)


def _searched_tour(
    costs: np.ndarray,
    end: int,
    last: int | None,
    deadline: float,
    on_solution: Callable[[float], None] | None,
    settle_s: float | None,
) -> list[int]:
    """The route from node 0 to ``end`` found by :mod:`navseq.route.search` (nearest
    neighbour, then its iterated local search until ``deadline``), as
    :func:`shortest_tour` gives it. The search runs in slices of :data:`SLICE_S`, each
    from the best route so far: between them the best is reported, the settling time
    checked and a Ctrl-C raised; the first slice lasts until the local search from nearest
    neighbour is over (a fraction of a second on 2000 places)."""
    from navseq.route.improve import nearest_neighbour
    from navseq.route.search import search

    count = len(costs)
    arcs, final = costs, end
    if end == 0:
        # The search keeps a path's two ends in place: a patrol's way back to node 0
        # ends at a copy of it (the same costs in, none out).
        arcs = np.zeros((count + 1, count + 1), dtype=np.int64)
        arcs[:count, :count] = costs
        arcs[:count, count] = costs[:, 0]
        final = count
    route = nearest_neighbour(arcs.astype(float), 0, final).tolist()

    def cost_of(path: list[int]) -> int:
        return int(arcs[path[:-1], path[1:]].sum())

    best = cost_of(route)
    if on_solution is not None:
        on_solution(best / _MM)
    better_at = time.perf_counter()
    settled = False
    for seed in itertools.count():
        now = time.perf_counter()
        if now >= deadline or (settle_s is not None and now - better_at >= settle_s):
            break
        # The first descent (from nearest neighbour), with no kick after it, is not cut
        # into slices: each slice would begin it again over every node (on 2000 nodes,
        # longer than a slice).
        left_s = deadline - now
        if settled:
            found, done = search(arcs, route, min(left_s, SLICE_S), seed=seed, settled=True)
        else:
            found, done = search(arcs, route, left_s, kicks=0)
        length = cost_of(found)
        if length <= best:  # as short, elsewhere: the next slice starts from there
            route, settled = found, done
        if length < best:
            best, better_at = length, time.perf_counter()
            if on_solution is not None:
                on_solution(best / _MM)
    if end == 0:
        route[-1] = 0
    return route[:-1] if last is None else route


def shortest_tour(
    matrix: np.ndarray,
    *,
    closed: bool,
    last: int | None = None,
    time_limit_s: float = 2.0,
    on_solution: Callable[[float], None] | None = None,
    settle_s: float | None = None,
) -> list[int]:
    """The order of the places of ``matrix`` (metres from each to each) that drives the
    least: node 0 first, every node once, node ``last`` last if given, and back to node 0
    when ``closed`` (a fixed last node makes the way back a constant: the route ends there).
    ``on_solution`` hears the cost of each better order the solver finds. ``settle_s``:
    the search also ends once it found nothing better for that long (the iterated local
    search only; None: it runs for ``time_limit_s``). Ctrl-C in the main thread ends the
    search (within :data:`SLICE_S` of the iterated local search, or at OR-tools' next
    order found) and raises KeyboardInterrupt then."""
    from ortools.constraint_solver import pywrapcp, routing_enums_pb2

    from navseq.route.search import compiled as search_compiled

    count = len(matrix)
    if last is not None:
        end, nodes = last, count
    elif closed:
        end, nodes = 0, count
    else:
        # An open route ends at a node of its own that costs nothing to reach: the last
        # waypoint is then whichever suits the solver.
        end, nodes = count, count + 1
    began = time.perf_counter()
    costs = np.zeros((nodes, nodes), dtype=np.int64)
    costs[:count, :count] = np.rint(matrix * _MM).astype(np.int64)
    if nodes - (1 if end == 0 else 2) <= EXACT_UP_TO:
        route = exact_route(costs, end)
        if on_solution is not None:
            on_solution(tour_length(costs.astype(float), route, closed=False) / _MM)
        return route[:-1] if last is None else route
    if search_compiled():
        return _searched_tour(costs, end, last, began + time_limit_s, on_solution, settle_s)
    manager, routing = _routing_model(costs, end)
    parameters = pywrapcp.DefaultRoutingSearchParameters()
    parameters.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    parameters.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    first = _first_route(costs, end, began + IMPROVE_SHARE * time_limit_s)
    left_s = time_limit_s - (time.perf_counter() - began)
    parameters.time_limit.FromMilliseconds(max(1, round(left_s * 1000)))
    with _interruptible(routing, on_solution):
        initial = None
        if first is not None:
            routing.CloseModelWithParameters(parameters)
            route = [manager.NodeToIndex(int(node)) for node in first[1:-1]]
            initial = routing.ReadAssignmentFromRoutes([route], True)
        if initial is not None:
            solution = routing.SolveFromAssignmentWithParameters(initial, parameters)
        else:
            solution = routing.SolveWithParameters(parameters)
    if solution is None:
        # The first tour alone outlasted the limit (thousands of places, a loaded
        # machine: the studio gives the solver 1 s): it is taken however long it takes,
        # with no search after it, rather than no order at all.
        manager, routing = _routing_model(costs, end)
        parameters.ClearField("time_limit")
        parameters.solution_limit = 1
        solution = routing.SolveWithParameters(parameters)
    if solution is None:  # every node may come in any order: this is a solver failure
        raise NavseqError("the route solver found no order (OR-tools gave no solution)")
    tour = []
    index = routing.Start(0)
    while not routing.IsEnd(index):
        tour.append(manager.IndexToNode(index))
        index = solution.Value(routing.NextVar(index))
    if last is not None:
        tour.append(last)  # the end node is not among the visited ones
    return tour


__all__ = [
    "MAX_WAYPOINTS",
    "NO_PATH_M",
    "Distances",
    "OrderProgress",
    "Ordering",
    "distance_matrix",
    "distances_between",
    "shortest_order",
    "shortest_tour",
    "straight_line",
    "tour_length",
]
