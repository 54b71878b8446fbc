"""The ``sim`` navigator: navseq's embedded simulator behind the Navigator interface.

It drives a :class:`navseq.sim.world.SimWorld` in simulated time, as fast as the CPU
allows, or paced against the wall clock at a chosen factor (``realtime``: 1 to watch
it or to drive RViz in real time): :meth:`SimNavigator.spin` steps the world, and
``now()`` is the world's clock.
Events follow what an actionlib client of move_base would see:

- ``GoalAccepted`` as soon as a goal is sent;
- ``GoalPlan`` each time the navigation server adopts a new plan for it;
- ``GoalFeedback`` (pose, distance remaining along the plan) every ``feedback_period``
  seconds of simulated time while the goal is active;
- ``GoalHeld`` / ``GoalReleased`` while a fleet's right of way holds the robot back
  (it waits for a robot the rule deals with, or gives way to one; the goal's server
  stays ACTIVE);
- ``GoalDone`` succeeded (status SUCCEEDED) or failed (ABORTED), the server's verdict
  and its reason, or failed (PREEMPTED) for a goal that was cancelled or replaced by
  a newer one.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.geometry import Pose2D
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    GoalHeld,
    GoalPlan,
    GoalReleased,
    NavEvent,
    RecoveryDone,
)
from navseq.navigators.recovery_behaviors import behavior_request, start_on
from navseq.navigators.registry import NavigatorDraft, NavigatorSetup
from navseq.navigators.settings import SimNavigatorSettings
from navseq.sim.behaviors import BehaviorGoal, BehaviorServer
from navseq.sim.behaviors import Outcome as BehaviorOutcome
from navseq.sim.navserver import NavParams, NavState
from navseq.sim.occupancy import load_map
from navseq.sim.world import SimWorld, default_start
from navseq.track import Track

if TYPE_CHECKING:
    from navseq.mission.model import Mission
    from navseq.mission.recovery import Recovery
    from navseq.mission.robot import RobotProfile
    from navseq.sim.occupancy import OccupancyGrid

# The simulated server plays move_base, so its results carry actionlib's status names.
_SUCCEEDED, _ABORTED, _PREEMPTED = "SUCCEEDED", "ABORTED", "PREEMPTED"


class SimNavigator:
    """A :class:`navseq.navigators.base.Navigator` on an in-process simulated robot.

    ``trajectory`` records ``(t, x, y)`` of the robot at the start and whenever it
    has moved 5 mm (or a 0.05 s step passed), for reports and pictures; it is a
    :class:`~navseq.track.Track`, so it stays bounded on a patrol that runs for days.

    ``realtime`` (a factor > 0, or None for as fast as possible) paces simulated time
    against ``wall_clock``: after each step the navigator sleeps until the wall clock has
    caught up with simulated time / ``realtime`` since the first step. Pacing is against
    that first step, not per step, so rounding does not add up over a long run, and a
    slow step is caught up rather than lost.
    """

    def __init__(
        self,
        world: SimWorld,
        *,
        feedback_period: float = 0.2,
        realtime: float | None = None,
        wall_clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        if not feedback_period > 0:
            raise ValueError(f"feedback_period must be positive, got {feedback_period}")
        if realtime is not None and not (math.isfinite(realtime) and realtime > 0):
            raise ValueError(f"realtime must be a factor above 0, got {realtime}")
        self.world = world
        self.realtime = realtime
        self._wall_clock = wall_clock
        self._sleep = sleep
        self._pace_origin: tuple[float, float] | None = None  # (simulated, wall) time
        self.feedback_period = feedback_period
        pose = world.robot.pose
        self.trajectory = Track(min_step=0.005, min_interval=0.05)
        self.trajectory.append((world.time, pose.x, pose.y))
        self._events: list[NavEvent] = []
        self._active: Goal | None = None
        self._held = False  # GoalHeld told about the active goal, GoalReleased not yet
        self._plan_version = world.server.plan_version
        self._next_feedback = math.inf
        self._unspun = 0.0  # simulated seconds asked for but shorter than a step
        # A retry's recoveries run on Nav2's behaviours, on the simulated robot.
        self._behaviors = BehaviorServer()
        self._recovery: tuple[int, BehaviorGoal] | None = None

    @classmethod
    def from_map(
        cls,
        map_yaml: str | Path,
        start: Pose2D | None = None,
        *,
        nav_params: NavParams | None = None,
        feedback_period: float = 0.2,
    ) -> SimNavigator:
        """A navigator on a map_server map; ``start=None`` uses :func:`default_start`.

        Raises ``NavseqError`` for an unreadable map or a start pose in an obstacle.
        """
        grid = load_map(map_yaml)
        if start is None:
            start = default_start(grid)
        world = SimWorld(grid, start, nav_params=nav_params)
        return cls(world, feedback_period=feedback_period)

    # -- Navigator protocol ----------------------------------------------------------

    def now(self) -> float:
        return self.world.time

    def wait_for_server(self, timeout: float) -> bool:
        return True  # the server lives in this process

    def send_goal(self, goal: Goal) -> None:
        if self._active is not None:
            self._events.append(
                GoalDone.failed(self._active.goal_id, _PREEMPTED, "replaced by a new goal")
            )
        self._active = goal
        self._held = False  # a goal still held is told so at the next step
        self.world.server.set_goal(goal.pose)
        self._events.append(GoalAccepted(goal.goal_id))
        self._next_feedback = self.world.time + self.feedback_period

    def cancel_goal(self) -> None:
        if self._active is None:
            return
        self.world.server.cancel()
        self._events.append(GoalDone.failed(self._active.goal_id, _PREEMPTED, "canceled"))
        self._active = None

    def clear_costmaps(self) -> None:
        self.world.server.clear_costmaps()

    def run_recovery(self, recovery_id: int, recovery: Recovery) -> None:
        """Spin, back up or wait on the simulated robot with Nav2's behaviours (collision
        checked ahead as Nav2's are); clear_costmaps clears the simulated server's."""
        self.cancel_recovery()
        request = behavior_request(recovery)
        if request is None:
            self.world.server.clear_costmaps()
            self._events.append(RecoveryDone(recovery_id, True))
            return
        goal = start_on(self._behaviors, request, self.world.time)
        self._recovery = (recovery_id, goal)
        self._settle_recovery()  # a goal refused at once (invalid input) ends here

    def cancel_recovery(self) -> None:
        if self._recovery is None:
            return
        self._behaviors.cancel(self._recovery[1], self.world.time)
        self._recovery = None
        self.world.body.command(0.0, 0.0)  # the robot brakes

    def robot_pose(self) -> Pose2D | None:
        return self.world.robot.pose

    def odometry_pose(self) -> Pose2D | None:
        return self.world.body.odom_pose

    def poll(self) -> list[NavEvent]:
        events, self._events = self._events, []
        return events

    def spin(self, seconds: float) -> None:
        world = self.world
        self._unspun += seconds
        steps = math.floor(self._unspun / world.dt + 1e-9)
        self._unspun -= steps * world.dt
        robot = world.robot
        trajectory = self.trajectory
        behaviors = self._behaviors
        for _ in range(steps):
            before = robot.pose
            if behaviors.running:
                body = world.body
                world.step_commanded(*behaviors.step(world.time, body.pose, body.collides))
                self._settle_recovery()
            else:
                world.step()
            if robot.pose is not before:
                trajectory.append((world.time, robot.pose.x, robot.pose.y))
            if self._active is not None:
                self._report(self._active)
            if self.realtime is not None:
                self._pace()

    def close(self) -> None:
        self.cancel_goal()

    # -- internals ---------------------------------------------------------------------

    def _settle_recovery(self) -> None:
        """Report the running recovery's end, once its behaviour ended."""
        if self._recovery is None:
            return
        recovery_id, goal = self._recovery
        ending = goal.ending
        if ending is None:
            return
        self._recovery = None
        succeeded = ending.outcome is BehaviorOutcome.SUCCEEDED
        detail = "" if succeeded else (ending.error or ending.log or ending.outcome.value)
        self._events.append(RecoveryDone(recovery_id, succeeded, detail))

    def _pace(self) -> None:
        """Sleep until the wall clock is where simulated time says it should be."""
        assert self.realtime is not None
        now = self._wall_clock()
        if self._pace_origin is None:
            self._pace_origin = (self.world.time, now)
            return
        sim_origin, wall_origin = self._pace_origin
        due = wall_origin + (self.world.time - sim_origin) / self.realtime
        if due > now:
            self._sleep(due - now)

    def _report(self, goal: Goal) -> None:
        """Turn what the server did during the last step into events."""
        world = self.world
        server = world.server
        held = server.held_reason
        if (held is not None) != self._held:
            self._held = held is not None
            self._events.append(
                GoalHeld(goal.goal_id, held) if held is not None else GoalReleased(goal.goal_id)
            )
        if server.plan_version != self._plan_version and server.plan is not None:
            self._plan_version = server.plan_version
            path = tuple((float(x), float(y)) for x, y in server.plan.points)
            self._events.append(GoalPlan(goal.goal_id, path))
        if server.state in (NavState.SUCCEEDED, NavState.ABORTED):
            if server.state is NavState.SUCCEEDED:
                done = GoalDone.succeeded(goal.goal_id, server.status_text, _SUCCEEDED)
            else:
                done = GoalDone.failed(goal.goal_id, _ABORTED, server.status_text)
            self._events.append(done)
            self._active = None
        elif world.time >= self._next_feedback - 1e-9:
            self._next_feedback += self.feedback_period
            self._events.append(
                GoalFeedback(goal.goal_id, world.robot.pose, server.distance_remaining)
            )


@dataclass(frozen=True)
class SimReady:
    """A simulated world for a mission, and where its robot starts."""

    world: SimWorld
    start: Pose2D
    start_defaulted: bool  # True: no start was given, the simulator chose ``start``


def prepare_sim_world(
    mission: Mission,
    grid: OccupancyGrid,
    start: Pose2D | None,
    robot: RobotProfile,
    *,
    preflight: bool = True,
    numbers: Sequence[int] | None = None,
) -> SimReady:
    """The simulated world for ``mission`` on ``grid`` with ``robot``.

    ``start`` None puts the robot at the roomy point nearest the map origin. With
    ``preflight``, every waypoint is checked against the costmap first and all problems
    are raised together as :class:`~navseq.errors.MissionErrors`, naming waypoints by
    ``numbers`` (their numbers in the file, when ``mission`` is a part of it). One
    costmap serves pre-flight and the simulated navigation server alike, and pre-flight
    comes before the world is built: it lists every problem at once, where building
    the world would stop at the first (a start inside an obstacle).
    """
    from navseq.errors import MissionErrors
    from navseq.preflight import check_mission
    from navseq.sim.costmap import Costmap
    from navseq.sim.profile import SimSettings

    settings = SimSettings.of(robot)
    defaulted = start is None
    if start is None:
        start = default_start(grid, settings.footprint)
    costmap = Costmap.from_grid(grid, settings.costmap_params)
    if preflight:
        problems = check_mission(mission, costmap, start, numbers=numbers, robot=robot)
        if problems:
            raise MissionErrors(problems)
    world = SimWorld(
        grid,
        start,
        costmap=costmap,
        nav_params=settings.nav_params,
        footprint=settings.footprint,
    )
    return SimReady(world, start, defaulted)


def create(settings: SimNavigatorSettings, draft: NavigatorDraft) -> NavigatorSetup:
    """The ``sim`` kind: the simulated world on the mission's map, paced at ``draft.realtime``.

    With no start pose given, the robot starts at the roomy point nearest the map
    origin (said in a note). One costmap serves pre-flight and the simulated server.
    """
    from navseq.errors import NavseqError
    from navseq.run.values import format_pose

    if draft.map_path is None:
        raise NavseqError(
            "the simulator needs a map: give --map MAP.yaml (map= in the Python API) or a "
            "map: key in the mission",
            source=draft.mission.source,
        )
    from navseq.sim.filters import load_filtered_map

    grid = load_filtered_map(draft.map_path, draft.mission.filters)
    ready = prepare_sim_world(
        draft.mission,
        grid,
        draft.start,
        draft.robot,
        preflight=draft.preflight,
        numbers=draft.numbers,
    )
    notes = []
    if ready.start_defaulted:
        draft.start = ready.start
        draft.start_source = "simulator default"
        notes.append(
            f"no start pose given (--start or start:): the robot starts at "
            f"{format_pose(ready.start)}, the roomy point nearest the map origin"
        )
    world = ready.world
    realtime = draft.realtime
    return NavigatorSetup(
        make_navigator=lambda: SimNavigator(world, realtime=realtime),
        info={"kind": "sim", "robot": draft.robot.name},
        grid=grid,
        notes=notes,
    )
