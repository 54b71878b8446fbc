"""What Nav2's navigators do, over navseq's simulator core, without any ROS import.

The ROS 2 simulator node (:mod:`navseq.ros2.sim_node`) serves Nav2's action interfaces;
this module holds the rules behind them, so that they can be read and tested without
rclpy. One :class:`Nav2StandIn` owns a :class:`navseq.sim.world.SimWorld` (the robot
body and the same :class:`navseq.sim.navserver.NavigationServer` the ROS 1 ``move_base``
stand-in uses) and plays three Nav2 servers on it:

- ``bt_navigator``'s two navigators, ``navigate_to_pose`` and ``navigate_through_poses``
  (:meth:`Nav2StandIn.navigate`). A new goal of the same navigator preempts the running
  one, which ends ABORTED with an empty result — what Nav2's ``SimpleActionServer``
  does in ``accept_pending_goal``. A goal for the *other* navigator while one runs is
  refused at once (ABORTED), as Nav2's navigator muxer does ("Requested navigation from
  ... while another navigator is processing"). Through poses, every pose but the last
  is passed without stopping: once the robot is within ``pass_radius`` (Nav2's
  ``RemovePassedGoals`` radius, 0.5 m) the next pose becomes the target;
- ``waypoint_follower``'s ``follow_waypoints`` (:meth:`Nav2StandIn.follow`): one
  ``navigate_to_pose`` task per pose, so that anyone else's ``navigate_to_pose`` goal
  preempts the follower's current one exactly as it would in Nav2. A waypoint whose
  task fails (aborted, preempted or canceled) is a missed waypoint; with
  ``stop_on_failure`` (Nav2's default) the whole goal then ends ABORTED, otherwise the
  follower goes on and SUCCEEDS at the end with the missed ones listed.

Re-planning on preemption (``replan_period``, off by default): Nav2's default tree
(``navigate_to_pose_w_replanning_and_recovery.xml``) computes the path inside a
``RateController hz="1.0"``, and a preempting ``navigate_to_pose`` goal only updates
the tree's goal: the tree goes on, and ``FollowPath`` keeps following the *old* path
until the next tick of that rate controller (ticks ``replan_period`` apart from the
plan that started the tree). If the robot reaches the old path's end within the goal
checker's tolerances before that tick, ``FollowPath`` succeeds and so does the tree:
the *new* goal ends SUCCEEDED with the robot at the old goal (measured on Nav2 Jazzy:
a pass-through radius of 0.4 m, SUCCEEDED 0.7 s after the goal was sent, 1.79 m from
it, in 2 of 6 runs). Meanwhile its feedback's ``distance_remaining`` is along the old
path. With ``replan_period`` > 0 the stand-in does the same; with 0 a preempting goal
is planned at once. The stand-in models this tick only for a preempting goal: otherwise
it re-plans by its own rules (a new goal, a robot that strays from the plan), which
give the same paths on a static map.

The robot's world as a Nav2 robot sees it (:meth:`Nav2StandIn.step`): the navigation
server steers from the pose :class:`navseq.sim.localization.Localization` believes (the
truth unless the odometry drifts or an initial pose moved the estimate), and its
commands, like the behaviours', go through Nav2's velocity chain
(:mod:`navseq.sim.velocity_chain`: ``cmd_vel_nav`` capped by the ``speed_limit``, then
smoothed) before they reach the body; :attr:`Nav2StandIn.commands` keeps each stage's
last value for the node to publish. A new map (:meth:`Nav2StandIn.replace_map`)
replaces the world's.

Times are simulated seconds (:attr:`Nav2StandIn.time`); the node steps this object from
one thread and calls everything else under the same lock.
"""

from __future__ import annotations

import dataclasses
import enum
import itertools
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import numpy.typing as npt

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.costmap_filters import CostmapFilter
from navseq.sim.behaviors import BehaviorServer
from navseq.sim.collision_monitor import CollisionMonitor, MonitorStage, nav2_bringup_polygons
from navseq.sim.filters import with_filters
from navseq.sim.localization import Localization
from navseq.sim.navserver import CONTROL_FAILED, NavState
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.velocity_chain import SpeedLimit, VelocitySmoother
from navseq.sim.world import SimWorld

PASS_RADIUS = 0.5  # m: Nav2's RemovePassedGoals default radius
# m: nav2_bringup's planner_server GridBased.tolerance. A goal in an obstacle or unknown
# space is planned to the nearest free cell within it and SUCCEEDS there (measured on
# Nav2 Jazzy: 0.44 m and 0.52 m from goals on and inside a pillar).
NAV2_PLANNER_TOLERANCE = 0.5


class Driver(Protocol):
    """A server that drives the robot itself while it runs (behaviours, docking)."""

    def drives(self, now: float) -> bool: ...

    def step(
        self, now: float, pose: Pose2D, collides: Callable[[Pose2D], bool]
    ) -> tuple[float, float]: ...

    def abort_all(self, now: float, why: str) -> None: ...


class Navigator(enum.Enum):
    """bt_navigator's two navigators (the action each one serves), and the controller
    server's ``follow_path``, which drives a given path without a navigator."""

    TO_POSE = "navigate_to_pose"
    THROUGH_POSES = "navigate_through_poses"
    FOLLOW_PATH = "follow_path"


class Outcome(enum.Enum):
    """How a goal ends, as the action's terminal status."""

    SUCCEEDED = "SUCCEEDED"
    ABORTED = "ABORTED"
    CANCELED = "CANCELED"


class ErrorCode(enum.IntEnum):
    """The Nav2 error codes a failed goal carries (nav2_msgs, Jazzy).

    Nav2's navigators pass on the code of the server that failed: the planner's
    ``ComputePathToPose`` codes (2xx) when there is no plan, the controller's
    ``FollowPath`` codes (1xx) when the robot cannot follow it. Each value is the
    nav2_msgs constant of the same name (``tests/test_ros2_error_codes.py`` compares
    them with the installed nav2_msgs), so navseq's ``nav2`` navigator names them.
    """

    NONE = 0
    CONTROLLER_UNKNOWN = 100  # FollowPath UNKNOWN
    FAILED_TO_MAKE_PROGRESS = 105
    NO_VALID_CONTROL = 106
    PLANNER_UNKNOWN = 200  # ComputePathToPose UNKNOWN
    START_OUTSIDE_MAP = 203
    GOAL_OUTSIDE_MAP = 204
    START_OCCUPIED = 205
    GOAL_OCCUPIED = 206
    NO_VALID_PATH = 208
    INVALID_PATH = 103  # FollowPath INVALID_PATH


@dataclass(frozen=True)
class Ending:
    outcome: Outcome
    error_code: int = ErrorCode.NONE
    error_msg: str = ""


@dataclass
class NavTask:
    """One ``navigate_to_pose`` / ``navigate_through_poses`` goal and how far it got."""

    navigator: Navigator
    poses: tuple[Pose2D, ...]
    started: float  # simulated seconds
    index: int = 0  # the pose being driven to
    recoveries_before: int = 0  # recovery behaviours run for poses already passed
    ending: Ending | None = None
    # SUCCEEDED while the server still followed a preempted goal's path (replan_period):
    # the robot stands at that goal's end, not at this one's.
    succeeded_on_old_path: bool = False
    done: threading.Event = field(default_factory=threading.Event, repr=False)

    @property
    def target(self) -> Pose2D:
        return self.poses[self.index]

    def end(self, ending: Ending) -> None:
        if self.ending is None:
            self.ending = ending
            self.done.set()


@dataclass(frozen=True)
class MissedWaypoint:
    index: int
    pose: Pose2D
    error_code: int


@dataclass
class WaypointRun:
    """One ``follow_waypoints`` goal: the poses, where it is, what it missed."""

    poses: tuple[Pose2D, ...]
    loops: int  # extra rounds after the first (Nav2's number_of_loops)
    stop_on_failure: bool
    current: int = 0
    loop: int = 0
    task: NavTask | None = None
    missed: list[MissedWaypoint] = field(default_factory=list)
    ending: Ending | None = None
    done: threading.Event = field(default_factory=threading.Event, repr=False)

    def end(self, ending: Ending) -> None:
        if self.ending is None:
            self.ending = ending
            self.done.set()


@dataclass
class Commands:
    """The last command of each stage of the velocity chain, and whether the chain
    drove this step (the node publishes ``cmd_vel_nav``, ``cmd_vel_smoothed`` and
    ``cmd_vel`` then)."""

    nav: tuple[float, float] = (0.0, 0.0)
    smoothed: tuple[float, float] = (0.0, 0.0)
    driving: bool = False
    # What the collision monitor passed on to the base (``cmd_vel``), and whether it
    # came from outside on ``cmd_vel_smoothed`` (teleop through the monitor) this step.
    out: tuple[float, float] = (0.0, 0.0)
    monitored_teleop: bool = False


@dataclass(frozen=True)
class Feedback:
    """The numbers Nav2's navigators put in their feedback."""

    pose: Pose2D
    navigation_time: float
    estimated_time_remaining: float
    number_of_recoveries: int
    distance_remaining: float
    poses_remaining: int


class Nav2StandIn:
    """bt_navigator and waypoint_follower on one simulated robot; see the module doc."""

    def __init__(
        self,
        world: SimWorld,
        *,
        pass_radius: float = PASS_RADIUS,
        replan_period: float = 0.0,
        planner_tolerance: float = NAV2_PLANNER_TOLERANCE,
        odom_drift: float = 0.0,
    ) -> None:
        self.world = world
        # Nav2's planner plans to a free cell near a goal that is not free (NavFn's
        # tolerance); the world's server, shared with ROS 1, does so only when told.
        server = world.server
        server.params = dataclasses.replace(server.params, planner_tolerance=planner_tolerance)
        self.pass_radius = pass_radius
        self.replan_period = replan_period  # s; 0: a preempting goal is planned at once
        self.time = 0.0
        self.active: NavTask | None = None
        self.waypoints: WaypointRun | None = None
        # The tree's rate controller: when it last planned, and when it plans the goal
        # that preempted another (None: the server pursues the active goal's own pose).
        self._planned_at = 0.0
        self._replan_due: float | None = None
        # A robot driven from outside (teleop on cmd_vel) follows its commands for longer
        # than the world's two steps; while a goal runs a command comes every step.
        world.body.cmd_vel_timeout = max(world.body.cmd_vel_timeout, 0.5)
        self.behaviors = BehaviorServer()
        # What drives the robot instead of the navigation server while it runs, first
        # asked first: the behaviour server, then any added (the docking server).
        self.drivers: list[Driver] = [self.behaviors]
        self.localization = Localization(world.robot.pose, drift=odom_drift)
        self.smoother = VelocitySmoother()
        self.speed_limit = SpeedLimit(server.params.limits.max_v)
        self.commands = Commands()
        # The costmap filters laid over every map the world gets (``replace_map``).
        self.filters: tuple[CostmapFilter, ...] = ()
        # Nav2's collision monitor between the smoother and the base (nav2_bringup's
        # FootprintApproach polygon on the robot's footprint, the laser as its source).
        self.monitor = MonitorStage(
            CollisionMonitor(nav2_bringup_polygons(), world.footprint.polygon)
        )
        self._smoothed_teleop: tuple[float, float, float] | None = None  # v, w, time
        # The navigator goal the tree started last (bt_navigator's log follows it), and
        # what refuses a goal before it moves: the selectors' unknown plugin ids.
        self.last_started: NavTask | None = None
        self.refusal: Callable[[Navigator], Ending | None] | None = None

    # -- goals -----------------------------------------------------------------------

    def navigate(self, navigator: Navigator, poses: Sequence[Pose2D]) -> NavTask:
        """Start a goal of ``navigator``; the task may have ended already (refused)."""
        task = NavTask(navigator, tuple(poses), self.time)
        if not task.poses:
            task.end(Ending(Outcome.ABORTED, ErrorCode.PLANNER_UNKNOWN, "no poses in the goal"))
            return task
        active = self.active
        if (
            active is not None
            and active.navigator is not navigator
            and active.navigator is not Navigator.FOLLOW_PATH
        ):
            task.end(
                Ending(
                    Outcome.ABORTED,
                    ErrorCode.NONE,
                    f"requested navigation from {navigator.value} while another "
                    f"navigator ({active.navigator.value}) is processing, rejecting request",
                )
            )
            return task
        self.last_started = task
        running = active is not None and active.ending is None
        if active is not None:
            active.end(Ending(Outcome.ABORTED, ErrorCode.NONE, "preempted by a new goal"))
        refused = self.refusal(navigator) if self.refusal is not None else None
        if refused is not None:  # the tree took the goal; its planner or controller fails
            if active is not None:
                self.active = None
                self._stop()
            task.end(refused)
            return task
        self.active = task
        server = self.world.server
        if (
            running
            and self.replan_period > 0
            and navigator is Navigator.TO_POSE
            and server.state is NavState.ACTIVE
        ):
            # Nav2's tree goes on with the old path until its rate controller ticks.
            if self._replan_due is None:
                self._replan_due = self._next_replan_tick()
            task.recoveries_before = -server.recoveries_run  # Nav2 counts from the preemption
            return task
        self._replan_due = None
        self._planned_at = self.time
        server.set_goal(task.target)
        return task

    def follow_path(self, points: npt.NDArray[np.float64], goal: Pose2D) -> NavTask:
        """Start a ``follow_path`` goal: ``points`` (N, 2) driven as given to ``goal``.

        It takes the controller from whatever goal runs (that one ends ABORTED): the
        stand-in has one controller, as Nav2's controller server has.
        """
        task = NavTask(Navigator.FOLLOW_PATH, (goal,), self.time)
        if len(points) == 0:
            task.end(Ending(Outcome.ABORTED, ErrorCode.INVALID_PATH, "the path has no poses"))
            return task
        if self.active is not None:
            self.active.end(Ending(Outcome.ABORTED, ErrorCode.NONE, "preempted by follow_path"))
        self.active = task
        self._replan_due = None
        self.world.server.follow_path(np.asarray(points, dtype=float), goal)
        return task

    def cancel(self, task: NavTask) -> None:
        """The client cancels ``task``: the robot stops (the body brakes from the next step)."""
        if task is self.active:
            self._stop()
        task.end(Ending(Outcome.CANCELED))

    def follow(
        self,
        poses: Sequence[Pose2D],
        *,
        loops: int = 0,
        start_index: int = 0,
        stop_on_failure: bool = True,
    ) -> WaypointRun:
        """Start a ``follow_waypoints`` goal; a running one is preempted (ABORTED)."""
        run = WaypointRun(tuple(poses), loops, stop_on_failure, current=start_index)
        previous = self.waypoints
        if previous is not None:
            self._drop_waypoint_task(previous)
            previous.end(Ending(Outcome.ABORTED, ErrorCode.NONE, "preempted by a new goal"))
        if not run.poses or not 0 <= start_index < len(run.poses):
            run.end(
                Ending(
                    Outcome.ABORTED,
                    601,  # FollowWaypoints TASK_EXECUTOR_FAILED: Nav2 has no better code
                    f"goal_index {start_index} is not a pose of the {len(run.poses)} given",
                )
            )
            return run
        self.waypoints = run
        self._next_waypoint_task(run)
        return run

    def cancel_waypoints(self, run: WaypointRun) -> None:
        if run is self.waypoints:
            self._drop_waypoint_task(run)
            self.waypoints = None
        run.end(Ending(Outcome.CANCELED))

    def abort_all(self, why: str) -> None:
        """End every goal (the node is shutting down) and stop the robot."""
        if self.waypoints is not None:
            self.waypoints.end(Ending(Outcome.ABORTED, ErrorCode.NONE, why))
            self.waypoints = None
        if self.active is not None:
            self.active.end(Ending(Outcome.ABORTED, ErrorCode.NONE, why))
        for driver in self.drivers:
            driver.abort_all(self.time, why)
        self._stop()

    # -- simulation ------------------------------------------------------------------

    def step(self) -> None:
        """Advance the world one step and settle whatever goal that ends."""
        world = self.world
        task = self.active
        if task is not None and task.ending is None:
            self._replan_if_due(task)
            self._pass_through(task)
        body = world.body
        nav: tuple[float, float] | None = None
        driver = next((d for d in self.drivers if d.drives(self.time)), None)
        if driver is not None:
            # A behaviour (or docking) has the robot; a navigation goal's controller waits.
            nav = driver.step(self.time, body.pose, body.collides)
        elif world.server.state is NavState.ACTIVE:
            believed = self.localization.believed_pose
            nav = self.speed_limit.apply(*world.controller_command(believed))
        if nav is not None:
            self.smoother.command(*nav, self.time)
            self.commands.nav = nav
        smoother = self.smoother
        self.commands.driving = smoother.active(self.time) and (
            nav is not None or smoother.output != (0.0, 0.0)
        )
        self.commands.monitored_teleop = False
        if self.commands.driving:
            self.commands.smoothed = smoother.step(self.time, world.dt)
            self.commands.out = self.monitor.filter(*self.commands.smoothed, world, self.time)
            world.drive(*self.commands.out)
        else:
            self._monitored_teleop()
            body.step(world.dt)  # idle: a teleop command, or braking to rest
        self.localization.moved(body.pose)
        self.time += world.dt
        if task is not None and task.ending is None:
            self._settle(task)
        if task is not None and task.ending is not None and task is self.active:
            self.active = None
            self._stop()
        run = self.waypoints
        if run is not None:
            self._advance_waypoints(run)

    def command(self, v: float, w: float) -> bool:
        """A velocity command from outside (teleop); ignored (False) while a goal or a
        behaviour runs."""
        if self.world.server.state is NavState.ACTIVE or any(
            d.drives(self.time) for d in self.drivers
        ):
            return False
        self.world.body.command(v, w)
        self._smoothed_teleop = None  # on cmd_vel, past the monitor
        return True

    def command_smoothed(self, v: float, w: float) -> bool:
        """A command from outside on ``cmd_vel_smoothed``: teleop through the collision
        monitor, as Nav2's monitor takes it; ignored (False) while the chain drives."""
        if not self.command(v, w):
            return False
        self._smoothed_teleop = (v, w, self.time)
        return True

    def _monitored_teleop(self) -> None:
        """Pass the latest ``cmd_vel_smoothed`` teleop command through the monitor to
        the body (each step: what the monitor sees changes as the robot moves)."""
        teleop = self._smoothed_teleop
        if teleop is None:
            return
        v, w, at = teleop
        if self.time - at > self.world.body.cmd_vel_timeout:
            self._smoothed_teleop = None
            self.commands.out = (0.0, 0.0)
            self.world.body.command(0.0, 0.0)  # the commands stopped coming: brake
            return
        self.commands.out = self.monitor.filter(v, w, self.world, self.time)
        self.commands.monitored_teleop = True
        self.world.body.command(*self.commands.out)

    def teleport(self, pose: Pose2D) -> str | None:
        """Put the robot at ``pose`` (and the belief with it); why not, if it cannot be."""
        try:
            self.world.teleport(pose)
        except NavseqError as error:
            return str(error)
        self.smoother.output = (0.0, 0.0)
        self.localization.teleported(self.world.robot.pose)
        return None

    def set_initial_pose(self, pose: Pose2D) -> None:
        """An initial pose (``initialpose``): the robot believes it is at ``pose``; it does
        not move. A running goal is steered from the new belief."""
        self.localization.set_pose(pose)

    def replace_map(self, grid: OccupancyGrid) -> str | None:
        """A new map replaces the world's (planner, costmaps, the body's walls); a
        warning when the robot now overlaps an obstacle of it (it cannot move then)."""
        # Nav2's filter masks come from their own map servers: a new map keeps them.
        self.world.replace_map(with_filters(grid, self.filters))
        pose = self.world.robot.pose
        if self.world.body.collides(pose):
            return (
                f"the robot at ({pose.x:.2f}, {pose.y:.2f}) overlaps an obstacle or unknown "
                "space of the new map: it cannot move until it is placed elsewhere"
            )
        return None

    def feedback(self, task: NavTask) -> Feedback:
        """What Nav2 reports for ``task`` now.

        The distance is along the current plan to the current pose (until the re-plan
        tick of a preempting goal, the preempted goal's plan, as in Nav2), plus the
        straight lines between the poses still ahead; the time remaining is that distance at the
        robot's present speed, zero when it stands or is within 0.1 m (Nav2's rule).
        """
        world = self.world
        robot = world.robot
        server = world.server
        believed = self.localization.believed_pose
        if server.distance_remaining is not None and task is self.active:
            to_target = server.distance_remaining
        else:
            to_target = believed.distance_to(task.target)
        ahead = sum(a.distance_to(b) for a, b in itertools.pairwise(task.poses[task.index :]))
        remaining = to_target + ahead
        speed = abs(robot.v)
        eta = remaining / speed if speed > 0.01 and remaining > 0.1 else 0.0
        recoveries = task.recoveries_before + (server.recoveries_run if task is self.active else 0)
        return Feedback(
            pose=believed,
            navigation_time=self.time - task.started,
            estimated_time_remaining=eta,
            number_of_recoveries=recoveries,
            distance_remaining=remaining,
            poses_remaining=len(task.poses) - task.index,
        )

    # -- internals -------------------------------------------------------------------

    def _stop(self) -> None:
        self._replan_due = None
        self.world.server.cancel()
        self.world.body.command(0.0, 0.0)
        # The controller's last word is a zero command; the smoother brakes to it.
        self.smoother.command(0.0, 0.0, self.time)

    def _next_replan_tick(self) -> float:
        """The rate controller's first tick after now: ``replan_period`` apart, counted
        from its last plan (the goal that started the tree, or the last preemption's)."""
        period = self.replan_period
        periods = math.floor((self.time - self._planned_at) / period + 1e-9) + 1
        return self._planned_at + periods * period

    def _replan_if_due(self, task: NavTask) -> None:
        """The rate controller ticks: the goal that preempted another gets its own path."""
        due = self._replan_due
        if due is None or self.time + 1e-9 < due:
            return
        self._replan_due = None
        self._planned_at = due
        server = self.world.server
        task.recoveries_before += server.recoveries_run
        server.set_goal(task.target)  # plans from where the robot is; it keeps rolling

    def _pass_through(self, task: NavTask) -> None:
        """Through poses: the next pose becomes the target once this one is near."""
        while (
            task.index + 1 < len(task.poses)
            and self.localization.believed_pose.distance_to(task.target) <= self.pass_radius
        ):
            task.recoveries_before += self.world.server.recoveries_run
            task.index += 1
            self.world.server.set_goal(task.target)  # replans; the robot keeps rolling

    def _settle(self, task: NavTask) -> None:
        server = self.world.server
        if server.state is NavState.SUCCEEDED:
            if task.index + 1 < len(task.poses):  # reached a pose to pass: go on
                task.recoveries_before += server.recoveries_run
                task.index += 1
                server.set_goal(task.target)
            else:
                task.succeeded_on_old_path = self._replan_due is not None
                task.end(Ending(Outcome.SUCCEEDED))
        elif server.state is NavState.ABORTED:
            task.end(Ending(Outcome.ABORTED, self._error_code(task), server.status_text))
        elif server.state is NavState.CANCELED:
            task.end(Ending(Outcome.CANCELED))

    def _error_code(self, task: NavTask) -> int:
        """The Nav2 code for the server's failure (see :class:`ErrorCode`)."""
        server = self.world.server
        text = server.status_text
        if task.navigator is Navigator.FOLLOW_PATH:  # no planner: the controller's codes
            if "another robot" in text:
                return ErrorCode.FAILED_TO_MAKE_PROGRESS
            return ErrorCode.NO_VALID_CONTROL
        # The pose the server pursued: a preempted goal's until the re-plan tick.
        goal = server.goal if server.goal is not None else task.target
        code, _ = self.no_plan_reason(self.localization.believed_pose, goal)
        if code in (ErrorCode.GOAL_OUTSIDE_MAP, ErrorCode.GOAL_OCCUPIED):
            return code
        if "another robot" in text:
            return ErrorCode.FAILED_TO_MAKE_PROGRESS
        if text.startswith(CONTROL_FAILED):
            return ErrorCode.NO_VALID_CONTROL
        return code

    def no_plan_reason(self, start: Pose2D, goal: Pose2D) -> tuple[int, str]:
        """Nav2's planner code and a text for why no plan leads from ``start`` to ``goal``."""
        costmap = self.world.server.costmap
        grid = costmap.grid
        if not grid.contains(goal.x, goal.y):
            return (
                ErrorCode.GOAL_OUTSIDE_MAP,
                f"goal ({goal.x:.2f}, {goal.y:.2f}) is outside the map",
            )
        if self.world.server.goal_point(goal) is None:
            tolerance = self.world.server.params.planner_tolerance
            return ErrorCode.GOAL_OCCUPIED, (
                f"goal ({goal.x:.2f}, {goal.y:.2f}) is in an obstacle or too close to one"
                + (f", no free cell within {tolerance:g} m" if tolerance > 0.0 else "")
            )
        if not grid.contains(start.x, start.y):
            return (
                ErrorCode.START_OUTSIDE_MAP,
                f"start ({start.x:.2f}, {start.y:.2f}) is outside the map",
            )
        return ErrorCode.NO_VALID_PATH, f"no valid path to ({goal.x:.2f}, {goal.y:.2f})"

    def _next_waypoint_task(self, run: WaypointRun) -> None:
        run.task = self.navigate(Navigator.TO_POSE, [run.poses[run.current]])

    def _drop_waypoint_task(self, run: WaypointRun) -> None:
        task = run.task
        if task is not None and task.ending is None:
            if task is self.active:
                self.active = None
                self._stop()
            task.end(Ending(Outcome.CANCELED))

    def _advance_waypoints(self, run: WaypointRun) -> None:
        """Waypoint follower: on to the next pose when the current task has ended."""
        task = run.task
        if task is None or task.ending is None or run.ending is not None:
            return
        if task.ending.outcome is not Outcome.SUCCEEDED:
            run.missed.append(
                MissedWaypoint(run.current, run.poses[run.current], task.ending.error_code)
            )
            if run.stop_on_failure:
                run.end(
                    Ending(
                        Outcome.ABORTED,
                        task.ending.error_code,
                        f"failed to process waypoint {run.current}: "
                        f"{task.ending.error_msg or task.ending.outcome.value}",
                    )
                )
                self.waypoints = None
                return
        following = run.current + 1
        if following >= len(run.poses):
            if run.loop >= run.loops:
                run.end(Ending(Outcome.SUCCEEDED))
                self.waypoints = None
                return
            run.loop += 1
            following = 0
        run.current = following
        self._next_waypoint_task(run)


def plan_poses(points: npt.ArrayLike, goal: Pose2D | None) -> list[Pose2D]:
    """The poses of a published plan (``points``: N x 2): each faces the next point, the
    last one has the goal's yaw (or keeps the last heading without a goal)."""
    xy = np.asarray(points, dtype=float).reshape(-1, 2)
    poses: list[Pose2D] = []
    count = len(xy)
    for index in range(count):
        x, y = float(xy[index, 0]), float(xy[index, 1])
        if index + 1 < count:
            yaw = math.atan2(float(xy[index + 1, 1]) - y, float(xy[index + 1, 0]) - x)
        elif goal is not None:
            yaw = goal.yaw
        elif index > 0:
            yaw = math.atan2(y - float(xy[index - 1, 1]), x - float(xy[index - 1, 0]))
        else:
            yaw = 0.0
        poses.append(Pose2D(x, y, yaw))
    return poses
