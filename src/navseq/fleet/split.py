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
    """The split of ``fleet``'s waypoints that lets the last robot finish soonest."""
    require_extra("plan", "splitting a mission among robots")
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
        takers = [
            k
            for k, robot in enumerate(robots)
            if fleet.may_take(robot.name, index) and distances.reachable(k, index)
        ]
        routing.VehicleVar(node_index).SetValues([-1, *takers])
        routing.AddDisjunction([node_index], _DROP_PENALTY)
    parameters = pywrapcp.DefaultRoutingSearchParameters()
    parameters.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    parameters.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    parameters.time_limit.FromMilliseconds(max(1, round(time_limit_s * 1000)))
    solution = routing.SolveWithParameters(parameters)
    if solution is None:
        raise NavseqError("the route solver found no split (OR-tools gave no solution)")
    shares = []
    taken: set[int] = set()
    for k, robot in enumerate(robots):
        order = []
        index = solution.Value(routing.NextVar(routing.Start(k)))
        while not routing.IsEnd(index):
            order.append(node_of[index] - count_r)
            index = solution.Value(routing.NextVar(index))
        taken.update(order)
        metres = _route_metres(distances.by_robot[k], k, [count_r + i for i in order])
        shares.append(Share(robot, tuple(order), metres, metres / robot.profile.max_linear_speed))
    dropped = tuple(i for i in range(count_w) if i not in taken)
    return Split(tuple(shares), dropped)


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


__all__ = ["Share", "Split", "split_waypoints"]
