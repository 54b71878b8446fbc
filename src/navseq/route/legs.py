"""The legs of a mission on a map: each one planned on the robot's costmap, with its length.

A leg goes from the start pose (when the mission has one) to the first waypoint, then
from each waypoint to the next, and for a patrol from the last back to the first. Legs
are planned with :func:`navseq.sim.planner.plan_path`, the planner the simulator drives
with, and kept: dragging a waypoint in the studio plans only the two legs it touches.
"""

from __future__ import annotations

import itertools
import math
import os
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.route.travel import RouteTable
    from navseq.sim.costmap import Costmap


@dataclass(frozen=True)
class Leg:
    """The planned path from one place to the next (None: no path)."""

    start: tuple[float, float]
    goal: tuple[float, float]
    points: list[tuple[float, float]] | None
    length_m: float | None


class LegPlanner:
    """Plans legs on one costmap, keeping the last plans so that unchanged legs are free.

    Dragging one waypoint changes the two legs touching it; the others come from the
    cache (keyed by their exact end points). The capacity holds every leg of a mission
    of several thousand waypoints: a cache smaller than the mission's legs, walked in
    order at every check, drops each leg before it is asked for again (a 5000-waypoint
    mission then planned all its legs anew at each drag: 8 s instead of under one).
    """

    def __init__(self, costmap: Costmap, capacity: int = 16384) -> None:
        self.costmap = costmap
        self._cache: OrderedDict[tuple[float, float, float, float], Leg] = OrderedDict()
        self._capacity = capacity
        self._lock = threading.Lock()
        self.planned = 0  # plans computed (not taken from the cache), for benchmarks

    def leg(self, start: tuple[float, float], goal: tuple[float, float]) -> Leg:
        from navseq.sim.planner import plan_path

        key = (start[0], start[1], goal[0], goal[1])
        with self._lock:
            cached = self._cache.get(key)
            if cached is not None:
                self._cache.move_to_end(key)
                return cached
        plan = plan_path(self.costmap, start, goal)
        if plan is None:
            leg = Leg(start, goal, None, None)
        else:
            leg = Leg(start, goal, corners(plan.points), round(plan.length, 3))
        with self._lock:
            self.planned += 1
            self._cache[key] = leg
            while len(self._cache) > self._capacity:
                self._cache.popitem(last=False)
        return leg

    def plan_ahead(self, pairs: Sequence[tuple[tuple[float, float], tuple[float, float]]]) -> None:
        """Plan the legs of ``pairs`` (start, goal) not in the cache yet, on one thread per
        core (the compiled search lets go of the GIL): the first check of a mission of
        5000 waypoints on a 2000 x 2000 map plans 5000 legs."""
        from concurrent.futures import ThreadPoolExecutor

        with self._lock:
            missing = list(
                dict.fromkeys(
                    (start, goal)
                    for start, goal in pairs
                    if (start[0], start[1], goal[0], goal[1]) not in self._cache
                )
            )
        if len(missing) < 2:
            return
        pool = ThreadPoolExecutor(max_workers=os.cpu_count() or 1)
        try:
            for _ in pool.map(lambda pair: self.leg(*pair), missing):
                pass
        finally:  # on Ctrl-C, the plans not started are dropped, not waited for
            pool.shutdown(wait=True, cancel_futures=True)

    def distances(self, places: Sequence[tuple[float, float]]) -> np.ndarray:
        """Metres between every two of ``places`` as :meth:`leg` plans them (``inf``
        where there is no path): one search from each place that stops once it reached
        the places after it, on one thread per core (the compiled search lets go of the
        GIL). For ordering hundreds of waypoints, where a plan per pair took minutes.
        Pairs measured before on the same map for the same robot, by this planner or
        another, are not searched again (:mod:`navseq.route.distances`). On a big map,
        the coarse routes of :mod:`navseq.route.coarse` (lengths within a few per cent,
        the same pairs reachable)."""
        from navseq.route import coarse
        from navseq.route.distances import distance_table
        from navseq.sim.planner import compiled_search_available, reach_lengths

        if compiled_search_available() and coarse.worth_it(self.costmap, len(places)):
            return self.routes(places, 0.0).metres
        return distance_table(self.costmap, places, reach_lengths, workers=os.cpu_count() or 1)

    def prepare_ordering(self, places: int) -> None:
        """Make now what a first ordering of ``places`` places needs before its searches:
        on a big map, the coarse graph (a third of a second on a 2000 x 2000 map, kept
        per map and robot). The studio does it once the opened mission is checked, so
        that its first Order… does not wait for it."""
        from navseq.route import coarse
        from navseq.sim.planner import compiled_search_available

        if compiled_search_available() and coarse.worth_it(self.costmap, places):
            coarse.graph_for(self.costmap)

    def routes(
        self, places: Sequence[tuple[float, float]], anchor_m: float, *, progress: Any = None
    ) -> RouteTable:
        """:meth:`distances` with the headings each route leaves and arrives with, for
        ordering by time (:mod:`navseq.route.travel`); ``progress(done, total)`` after
        each search."""
        from navseq.route.travel import route_table

        return route_table(
            self.costmap, places, anchor_m, workers=os.cpu_count() or 1, progress=progress
        )


class StraightLegs:
    """Legs as straight lines, for a mission with no map to plan on."""

    def leg(self, start: tuple[float, float], goal: tuple[float, float]) -> Leg:
        return Leg(start, goal, [start, goal], round(math.dist(start, goal), 3))

    def plan_ahead(self, pairs: Sequence[tuple[tuple[float, float], tuple[float, float]]]) -> None:
        """Nothing to plan: a straight line is drawn when asked for."""

    def distances(self, places: Sequence[tuple[float, float]]) -> np.ndarray:
        """Metres between every two of ``places`` in straight lines."""
        points = np.asarray(places, dtype=float).reshape(-1, 2)
        return np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))

    def routes(
        self, places: Sequence[tuple[float, float]], anchor_m: float, *, progress: Any = None
    ) -> RouteTable:
        """Straight lines between every two of ``places``, with their directions."""
        from navseq.route.travel import straight_routes

        return straight_routes(places)


class Legs(Protocol):
    """What plans a leg: a :class:`LegPlanner` on a costmap, or :class:`StraightLegs`."""

    def leg(self, start: tuple[float, float], goal: tuple[float, float]) -> Leg: ...

    def plan_ahead(self, pairs: Sequence[tuple[tuple[float, float], tuple[float, float]]]) -> None:
        """Plan these legs now, side by side where it can (the next :meth:`leg` asks
        find them made)."""
        ...

    def distances(self, places: Sequence[tuple[float, float]]) -> np.ndarray:
        """Metres between every two of ``places`` (``inf``: no path)."""
        ...


def route_length(legs: list[dict[str, Any]]) -> float | None:
    """Metres once through the legs :func:`legs_of` gives, a patrol's way back to its
    first waypoint included (that leg changes with the order too); None if one has no path."""
    metres = [leg["length_m"] for leg in legs]
    return None if any(m is None for m in metres) else round(sum(metres), 3)


def lengths(legs: Legs) -> Callable[[tuple[float, float], tuple[float, float]], float | None]:
    """Metres from a place to another as ``legs`` plans them (None: no path)."""
    return lambda start, goal: legs.leg(start, goal).length_m


def corners(points: Any) -> list[tuple[float, float]]:
    """The plan's cells thinned to where its direction changes (what a line needs)."""
    array = np.asarray(points, dtype=float)
    if len(array) <= 2:
        return [(round(float(x), 3), round(float(y), 3)) for x, y in array]
    steps = np.diff(array, axis=0)
    turn = np.abs(steps[1:, 0] * steps[:-1, 1] - steps[1:, 1] * steps[:-1, 0]) > 1e-12
    keep = np.concatenate(([True], turn, [True]))
    return [(round(float(x), 3), round(float(y), 3)) for x, y in array[keep]]


def legs_of(mission: Mission, planner: Legs) -> list[dict[str, Any]]:
    """Each leg of ``mission`` as the page draws it: from the start pose (when there is
    one) through every waypoint, plus the way back to the first for a patrol."""
    places: list[tuple[str, tuple[float, float]]] = []
    if mission.start is not None:
        places.append(("start", (mission.start.x, mission.start.y)))
    for index, waypoint in enumerate(mission.waypoints):
        places.append((str(index), (waypoint.x, waypoint.y)))
    pairs = [(a, b, False) for a, b in itertools.pairwise(places)]
    if mission.loops != 1 and len(mission.waypoints) > 1:
        pairs.append((places[-1], places[-len(mission.waypoints)], True))  # back to the first
    planner.plan_ahead([(start, goal) for (_, start), (_, goal), _ in pairs])
    return [
        _drawn_leg(planner, from_name, start, int(to_name), goal, loop)
        for (from_name, start), (to_name, goal), loop in pairs
    ]


def legs_after_edit(
    before: list[dict[str, Any]], mission: Mission, planner: Legs, moved: set[int]
) -> list[dict[str, Any]]:
    """:func:`legs_of` ``mission``, given the legs of the same mission before the
    waypoints ``moved`` (indices) moved: only the legs that touch them are planned (or
    taken from the planner's cache) again. The mission must have the same waypoint count,
    start pose and loops as the one ``before`` was made of."""
    names = {str(index) for index in moved}
    legs = list(before)
    for position, leg in enumerate(before):
        if leg["to"] not in moved and leg["from"] not in names:
            continue
        source = leg["from"]
        if source == "start":
            assert mission.start is not None
            start = (mission.start.x, mission.start.y)
        else:
            waypoint = mission.waypoints[int(source)]
            start = (waypoint.x, waypoint.y)
        goal = mission.waypoints[leg["to"]]
        legs[position] = _drawn_leg(
            planner, source, start, leg["to"], (goal.x, goal.y), leg["loop"]
        )
    return legs


def _drawn_leg(
    planner: Legs,
    from_name: str,
    start: tuple[float, float],
    to: int,
    goal: tuple[float, float],
    loop: bool,
) -> dict[str, Any]:
    leg = planner.leg(start, goal)
    return {
        "from": from_name,
        "to": to,
        "points": leg.points,
        "length_m": leg.length_m,
        "loop": loop,
    }


def route_summary(legs: list[dict[str, Any]], robot: RobotProfile) -> dict[str, Any]:
    """Total length of the legs and the time they take at the robot's top speed."""
    from navseq.sinks.progress import eta_text

    lengths = [leg["length_m"] for leg in legs if not leg["loop"]]
    if any(length is None for length in lengths):
        return {"total_length_m": None, "estimated_duration": "", "unplanned_legs": True}
    total = float(sum(lengths))
    return {
        "total_length_m": round(total, 3),
        "estimated_duration": eta_text(total, robot),
        "unplanned_legs": False,
    }
