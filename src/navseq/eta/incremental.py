"""A mission's expected duration worked out again after some waypoints moved.

The studio predicts the mission after every edit; a drag moves one waypoint of 5000.
:func:`~navseq.eta.predict.predict_legs` visits all 5000 each time (the planned ones
recalled from :class:`~navseq.eta.memo.RememberedDrives`, the paced ones made anew),
30–130 ms of every check. :class:`IncrementalPrediction` keeps, per visit, the state the
robot starts it in and the seconds it takes; after an edit only the visits whose inputs
changed are worked out again (the moved waypoints', and each one after whose start
moved), with the same arithmetic as :func:`~navseq.eta.predict.predict_mission`, and the
sums are taken again from the kept seconds (the same numpy sums as
:class:`~navseq.eta.predict.MissionPrediction`): the answer is the very one a full
prediction gives (tests compare them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from navseq.eta.predict import PLANNED_VISITS, TaskTime, paced_leg, time_of_tasks

if TYPE_CHECKING:
    from navseq.eta.memo import RememberedDrives
    from navseq.mission.model import Mission, Policy
    from navseq.route.legs import Legs

#: Planned paths kept by their ends' cells (a few visits' worth per edit).
PATHS_KEPT = 8192

#: Where a visit starts: the robot's place, heading (None: unknown) and speed.
State = tuple[tuple[float, float], float | None, float]

_DRIVE, _DWELL, _EXPECTED, _UPPER = range(4)


@dataclass
class _Loop:
    """One loop's visits: each one's start state, end state and seconds (columns
    drive, dwell, tasks expected, tasks at most), and for planned ones the driving and
    straight metres the pace of the paced ones comes from (NaN: no path)."""

    starts: list[State]
    ends: list[State]
    seconds: np.ndarray  # (visits, 4)
    planned_s: list[float]  # per planned visit: its driving (NaN: no path, not counted)
    planned_m: list[float]  # per planned visit: its straight metres
    straight_m: np.ndarray  # per paced visit (index - planned): straight metres

    def copy(self) -> _Loop:
        return _Loop(
            list(self.starts),
            list(self.ends),
            self.seconds.copy(),
            list(self.planned_s),
            list(self.planned_m),
            self.straight_m.copy(),
        )


class IncrementalPrediction:
    """:func:`~navseq.eta.predict.predict_legs` of a mission, kept so that the same
    mission with some waypoints moved (same count, loops, start pose and settings) is
    predicted from it (:meth:`after_edit`). Immutable once made: an edit gives a new one.
    """

    def __init__(
        self,
        mission: Mission,
        legs: Legs,
        drives: RememberedDrives,
        planned_visits: int = PLANNED_VISITS,
    ) -> None:
        self.mission = mission
        self.legs = legs
        self.drives = drives
        self.planned_visits = planned_visits
        self.loops: list[_Loop] = []
        self.visits_worked_out = 0  # visits driven or paced for this one, for tests
        self._paths: dict[tuple[Any, ...], list[tuple[float, float]] | None] = {}
        count = len(mission.waypoints)
        if count:
            self.loops.append(self._whole_loop(0, self._first_start()))
            if mission.loops is None or mission.loops > 1:
                self.loops.append(self._whole_loop(1, self.loops[0].ends[-1]))

    # -- what is predicted ----------------------------------------------------------------

    @property
    def expected_s(self) -> float | None:
        """The whole mission, expected (None: it loops forever)."""
        return self._total(self._parts("expected"))

    @property
    def upper_s(self) -> float | None:
        """The whole mission with every task taking its timeout (None: forever)."""
        return self._total(self._parts("upper"))

    @property
    def loop_expected_s(self) -> float:
        """One loop after the first (a patrol's period)."""
        parts = self._parts("expected")
        later = parts[-1] if parts else np.zeros(0)
        return float(np.cumsum(later)[-1]) if len(later) else 0

    def _parts(self, part: str) -> list[np.ndarray]:
        """Each loop's visits' seconds as :meth:`MissionPrediction._parts` adds them."""
        out = []
        for loop in self.loops:
            drive, dwell, expected, upper = loop.seconds.T
            out.append(
                drive + dwell + (np.maximum(upper, expected) if part == "upper" else expected)
            )
        return out

    def _total(self, parts: list[np.ndarray]) -> float | None:
        """:meth:`MissionPrediction._total`, from the same columns with the same sums."""
        loops = self.mission.loops
        if loops is None or not parts:
            return None if loops is None else 0.0

        def rest_after_first(each: np.ndarray) -> float:
            rest = np.cumsum(each[::-1])[::-1]
            return float(np.append(rest[1:], 0.0)[0])

        first, later = parts[0], parts[-1]
        whole = rest_after_first(later) + float(later[0])
        after = rest_after_first(first) + max(loops - 1, 0) * float(whole)
        return float(first[0]) + after

    # -- an edit ----------------------------------------------------------------------------

    def after_edit(self, mission: Mission, moved: set[int]) -> IncrementalPrediction:
        """The prediction of ``mission``: this one's mission with the waypoints ``moved``
        (indices) changed, nothing else. Only the visits whose inputs changed are worked
        out again."""
        edited = object.__new__(IncrementalPrediction)
        edited.mission = mission
        edited.legs = self.legs
        edited.drives = self.drives
        edited.planned_visits = self.planned_visits
        edited.visits_worked_out = 0
        edited._paths = self._paths  # a cache of a pure function: shared
        edited.loops = []
        if not self.loops:
            return edited
        start = edited._first_start()
        first = edited._loop_after_edit(0, self.loops[0], start, moved)
        edited.loops.append(first)
        if len(self.loops) > 1:
            edited.loops.append(edited._loop_after_edit(1, self.loops[1], first.ends[-1], moved))
        return edited

    def _loop_after_edit(self, loop: int, before: _Loop, start: State, moved: set[int]) -> _Loop:
        now = before.copy()
        count = len(self.mission.waypoints)
        planned = min(count, self.planned_visits)
        # Planned visits: each one whose start or waypoint changed is driven (recalled)
        # again; one whose neither did ends as before, and so does each after it up to
        # the next moved one.
        moved_planned = sorted(i for i in moved if i < planned)
        state, index = start, 0
        while index < planned:
            if index not in moved and state == now.starts[index]:
                index = next((i for i in moved_planned if i > index), planned)
                state = now.ends[index - 1]
                continue
            self._plan(now, loop, index, state)
            state = now.ends[index]
            index += 1
        # Paced visits: their pace (the planned ones' seconds per metre, this loop's and
        # the first loop's) and each one's straight metres from the one before.
        pace = self._pace(loop, now)
        touched = {i for i in moved if i >= planned} | {i + 1 for i in moved if i + 1 >= planned}
        if count > planned and state != now.starts[planned]:
            touched.add(planned)
        for index in sorted(i for i in touched if planned <= i < count):
            where = now.ends[index - 1][0] if index > planned else state[0]
            if index == planned:
                now.starts[index] = state
            else:
                now.starts[index] = now.ends[index - 1]
            self._pace_visit(now, index, where, pace, planned)
        if count > planned:
            now.seconds[planned:, _DRIVE] = now.straight_m * pace
        return now

    # -- one visit ----------------------------------------------------------------------------

    def _first_start(self) -> State:
        start = self.mission.start
        if start is not None:
            return ((start.x, start.y), start.yaw, 0.0)
        first = self.mission.waypoints[0]
        return ((first.x, first.y), None, 0.0)

    def _whole_loop(self, loop: int, start: State) -> _Loop:
        count = len(self.mission.waypoints)
        planned = min(count, self.planned_visits)
        empty: State = ((math.nan, math.nan), None, math.nan)
        now = _Loop(
            [empty] * count,
            [empty] * count,
            np.zeros((count, 4)),
            [math.nan] * planned,
            [0.0] * planned,
            np.zeros(count - planned),
        )
        state = start
        for index in range(planned):
            self._plan(now, loop, index, state)
            state = now.ends[index]
        pace = self._pace(loop, now)
        for index in range(planned, count):
            now.starts[index] = state
            self._pace_visit(now, index, state[0], pace, planned)
            state = now.ends[index]
        if count > planned:
            now.seconds[planned:, _DRIVE] = now.straight_m * pace
        return now

    def _plan(self, now: _Loop, loop: int, index: int, state: State) -> None:
        """Visit ``index`` planned and driven on paper from ``state``, as
        :func:`~navseq.eta.predict.predict_mission` drives it."""
        from navseq.executor.visit import Visit

        self.visits_worked_out += 1
        (where, heading, speed) = state
        visit = Visit.of(self.mission, loop, index)
        waypoint = visit.waypoint
        goal = (waypoint.x, waypoint.y)
        now.starts[index] = state
        now.planned_m[index] = math.dist(where, goal)
        points = self._path(where, goal)
        if points is None:
            now.planned_s[index] = math.nan
            now.ends[index] = (goal, waypoint.yaw_rad, 0.0)
            drive_s = 0.0
        else:
            path = [where, *points[1:-1], goal] if len(points) > 2 else [where, goal]
            driven = self.drives(
                path,
                self.drives.model,
                start_heading=heading,
                start_speed=speed,
                goal_yaw=waypoint.yaw_rad,
                pass_radius=visit.policy.pass_through_m if visit.passes_through else None,
                goal=goal,
                speed_cap=self.drives.speed_cap,
            )
            now.planned_s[index] = driven.duration_s
            now.ends[index] = (driven.end_point, driven.end_heading, driven.end_speed)
            drive_s = driven.duration_s
        self._tasks(now, index, visit.policy, drive_s)

    def _path(
        self, where: tuple[float, float], goal: tuple[float, float]
    ) -> list[tuple[float, float]] | None:
        """``legs.leg(where, goal).points``. A :class:`~navseq.route.legs.LegPlanner`'s
        plan depends only on the cells of its ends (the search snaps them to their
        cells): the visits after a moved waypoint start a hair from where they did, in
        the same cell, and their plans are the ones made before instead of new searches."""
        from navseq.route.legs import LegPlanner

        if type(self.legs) is not LegPlanner:
            return self.legs.leg(where, goal).points
        grid = self.legs.costmap.grid
        key = (grid.world_to_cell(*where), grid.world_to_cell(*goal))  # one planner's
        if key not in self._paths:
            if len(self._paths) >= PATHS_KEPT:
                self._paths.clear()
            self._paths[key] = self.legs.leg(where, goal).points
        return self._paths[key]

    def _pace_visit(
        self, now: _Loop, index: int, where: tuple[float, float], pace: float, planned: int
    ) -> None:
        """Visit ``index`` paced: its straight metres from ``where`` (the seconds are
        these metres at the pace, set for all paced visits at once by the caller)."""
        self.visits_worked_out += 1
        waypoint = self.mission.waypoints[index]
        goal = (waypoint.x, waypoint.y)
        straight = math.dist(where, goal)
        now.straight_m[index - planned] = straight
        # paced_leg's end: the goal, stopped, facing the waypoint's yaw.
        leg = paced_leg(goal, straight, straight * pace, waypoint.yaw_rad)
        now.ends[index] = (leg.end_point, leg.end_heading, leg.end_speed)
        self._tasks(now, index, self.mission.policy_for(index), straight * pace)

    def _pace(self, loop: int, now: _Loop) -> float:
        """Seconds per straight metre of the planned visits so far (this loop's and the
        ones before), added up in the order predict_mission adds them."""
        seconds, metres = 0.0, 0.0
        loops = [*self.loops[:loop], now] if loop else [now]
        for each in loops:
            for driven_s, straight in zip(each.planned_s, each.planned_m, strict=True):
                if not math.isnan(driven_s):
                    seconds += driven_s
                    metres += straight
        return seconds / metres if metres > 0 else 1 / self.drives.model.max_speed

    @staticmethod
    def _tasks(now: _Loop, index: int, policy: Policy, drive_s: float) -> None:
        times = time_of_tasks(policy.tasks) if policy.tasks else TaskTime()
        now.seconds[index] = (drive_s, policy.dwell_s, times.expected_s, times.upper_s)


__all__ = ["IncrementalPrediction"]
