"""A mission's expected duration and its upper bound, before the robot moves.

Each visit of the mission (every waypoint of every loop, in the order the executor
takes them) is one leg planned on the map with the planner the simulator drives with
(:mod:`navseq.route.legs`; straight lines without a map), driven by
:func:`navseq.eta.drive.drive_path` with the robot's limits, plus the waypoint's dwell
and its tasks' time.

- A pass-through waypoint's leg ends where the robot comes within the radius, at
  speed; the next leg is planned from there, as the executor sends the next goal there.
- Loops are counted (a patrol that loops forever has no end: its figures are per loop);
  retries are not: they are failures, not the plan.
- **Expected**: driving + dwell + each task's expected time.
- **Upper bound**: driving + dwell + each task's timeout (a task cannot take longer). It
  bounds what the mission asks the robot to wait for, not what can go wrong on the way:
  a goal timeout is no bound on a leg that goes well, and retries, recovery behaviours
  or a blocked door have no bound the mission states.

Tasks at waypoints count by :func:`time_of_tasks` (or a :data:`TaskTimes` given).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np

from navseq.eta.drive import DriveModel, DrivenPath, Point, SpeedCap, drive_path

#: What drives a leg on paper: :func:`drive_path`, or one that recalls legs driven before
#: (:class:`navseq.eta.memo.RememberedDrives`).
Drive = Callable[..., DrivenPath]

if TYPE_CHECKING:
    from navseq.eta.memo import RememberedDrives
    from navseq.geometry import Pose2D
    from navseq.mission.model import Mission, Waypoint
    from navseq.mission.robot import RobotProfile
    from navseq.mission.tasks import Task
    from navseq.route.legs import Legs
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid


@dataclass(frozen=True)
class TaskTime:
    """Seconds the tasks at one waypoint take: expected, and at most (their timeouts)."""

    expected_s: float = 0.0
    upper_s: float = 0.0


#: The tasks' time at a waypoint, given its index in the mission and the waypoint.
TaskTimes = Callable[[int, "Waypoint"], TaskTime]


def no_tasks(index: int, waypoint: Waypoint) -> TaskTime:
    """A mission without tasks at its waypoints."""
    return TaskTime()


def time_of_tasks(tasks: Iterable[Task]) -> TaskTime:
    """The mission's own tasks at a waypoint: a ``wait`` is expected to take its seconds,
    any other task nothing beyond its start (no figure says more); at most, each takes
    its timeout (a ``wait`` its seconds). A task without timeout that can wait for ever
    (``input``, ``wait_for`` ...) makes the upper bound infinite."""
    from navseq.mission.tasks import WaitTask

    expected = upper = 0.0
    for task in tasks:
        if isinstance(task, WaitTask):
            expected += task.seconds
            limit = task.seconds if task.timeout_s is None else min(task.seconds, task.timeout_s)
            upper += limit
        else:
            upper += math.inf if task.timeout_s is None else task.timeout_s
    return TaskTime(expected, upper)


@dataclass(frozen=True)
class VisitPrediction:
    """One visit: its leg driven (None: no path to it), dwell and tasks."""

    loop: int
    index: int
    leg: DrivenPath | None
    dwell_s: float
    tasks: TaskTime

    @property
    def drive_s(self) -> float:
        return self.leg.duration_s if self.leg is not None else 0.0

    @property
    def expected_s(self) -> float:
        return self.drive_s + self.dwell_s + self.tasks.expected_s

    @property
    def upper_s(self) -> float:
        return self.drive_s + self.dwell_s + max(self.tasks.upper_s, self.tasks.expected_s)


@dataclass(frozen=True)
class MissionPrediction:
    """The visits of the first loop and of any later one (all later loops are alike).

    ``loops`` is the mission's (None: forever). ``planned`` is False when some leg has
    no path: the figures then leave those legs out.
    """

    first_loop: tuple[VisitPrediction, ...]
    later_loop: tuple[VisitPrediction, ...]
    loops: int | None
    paced: int = 0  # visits of each loop paced, not planned (a huge mission)
    _rests: dict[tuple[bool, str], np.ndarray] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    @property
    def planned(self) -> bool:
        return all(v.leg is not None for v in (*self.first_loop, *self.later_loop))

    def visit(self, loop: int, index: int) -> VisitPrediction:
        visits = self.first_loop if loop == 0 else self.later_loop
        return visits[index]

    def after(self, loop: int, index: int, part: Part = "expected") -> float | None:
        """Seconds of the visits after ``(loop, index)`` to the mission's end (None:
        forever): their expected time, upper bound or driving alone (``part``)."""
        if self.loops is None:
            return None
        rest = self._rest_after(loop == 0, part)[index]
        whole = self._rest_after(False, part)[0] + _part_of(self.later_loop[0], part)
        return float(rest) + max(self.loops - loop - 1, 0) * float(whole)

    @property
    def expected_s(self) -> float | None:
        """The whole mission, expected (None: it loops forever)."""
        return self._total("expected")

    @property
    def upper_s(self) -> float | None:
        """The whole mission with every task taking its timeout (None: forever)."""
        return self._total("upper")

    @property
    def loop_expected_s(self) -> float:
        """One loop after the first (a patrol's period)."""
        return sum(v.expected_s for v in self.later_loop)

    def _total(self, part: Part) -> float | None:
        if self.loops is None or not self.first_loop:
            return None if self.loops is None else 0.0
        first = _part_of(self.first_loop[0], part)
        return first + (self.after(0, 0, part) or 0.0)

    def _rest_after(self, first: bool, part: Part) -> np.ndarray:
        """For each visit of a loop, the seconds of the visits after it in that loop
        (worked out once: a progress event asks often, and a mission may have 100 000
        visits)."""
        key = (first, part)
        if key not in self._rests:
            each = self._parts(first, part)
            rest = np.cumsum(each[::-1])[::-1]
            self._rests[key] = np.append(rest[1:], 0.0)
        return self._rests[key]

    def _parts(self, first: bool, part: Part) -> np.ndarray:
        """:func:`_part_of` each visit of a loop, added up as it does (the same floats),
        from columns read once: a check in the studio asks for all three parts of 5000."""
        key = (first, "columns")
        if key not in self._rests:
            visits = self.first_loop if first else self.later_loop
            self._rests[key] = np.array(
                [(v.drive_s, v.dwell_s, v.tasks.expected_s, v.tasks.upper_s) for v in visits],
                dtype=float,
            ).reshape(-1, 4)
        drive, dwell, expected, upper = self._rests[key].T
        if part == "drive":
            return drive
        if part == "upper":
            return drive + dwell + np.maximum(upper, expected)
        return drive + dwell + expected


#: Which seconds of a visit :meth:`MissionPrediction.after` adds up.
Part = Literal["expected", "upper", "drive"]


def _part_of(visit: VisitPrediction, part: Part) -> float:
    if part == "drive":
        return visit.drive_s
    return visit.upper_s if part == "upper" else visit.expected_s


#: Visits planned and driven on paper before the robot moves; a mission with more has
#: the rest paced (see :func:`predict_mission`): planning 100 000 legs would hold the
#: robot for minutes.
PLANNED_VISITS = 500


def predict_mission(
    mission: Mission,
    legs: Legs,
    model: DriveModel,
    start: Pose2D | None,
    *,
    speed_cap: SpeedCap | None = None,
    task_times: TaskTimes | None = None,
    planned_visits: int = PLANNED_VISITS,
    drive: Drive = drive_path,
) -> MissionPrediction:
    """The mission's visits predicted; ``start`` None: the first leg starts at the first
    waypoint (nothing to drive), as nothing says where the robot is.

    The first ``planned_visits`` visits of a loop are planned and driven; each later one
    is paced: its straight-line distance at the seconds per metre of the planned ones.
    """
    from navseq.executor.visit import Visit

    count = len(mission.waypoints)
    loops = mission.loops
    if start is not None:
        where: tuple[float, float] = (start.x, start.y)
        heading: float | None = start.yaw
    elif count:
        where, heading = (mission.waypoints[0].x, mission.waypoints[0].y), None
    speed = 0.0
    planned = 0
    paced_seconds, paced_metres = 0.0, 0.0  # the planned visits' driving and distance

    def driven_leg(visit: Visit, goal: tuple[float, float]) -> DrivenPath | None:
        nonlocal planned, paced_seconds, paced_metres
        straight = math.dist(where, goal)
        if planned >= planned_visits:
            pace = paced_seconds / paced_metres if paced_metres > 0 else 1 / model.max_speed
            return paced_leg(goal, straight, straight * pace, visit.waypoint.yaw_rad)
        planned += 1
        points = legs.leg(where, goal).points
        if points is None:
            return None
        path = [where, *points[1:-1], goal] if len(points) > 2 else [where, goal]
        driven = drive(
            path,
            model,
            start_heading=heading,
            start_speed=speed,
            goal_yaw=visit.waypoint.yaw_rad,
            pass_radius=visit.policy.pass_through_m if visit.passes_through else None,
            goal=goal,
            speed_cap=speed_cap,
        )
        paced_seconds += driven.duration_s
        paced_metres += straight
        return driven

    def loop_of(loop: int) -> tuple[VisitPrediction, ...]:
        nonlocal where, heading, speed, planned
        planned = 0  # the first visits of each loop are planned
        visits = []
        for index, waypoint in enumerate(mission.waypoints):
            visit = Visit.of(mission, loop, index)
            goal = (waypoint.x, waypoint.y)
            driven = driven_leg(visit, goal)
            if driven is not None:
                where, heading, speed = driven.end_point, driven.end_heading, driven.end_speed
            else:
                where, heading, speed = goal, waypoint.yaw_rad, 0.0
            tasks = (
                task_times(index, waypoint)
                if task_times is not None
                else time_of_tasks(visit.policy.tasks)
            )
            visits.append(VisitPrediction(loop, index, driven, visit.policy.dwell_s, tasks))
        return tuple(visits)

    first = loop_of(0) if count else ()
    later = loop_of(1) if count and (loops is None or loops > 1) else first
    return MissionPrediction(first, later, loops, paced=max(0, count - planned_visits))


def paced_leg(goal: Point, metres: float, seconds: float, yaw: float) -> DrivenPath:
    """A leg not planned: ``metres`` to ``goal`` in ``seconds``, evenly."""
    return DrivenPath(
        duration_s=seconds,
        length_m=metres,
        end_speed=0.0,
        end_heading=yaw,
        end_point=goal,
        remaining_m=np.array([metres, 0.0]),
        time_left_s=np.array([seconds, 0.0]),
    )


def costmap_speed_cap(costmap: Costmap, model: DriveModel) -> SpeedCap:
    """The controller's slowdown near obstacles, read from ``costmap`` at each point, and
    the speed zones' limits of its map's filters (:mod:`navseq.sim.filters`)."""
    from navseq.sim.controller import ControllerParams, speed_factors_by_cost

    factors = np.asarray(speed_factors_by_cost(ControllerParams(), costmap))
    grid = costmap.grid

    def cap(points: np.ndarray) -> np.ndarray:
        rows, cols = grid.world_to_cells(points[:, 0], points[:, 1])
        inside = (rows >= 0) & (rows < costmap.cost.shape[0]) & (cols >= 0)
        inside &= cols < costmap.cost.shape[1]
        costs = np.zeros(len(points), dtype=int)
        costs[inside] = costmap.cost[rows[inside], cols[inside]]
        speeds: np.ndarray = factors[costs] * model.max_speed
        zones = grid.filters
        if zones is not None and zones.speed_limit is not None:  # the speed zones' limits
            limits = np.full(len(points), np.nan, dtype=np.float32)
            limits[inside] = zones.speed_limit[rows[inside], cols[inside]]
            allowed = (
                np.fmin(limits, model.max_speed)
                if zones.speed_absolute
                else model.max_speed * limits / 100.0
            )
            speeds = np.fmin(speeds, allowed)  # fmin: NaN (no limit) leaves the speed
        return speeds

    return cap


def predict_on_map(
    mission: Mission,
    grid: OccupancyGrid | None,
    robot: RobotProfile,
    start: Pose2D | None,
    *,
    task_times: TaskTimes | None = None,
) -> MissionPrediction:
    """``mission`` predicted for ``robot`` on ``grid`` (legs planned on its costmap, the
    slowdown near obstacles read from it), or on straight lines when there is no map."""
    from navseq.route.legs import LegPlanner, StraightLegs

    model = DriveModel.of(robot)
    if grid is None:
        return predict_mission(mission, StraightLegs(), model, start, task_times=task_times)
    from navseq.sim.costmap import Costmap
    from navseq.sim.profile import costmap_params_of

    costmap = Costmap.from_grid(grid, costmap_params_of(robot))
    return predict_legs(mission, LegPlanner(costmap), robot, start, task_times=task_times)


def predict_legs(
    mission: Mission,
    legs: Legs,
    robot: RobotProfile,
    start: Pose2D | None,
    *,
    task_times: TaskTimes | None = None,
    drives: RememberedDrives | None = None,
) -> MissionPrediction:
    """``mission`` predicted on ``legs`` (a planner's costmap slows the robot near walls).

    ``drives``: legs driven before on these legs for this robot
    (:meth:`RememberedDrives.on`), recalled instead of driven again.
    """
    if drives is None:
        model = DriveModel.of(robot)
        costmap = getattr(legs, "costmap", None)
        cap = costmap_speed_cap(costmap, model) if costmap is not None else None
        return predict_mission(mission, legs, model, start, speed_cap=cap, task_times=task_times)
    return predict_mission(
        mission,
        legs,
        drives.model,
        start,
        speed_cap=drives.speed_cap,
        task_times=task_times,
        drive=drives,
    )


__all__ = [
    "PLANNED_VISITS",
    "MissionPrediction",
    "TaskTime",
    "TaskTimes",
    "VisitPrediction",
    "costmap_speed_cap",
    "no_tasks",
    "paced_leg",
    "predict_legs",
    "predict_mission",
    "predict_on_map",
]
