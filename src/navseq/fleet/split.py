"""The waypoints of a mission split among a fleet's robots: the last one done soonest.

A vehicle routing problem for OR-tools' routing solver: each robot starts at its start
pose and ends wherever its last waypoint is; a leg takes the robot the planned
distance (on the costmap of its own footprint) divided by its top speed; the objective
is the time the last robot finishes (a global span cost on time), with the total time
as a tie-breaker so that no robot drives further than it must. Constraints: a
waypoint goes only to the robots the fleet file allows (and that can reach it), and a
robot's ``max_time`` bounds its share. A waypoint no robot can take within those
bounds is left out, and said so, rather than failing the whole split.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from navseq.errors import NavseqError
from navseq.extras import require_extra
from navseq.fleet.checks import FleetDistances
from navseq.fleet.model import Fleet, FleetRobot
from navseq.mission.model import Mission

#: The solver works in integers: times in tenths of a second.
_TICKS_PER_S = 10
#: The cost of leaving a waypoint out: more than any fleet's time.
_DROP_PENALTY = 10**12
#: The makespan's weight against the total time (the tie-breaker).
_SPAN_WEIGHT = 100


@dataclass(frozen=True)
class Share:
    """One robot's part: its waypoints (indices into the fleet's mission) in order."""

    robot: FleetRobot
    order: tuple[int, ...]
    distance_m: float
    time_s: float

    def mission(self, fleet: Fleet) -> Mission | None:
        """The robot's own mission (None: it has no waypoint): the shared mission's
        waypoints in this order, from the robot's start, with its robot profile."""
        if not self.order:
            return None
        shared = fleet.mission
        return replace(
            shared,
            waypoints=tuple(shared.waypoints[i] for i in self.order),
            start=self.robot.start,
            robot=self.robot.profile,
            map=fleet.map,
            loops=1,
            numbers=None,
        )


@dataclass(frozen=True)
class Split:
    """The fleet's plan: one share per robot (fleet order), and the waypoints left out."""

    shares: tuple[Share, ...]
    dropped: tuple[int, ...]

    @property
    def makespan_s(self) -> float:
        return max((share.time_s for share in self.shares), default=0.0)


def split_waypoints(fleet: Fleet, distances: FleetDistances, time_limit_s: float = 2.0) -> Split:
    """The split of ``fleet``'s waypoints that lets the last robot finish soonest.

    Half the time goes to one robot's tour of every waypoint, cut into one stretch per
    robot (:func:`tour_split`: a good, balanced split at once, where the routing
    solver's own first split fills one robot after another); the solver then improves
    on it for the other half. The better of the two (by makespan) is the answer.
    """
    require_extra("plan", "splitting a mission among robots")
    robots = fleet.robots
    count_w = len(fleet.mission.waypoints)
    takers = [
        [
            k
            for k, robot in enumerate(robots)
            if fleet.may_take(robot.name, index) and distances.reachable(k, index)
        ]
        for index in range(count_w)
    ]
    seed = tour_split(fleet, distances, takers, time_limit_s / 2)
    routes = _route(fleet, distances, takers, seed, time_limit_s / (2 if seed else 1))
    found = _split_of(fleet, distances, routes)
    if seed is not None:
        seeded = _split_of(fleet, distances, seed)
        if seeded.makespan_s < found.makespan_s - 1e-9:
            return seeded
    return found


def _split_of(fleet: Fleet, distances: FleetDistances, routes: list[list[int]]) -> Split:
    shares = []
    for k, (robot, order) in enumerate(zip(fleet.robots, routes, strict=True)):
        metres = _route_metres(distances.by_robot[k], k, [len(fleet.robots) + i for i in order])
        shares.append(Share(robot, tuple(order), metres, metres / robot.profile.max_linear_speed))
    taken = {index for order in routes for index in order}
    dropped = tuple(i for i in range(len(fleet.mission.waypoints)) if i not in taken)
    return Split(tuple(shares), dropped)


def tour_split(
    fleet: Fleet,
    distances: FleetDistances,
    takers: list[list[int]],
    time_limit_s: float,
) -> list[list[int]] | None:
    """One closed tour of every waypoint (the first robot's distances), cut into
    consecutive stretches, one per robot, so that the longest takes least: for each of
    a few places to cut the cycle open, the smallest time bound that robots (each
    driving from its start to its stretch) cover the tour with (bisection, greedy
    cover). None where it does not apply: waypoints some robot may not take, or a
    robot's ``max_time``."""
    from navseq.route.order import shortest_tour

    robots = fleet.robots
    count_r, count_w = len(robots), len(takers)
    everyone = list(range(count_r))
    if count_w < 2 or any(t != everyone for t in takers):
        return None
    if any(robot.max_time_s is not None for robot in robots):
        return None
    nodes = [count_r + i for i in range(count_w)]
    among = distances.by_robot[0][np.ix_(nodes, nodes)]
    tour = shortest_tour(
        np.where(np.isfinite(among), among, 1.0e6),
        closed=True,
        time_limit_s=max(0.05, time_limit_s),
    )
    seconds = [
        np.where(np.isfinite(m), m, 1.0e6) / robot.profile.max_linear_speed
        for m, robot in zip(distances.by_robot, robots, strict=True)
    ]
    best: tuple[float, list[list[int]]] | None = None
    cuts = sorted(
        {round(c * count_w / min(count_w, 40)) % count_w for c in range(min(count_w, 40))}
    )
    for cut in cuts:
        order = [tour[(cut + j) % count_w] for j in range(count_w)]
        low, high = 0.0, max(_stretch_time(seconds[k], k, count_r, order) for k in range(count_r))
        routes = _cover(seconds, count_r, order, high)
        assert routes is not None
        for _ in range(30):
            middle = (low + high) / 2
            covered = _cover(seconds, count_r, order, middle)
            if covered is None:
                low = middle
            else:
                high, routes = middle, covered
        if best is None or high < best[0]:
            best = (high, routes)
    assert best is not None
    return best[1]


def _stretch_time(seconds: np.ndarray, k: int, count_r: int, stretch: list[int]) -> float:
    """Robot ``k``'s time from its start along ``stretch`` (waypoint indices)."""
    total, here = 0.0, k
    for index in stretch:
        total += float(seconds[here, count_r + index])
        here = count_r + index
    return total


def _cover(
    seconds: list[np.ndarray], count_r: int, order: list[int], bound: float
) -> list[list[int]] | None:
    """Consecutive stretches of ``order``, each driven by a robot within ``bound``: at
    each step the free robot that gets furthest takes the next stretch. None if the
    robots run out before the tour does."""
    routes: list[list[int]] = [[] for _ in range(count_r)]
    free, position = set(range(count_r)), 0
    while position < len(order):
        reach = {}
        for k in free:
            total, here, end = 0.0, k, position
            while end < len(order):
                step = float(seconds[k][here, count_r + order[end]])
                if total + step > bound:
                    break
                total, here, end = total + step, count_r + order[end], end + 1
            reach[k] = end
        k = max(sorted(free), key=lambda robot: reach[robot])
        if reach[k] == position:
            return None
        routes[k] = order[position : reach[k]]
        free.discard(k)
        position = reach[k]
        if not free and position < len(order):
            return None
    return routes


def _route(
    fleet: Fleet,
    distances: FleetDistances,
    takers: list[list[int]],
    seed: list[list[int]] | None,
    time_limit_s: float,
) -> list[list[int]]:
    """The routing solver's routes (waypoint indices per robot), from ``seed`` if given."""
    from ortools.constraint_solver import pywrapcp, routing_enums_pb2

    robots = fleet.robots
    count_r, count_w = len(robots), len(fleet.mission.waypoints)
    end = count_r + count_w  # one end node, reached at no cost: routes are open
    nodes = end + 1
    manager = pywrapcp.RoutingIndexManager(nodes, count_r, list(range(count_r)), [end] * count_r)
    routing = pywrapcp.RoutingModel(manager)
    node_of = [manager.IndexToNode(index) for index in range(routing.Size() + count_r)]
    evaluators = []
    for k, robot in enumerate(robots):
        ticks = _time_ticks(distances.by_robot[k], robot.profile.max_linear_speed, nodes)

        def transit(from_index: int, to_index: int, rows: list[list[int]] = ticks) -> int:
            return rows[node_of[from_index]][node_of[to_index]]

        evaluators.append(routing.RegisterTransitCallback(transit))
        routing.SetArcCostEvaluatorOfVehicle(evaluators[-1], k)
    horizon = [
        round(robot.max_time_s * _TICKS_PER_S) if robot.max_time_s is not None else 2**40
        for robot in robots
    ]
    routing.AddDimensionWithVehicleTransitAndCapacity(evaluators, 0, horizon, True, "time")
    routing.GetDimensionOrDie("time").SetGlobalSpanCostCoefficient(_SPAN_WEIGHT)
    for index in range(count_w):
        node_index = manager.NodeToIndex(count_r + index)
        routing.VehicleVar(node_index).SetValues([-1, *takers[index]])
        routing.AddDisjunction([node_index], _DROP_PENALTY)
    parameters = pywrapcp.DefaultRoutingSearchParameters()
    parameters.first_solution_strategy = (
        routing_enums_pb2.FirstSolutionStrategy.PARALLEL_CHEAPEST_INSERTION
    )
    parameters.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    parameters.time_limit.FromMilliseconds(max(1, round(time_limit_s * 1000)))
    solution = None
    if seed is not None:
        routing.CloseModelWithParameters(parameters)
        start = routing.ReadAssignmentFromRoutes(
            [[manager.NodeToIndex(count_r + i) for i in order] for order in seed], True
        )
        if start is not None:
            solution = routing.SolveFromAssignmentWithParameters(start, parameters)
    if solution is None:
        solution = routing.SolveWithParameters(parameters)
    if solution is None:
        raise NavseqError("the route solver found no split (OR-tools gave no solution)")
    routes = []
    for k in range(count_r):
        order = []
        index = solution.Value(routing.NextVar(routing.Start(k)))
        while not routing.IsEnd(index):
            order.append(node_of[index] - count_r)
            index = solution.Value(routing.NextVar(index))
        routes.append(order)
    return routes


def _time_ticks(metres: np.ndarray, speed: float, nodes: int) -> list[list[int]]:
    """Tenths of a second from node to node at ``speed``; the end node costs nothing."""
    count = len(metres)
    finite = np.where(np.isfinite(metres), metres, 1.0e6)
    ticks = np.zeros((nodes, nodes), dtype=np.int64)
    ticks[:count, :count] = np.rint(finite / speed * _TICKS_PER_S).astype(np.int64)
    return ticks.tolist()


def _route_metres(metres: np.ndarray, start: int, nodes: list[int]) -> float:
    total, here = 0.0, start
    for node in nodes:
        leg = float(metres[here, node])
        total += leg if math.isfinite(leg) else 0.0
        here = node
    return round(total, 3)


__all__ = ["Share", "Split", "split_waypoints", "tour_split"]
