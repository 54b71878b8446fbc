"""A navigation server in the spirit of move_base: plan, follow, replan, succeed or abort.

The server is independent of any robot body: each control step it is given the robot's
pose and current velocity and answers with a velocity command, so the same object
drives the in-process :class:`navseq.sim.world.SimWorld` and the ROS navigation node.

Life of a goal (``state``): :meth:`set_goal` makes it ACTIVE (replacing any other);
the first control step plans on the costmap. It ends

- SUCCEEDED when the controller has the robot within the xy and yaw tolerances;
- ABORTED at once when the goal is off the map or not free (and, with
  ``planner_tolerance``, no free cell is that near it: else the plan ends at the nearest
  one and the goal SUCCEEDS there, as Nav2's NavFn plans), or no way on the map leads
  there from a robot that stands where it can turn (nothing the robot does changes that);
- otherwise, when no plan exists from where the robot is (it stopped where it cannot
  turn, and no free cell is near), or the next step could not
  be taken without the footprint touching an obstacle and no evasive move (turning the
  other way, creeping forward or back) is safe either, or evading has not brought the
  robot 0.2 m closer within ``blocked_patience`` seconds, the server runs move_base's
  recovery behaviours one at a time, each followed by a new plan: clear the costmap,
  rotate in place (a full turn, as far as it is safe), back up a little (forward if
  backing up is unsafe). A robot that can physically get out does. When the robot is
  stuck again after the last one it ends ABORTED with move_base's text, "Failed to find
  a valid plan. Even after executing recovery behaviors." or "Failed to find a valid
  control. Even after executing recovery behaviors.", and our reason in brackets. Real
  progress (0.2 m closer) re-arms the behaviours, at most ``recovery_rounds`` rounds per
  goal, so a goal always ends. Stopping, the command is zero: the robot never collides;
- CANCELED on :meth:`cancel`.

Replanning happens when the robot strays more than ``stray_distance`` from the plan
and, if ``replan_period`` is set, periodically. Every new plan bumps ``plan_version``.

Collision safety: every step, the footprint at the pose the next command leads to is
tested with :func:`footprint_collides`. Near obstacles the test is extended to the
whole braking manoeuvre that would follow, so that when the server must stop, the
robot can still come to rest without touching anything.

Other robots (a fleet): the caller passes their poses and footprints every control
step (:meth:`NavigationServer.set_other_robots`); with none, nothing above changes.

- The safety test treats them as obstacles, exactly (:func:`footprints_overlap`), and
  keeps ``robot_margin`` from them: their poses may be a step old (from ROS), and a
  robot driving toward this one closes the gap while this one brakes. A robot that
  is within the margin already may still move, so long as it does not close in.
- Plans are made on ``planning_costmap``: the map's ``costmap`` plus the other robots'
  footprints, grown by ``robot_margin``, as lethal cells, inflated as usual. It is
  rebuilt only when planning, and only once some robot has moved ``robot_moved`` since
  the last build. A robot that moved and is now within ``robot_near_plan`` of the rest
  of the plan makes the server replan around it.
- When the other robots leave no way to the goal but the map has one (a robot parked
  in the only door, or on the goal itself), or only robots block every move, the goal
  stays ACTIVE and the robot waits at rest, replanning every ``robot_replan_period``.
  It ends ABORTED, "blocked by another robot", when no way has opened and the robot
  has not got 0.2 m closer within ``blocked_patience`` — move_base's planner_patience.
  Two robots that need the same narrow passage at once may both wait and give up:
  nothing here negotiates who goes first. In a :class:`~navseq.sim.fleet_world.FleetWorld`
  :mod:`navseq.sim.right_of_way` does: it sends robots aside so that every such
  conflict resolves.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from navseq.geometry import Pose2D, normalize_angle
from navseq.sim.controller import ControllerParams, RegulatedPurePursuit
from navseq.sim.costmap import Costmap
from navseq.sim.footprint import (
    TURTLEBOT3_BURGER,
    Footprint,
    clearance_map,
    footprint_cells,
    footprint_collides,
    footprints_overlap,
)
from navseq.sim.planner import Plan, plan_path
from navseq.sim.robot import integrate_arc, next_velocity

OtherRobots = Sequence[tuple[Pose2D, Footprint]]

PLAN_FAILED = "Failed to find a valid plan. Even after executing recovery behaviors."
CONTROL_FAILED = "Failed to find a valid control. Even after executing recovery behaviors."
RECOVERY_BEHAVIOURS = ("clear_costmap", "rotate", "back_up")


class NavState(enum.Enum):
    IDLE = "IDLE"
    ACTIVE = "ACTIVE"
    SUCCEEDED = "SUCCEEDED"
    ABORTED = "ABORTED"
    CANCELED = "CANCELED"


@dataclass(frozen=True)
class NavParams(ControllerParams):
    """Controller tuning plus the server's own settings (metres, seconds).

    ``start_search_radius``: when the robot centre sits in a cell the planner may not
    start from (it stopped close to a wall), plan from the nearest free cell within
    this radius, as move_base's planners clear the robot's own cell.

    ``planner_tolerance``: when the goal's cell is not free (an obstacle, too close to
    one, unknown), plan to the nearest free cell within this distance and drive there
    (the goal then succeeds at the plan's end), as NavFn does with its ``tolerance``.
    move_base's ``default_tolerance`` is 0 (the ROS 1 default here); nav2_bringup's
    ``GridBased.tolerance`` is 0.5 m (the ROS 2 stand-in's, see ``NAV2_PLANNER_TOLERANCE``).
    """

    stray_distance: float = 0.3
    replan_period: float | None = None  # the simulated world is static: off by default
    start_search_radius: float = 0.25
    planner_tolerance: float = 0.0  # m; 0: a goal that is not free is not planned to
    escape_speed: float = 0.05  # m/s, forward or back, when the controller's move is unsafe
    escape_distance: float = 0.1  # m crept before the controller gets another try
    blocked_patience: float = 10.0  # s blocked without 0.2 m of progress before ABORT
    robot_near_plan: float = 0.5  # m: another robot's centre this close to the plan: replan
    robot_moved: float = 0.1  # m a robot's outline moves before the costmap holding it is stale
    robot_replan_period: float = 1.0  # s between replans while another robot blocks the way
    robot_margin: float = 0.05  # m kept from other robots: they move while this one brakes
    recovery_rotation: float = 2.0 * math.pi  # rad turned in place by the rotate recovery
    recovery_backup: float = 0.3  # m driven back (or forward) by the back-up recovery (Nav2's)
    recovery_rounds: int = 3  # times per goal the behaviours re-arm after real progress


class NavigationServer:
    """Pursues one goal at a time on a costmap; see the module docstring."""

    def __init__(
        self,
        costmap: Costmap,
        params: NavParams | None = None,
        footprint: Footprint = TURTLEBOT3_BURGER,
    ) -> None:
        self.params = params if params is not None else NavParams()
        self.footprint = footprint
        self.controller = RegulatedPurePursuit(self.params, costmap)
        self.state = NavState.IDLE
        self.status_text = ""
        self.goal: Pose2D | None = None
        self.plan: Plan | None = None
        self.plan_version = 0
        self.distance_remaining: float | None = None
        self._needs_plan = False
        self._follows_given_path = False  # a FollowPath goal: no planning of our own
        self._since_plan = 0.0
        self._goal_time = 0.0
        self._blocked_since: float | None = None  # goal time the controller was first blocked
        self._remaining_when_blocked = math.inf
        self._blocked_by_robot = False
        self._escape_command = (0.0, 0.0)
        self._escape_time_left = 0.0
        self._others: OtherRobots = ()
        self._nearby: OtherRobots = ()  # those of them the safety test could meet
        self._costmap_others: list[Pose2D] = []  # where planning_costmap has the others
        self._plan_others: list[Pose2D] = []  # ... and where the current plan had them
        self._waiting = False  # holding still until a replan finds a way past another robot
        self._waiting_since: float | None = None
        self._remaining_when_waiting = math.inf
        self._pending_recoveries: list[str] = []
        self._recovery_rounds_left = 0
        self._recovery: _Recovery | None = None
        self._remaining_at_recovery = math.inf
        self.recoveries_run = 0
        self.costmap_version = 0
        # Set by a fleet's right of way while it holds the robot back (it waits for a
        # robot the fleet deals with, or gives way to one): for whom. None: not held.
        self.held_reason: str | None = None
        self._use_costmap(costmap)

    # -- goal life cycle -------------------------------------------------------------

    def set_goal(self, goal: Pose2D) -> None:
        """Pursue ``goal`` from the next control step on; replaces (preempts) any active goal."""
        self.goal = goal
        self.state = NavState.ACTIVE
        self.status_text = ""
        self.distance_remaining = None
        self._needs_plan = True
        self._follows_given_path = False
        self._goal_time = 0.0
        self._blocked_since = None  # goal time the controller was first blocked
        self._remaining_when_blocked = math.inf
        self._blocked_by_robot = False  # ... by another robot only, not by the map
        self._escape_time_left = 0.0
        self._waiting = False
        self._waiting_since = None  # goal time another robot first blocked the way
        self._remaining_when_waiting = math.inf
        self._pending_recoveries = list(RECOVERY_BEHAVIOURS)
        self._recovery_rounds_left = self.params.recovery_rounds - 1
        self._recovery = None
        self._remaining_at_recovery = math.inf
        self.recoveries_run = 0  # behaviours run for this goal (tests, reports)

    @property
    def recovery_kind(self) -> str | None:
        """The recovery behaviour running now (one of RECOVERY_BEHAVIOURS), or None."""
        return self._recovery.kind if self._recovery is not None else None

    def follow_path(self, points: np.ndarray, goal: Pose2D) -> None:
        """Follow ``points`` (N, 2) to ``goal`` as given, as Nav2's controller server does
        a ``FollowPath`` goal: no planning nor re-planning, no recovery behaviours; a
        robot that cannot go on ends ABORTED. Replaces (preempts) any active goal."""
        self.set_goal(goal)
        self._follows_given_path = True
        self._needs_plan = False
        self._pending_recoveries = []
        self._recovery_rounds_left = 0
        steps = np.hypot(*np.diff(points, axis=0).T) if len(points) > 1 else np.zeros(0)
        self.plan = Plan(points=points, length=float(steps.sum()), cost=float(steps.sum()))
        self.plan_version += 1
        self.controller.set_path(points, goal)

    def set_other_robots(
        self,
        others: Iterable[tuple[Pose2D, Footprint]],
        nearby: OtherRobots | None = None,
    ) -> None:
        """The other robots' poses (map frame) and footprints now; call every control step.

        Cheap: the costmap is rebuilt only when planning. A robot is expected to keep its
        place in the sequence and its footprint from one call to the next. ``nearby``,
        when the caller knows it (a fleet sorts every pair once a step), holds those of
        them the safety test could meet this step; None: all of them.
        """
        self._others = others if isinstance(others, list | tuple) else list(others)
        self._nearby = self._others if nearby is None else nearby

    def cancel(self) -> None:
        """Stop pursuing the active goal (state CANCELED); nothing happens when idle."""
        if self.state is NavState.ACTIVE:
            self._finish(NavState.CANCELED, "canceled")

    def compute_velocity(self, pose: Pose2D, v: float, w: float, dt: float) -> tuple[float, float]:
        """Velocity command for the next ``dt`` seconds; (0, 0) unless a goal is ACTIVE."""
        if self.state is not NavState.ACTIVE or self.goal is None:
            return 0.0, 0.0
        controller = self.controller
        self._since_plan += dt
        if self._waiting:
            return self._keep_waiting(pose, dt)
        if self._recovery is not None:
            return self._run_recovery(pose, v, w, dt)
        period = self.params.replan_period
        wants_plan = not self._follows_given_path and (
            self._needs_plan
            or controller.distance_to_path > self.params.stray_distance
            or (period is not None and self._since_plan >= period)
            or (self._others and self._robot_near_plan())
        )
        if wants_plan and not self._replan(pose):
            return 0.0, 0.0

        self._goal_time += dt
        if self._blocked_since is not None and (
            self._goal_time - self._blocked_since > self.params.blocked_patience
        ):
            if self._blocked_by_robot:
                self._finish(
                    NavState.ABORTED, "stopped: blocked by another robot, no way around it"
                )
            else:
                self._stuck(CONTROL_FAILED, "stopped: blocked by an obstacle, no way around it")
            return 0.0, 0.0

        if self._escape_time_left > 0.0:
            self._escape_time_left -= dt
            if self._command_is_safe(pose, v, w, *self._escape_command, dt):
                return self._escape_command
            self._escape_time_left = 0.0

        cmd_v, cmd_w = controller.compute(pose, v, w)
        self.distance_remaining = remaining = controller.distance_remaining
        if controller.goal_reached:
            self._finish(NavState.SUCCEEDED, "goal reached")
            return 0.0, 0.0
        if remaining < self._remaining_at_recovery - 0.2:
            self._rearm_recoveries()
        if self._blocked_since is not None and remaining < self._remaining_when_blocked - 0.2:
            self._blocked_since = None  # real progress since: the obstacle is behind us
        if self._waiting_since is not None and remaining < self._remaining_when_waiting - 0.2:
            self._waiting_since = None  # ... and the robot that blocked the way
        if self._command_is_safe(pose, v, w, cmd_v, cmd_w, dt):
            return cmd_v, cmd_w

        robots_only = bool(self._others) and self._command_is_safe(
            pose, v, w, cmd_v, cmd_w, dt, with_others=False
        )
        if self._blocked_since is None:
            self._blocked_since = self._goal_time
            self._remaining_when_blocked = remaining
            self._blocked_by_robot = robots_only
        evasion = self._evasive_command(pose, v, w, cmd_v, cmd_w, dt)
        if evasion is None:
            if robots_only:
                self._wait_for_robot()  # only robots are in the way, and robots move
                return 0.0, 0.0
            self._stuck(CONTROL_FAILED, "stopped: the footprint would hit an obstacle")
            return 0.0, 0.0
        if evasion[0] != 0.0:  # creep on for a while, or the controller steers straight back
            self._escape_command = evasion
            self._escape_time_left = self.params.escape_distance / self.params.escape_speed
        else:
            controller.turn_the_long_way(cmd_w)
        return evasion

    # -- services ------------------------------------------------------------------------

    def make_plan(self, start: Pose2D, goal: Pose2D) -> Plan | None:
        """A plan from ``start`` to ``goal`` (exact end points) around the other robots,
        or None; no goal is started."""
        self._refresh_planning_costmap()
        return self._plan_on(self.planning_costmap, start, goal)

    def clear_costmaps(self) -> None:
        """Rebuild the costmap from the map and the other robots' present poses (drops
        anything transient) and replan."""
        self._use_costmap(Costmap.from_grid(self.costmap.grid, self.costmap.params))
        self._refresh_planning_costmap()
        if self.state is NavState.ACTIVE:
            self._needs_plan = True

    def use_map(self, costmap: Costmap) -> None:
        """Plan and steer on ``costmap`` (a new map's) from now on; an active goal is
        planned again on it."""
        self._use_costmap(costmap)
        self._refresh_planning_costmap()
        if self.state is NavState.ACTIVE and not self._follows_given_path:
            self._needs_plan = True

    # -- internals -----------------------------------------------------------------------

    def _use_costmap(self, costmap: Costmap) -> None:
        """``costmap`` is the map's; the planning costmap starts as that, without robots."""
        self.costmap = costmap
        self._clearance = clearance_map(costmap.grid)
        self._costmap_others = []
        self._use_planning_costmap(costmap)

    def _use_planning_costmap(self, costmap: Costmap) -> None:
        self.planning_costmap = costmap
        self.controller.set_costmap(costmap)  # slows down near other robots as near walls
        self.costmap_version += 1

    def _refresh_planning_costmap(self) -> None:
        """Put the other robots' present footprints in the planning costmap if it is stale."""
        if not self._others_moved(self._costmap_others):
            return
        grid = self.costmap.grid
        groups = [footprint_cells(grid, footprint, at) for at, footprint in self._others]
        # None: partly off the map, where no plan goes anyway. Grown by the margin the
        # safety test keeps, or plans squeeze through gaps the robot then may not drive.
        costmap = self.costmap.with_obstacle_groups(
            [cells for cells in groups if cells is not None], padding=self.params.robot_margin
        )
        self._costmap_others = [at for at, _ in self._others]
        self._use_planning_costmap(costmap)

    def _others_moved(self, seen: list[Pose2D]) -> bool:
        """True if the other robots are not (within ``robot_moved``) where ``seen`` has them."""
        others = self._others
        if len(others) != len(seen):
            return True
        return any(
            self._robot_moved(before, at, footprint)
            for before, (at, footprint) in zip(seen, others, strict=True)
        )

    def _robot_moved(self, before: Pose2D, at: Pose2D, footprint: Footprint) -> bool:
        # How far its outline's farthest corner may have gone: travel plus turn.
        turned = abs(normalize_angle(at.yaw - before.yaw)) * footprint.circumscribed_radius
        return math.hypot(at.x - before.x, at.y - before.y) + turned > self.params.robot_moved

    def _robot_near_plan(self) -> bool:
        """True if a robot that moved since the plan was made is near the rest of the plan."""
        plan = self.plan
        if plan is None:
            return False
        seen = self._plan_others
        ahead: np.ndarray | None = None
        near_squared = self.params.robot_near_plan**2
        for index, (at, footprint) in enumerate(self._others):
            if index < len(seen) and not self._robot_moved(seen[index], at, footprint):
                continue
            if ahead is None:
                ahead = plan.points[self.controller.closest_index :]
            squared = (ahead[:, 0] - at.x) ** 2 + (ahead[:, 1] - at.y) ** 2
            if squared.size and float(squared.min()) < near_squared:
                return True
        return False

    def _wait_for_robot(self, remaining: float | None = None) -> None:
        """Hold still: another robot blocks the way. Replan now and then; see _keep_waiting.

        ``remaining``: the way left to the goal when the controller has not measured it.
        """
        if self._waiting_since is None:
            self._waiting_since = self._goal_time
            if self.distance_remaining is not None:
                remaining = self.distance_remaining
            self._remaining_when_waiting = math.inf if remaining is None else remaining
        self._waiting = True
        self._since_plan = 0.0
        # Not an obstacle that evasion may get round: that patience starts afresh later.
        self._blocked_since = None
        self._escape_time_left = 0.0

    def _keep_waiting(self, pose: Pose2D, dt: float) -> tuple[float, float]:
        """One step of waiting for another robot: give up after the patience, or replan."""
        assert self._waiting_since is not None
        self._goal_time += dt
        patience = self.params.blocked_patience
        if self._goal_time - self._waiting_since > patience:
            self._finish(
                NavState.ABORTED,
                f"no way to the goal: blocked by another robot for {patience:g} s",
            )
        elif self._since_plan >= self.params.robot_replan_period:
            self._replan(pose)  # a way found: it is followed from the next step on
        return 0.0, 0.0

    def _finish(self, state: NavState, text: str) -> None:
        self.state = state
        self.status_text = text

    def _replan(self, pose: Pose2D) -> bool:
        """Plan from ``pose`` to the goal; ABORT (and return False) if there is no plan."""
        assert self.goal is not None
        goal = self.goal
        plan = self.make_plan(pose, goal)
        self._needs_plan = False
        self._since_plan = 0.0
        if plan is None:
            self.plan = None
            on_the_map = self._plan_on(self.costmap, pose, goal) if self._others else None
            if on_the_map is not None:  # the map has a way: robots block it, for now
                self._wait_for_robot(on_the_map.length)
                return False
            why = self._why_no_plan(pose, goal)
            if self._goal_is_hopeless(goal) or self.costmap.is_free(pose.x, pose.y):
                # Nothing the robot can do changes the answer: the goal is ruled out, or
                # the robot stands where it can turn and the map has no way from there.
                self._finish(NavState.ABORTED, why)
            else:
                self._stuck(PLAN_FAILED, why)
            return False
        self._follow(plan, goal)
        return True

    def _follow(self, plan: Plan, goal: Pose2D) -> None:
        """Make ``plan`` (to ``goal``) the one the controller follows from now on."""
        self.plan = plan
        self.plan_version += 1
        self._plan_others = self._costmap_others
        self._waiting = False
        # The plan may end short of a goal that is not free (planner_tolerance): the
        # goal checker is satisfied at the plan's end, as Nav2's controller is.
        end_x, end_y = (float(value) for value in plan.points[-1])
        self.controller.set_path(plan.points, Pose2D(end_x, end_y, goal.yaw))

    # -- recovery behaviours (move_base's, in small) -------------------------------------

    def _goal_is_hopeless(self, goal: Pose2D) -> bool:
        """True if no move of the robot can make a plan exist: the goal is off the map or
        neither it nor a free cell within ``planner_tolerance`` is free there."""
        costmap = self.costmap
        return not costmap.grid.contains(goal.x, goal.y) or self.goal_point(goal) is None

    def goal_point(
        self, goal: Pose2D, costmap: Costmap | None = None
    ) -> tuple[float, float] | None:
        """Where a plan to ``goal`` ends: the goal if it is free, else the centre of the
        nearest free cell within ``planner_tolerance`` (NavFn's tolerance), else None."""
        costmap = costmap if costmap is not None else self.costmap
        if not costmap.grid.contains(goal.x, goal.y):
            return None  # Nav2 and move_base refuse a goal off the map, tolerance or not
        if costmap.is_free(goal.x, goal.y):
            return goal.x, goal.y
        tolerance = self.params.planner_tolerance
        if tolerance <= 0.0:
            return None
        return _nearest_free(costmap, goal.x, goal.y, tolerance)

    def _stuck(self, failure: str, why: str) -> None:
        """Start the next recovery behaviour, or ABORT with move_base's text if none is left."""
        if not self._pending_recoveries:
            self._finish(NavState.ABORTED, f"{failure} ({why})")
            return
        kind = self._pending_recoveries.pop(0)
        self.recoveries_run += 1
        if self.distance_remaining is not None:
            self._remaining_at_recovery = min(self._remaining_at_recovery, self.distance_remaining)
        amount = {
            "clear_costmap": 0.0,
            "rotate": self.params.recovery_rotation,
            "back_up": self.params.recovery_backup,
        }[kind]
        self._recovery = _Recovery(kind, amount)
        self._blocked_since = None
        self._escape_time_left = 0.0

    def _rearm_recoveries(self) -> None:
        """Real progress since the last recovery: the behaviours may help again later."""
        self._remaining_at_recovery = math.inf
        full = len(self._pending_recoveries) == len(RECOVERY_BEHAVIOURS)
        if not full and self._recovery_rounds_left > 0:
            self._recovery_rounds_left -= 1
            self._pending_recoveries = list(RECOVERY_BEHAVIOURS)

    def _run_recovery(self, pose: Pose2D, v: float, w: float, dt: float) -> tuple[float, float]:
        """One step of the running recovery behaviour; a new plan follows when it ends.

        Each behaviour is bounded: by its amount (angle, distance) and by a time limit,
        and it ends early when its next step would not be safe.
        """
        recovery = self._recovery
        assert recovery is not None
        self._goal_time += dt
        recovery.elapsed += dt
        command: tuple[float, float] | None = None
        if recovery.kind == "rotate" and recovery.elapsed == dt and not self._can_turn_round(pose):
            recovery.left = 0.0  # as move_base's rotate recovery: only a turn that is clear
        if recovery.kind == "rotate":
            speed = min(self.params.rotate_speed, self.params.limits.max_w)
            recovery.left -= abs(w) * dt
            limit = self.params.recovery_rotation / max(speed, 1e-6) + 2.0
            if recovery.left > 0.0 and recovery.elapsed < limit:
                command = self._first_safe(pose, v, w, dt, [(0.0, speed), (0.0, -speed)], recovery)
        elif recovery.kind == "back_up":
            speed = self.params.escape_speed
            recovery.left -= abs(v) * dt
            limit = self.params.recovery_backup / max(speed, 1e-6) + 2.0
            if recovery.left > 0.0 and recovery.elapsed < limit:
                command = self._first_safe(pose, v, w, dt, [(-speed, 0.0), (speed, 0.0)], recovery)
        else:  # clear_costmap: the costmap from the map again, and a new plan
            self.clear_costmaps()
        if command is not None:
            return command
        if v != 0.0 or w != 0.0:
            recovery.left = 0.0
            return 0.0, 0.0  # done: come to rest before planning again
        self._recovery = None
        self._needs_plan = True
        self._blocked_since = None
        return 0.0, 0.0

    def _can_turn_round(self, pose: Pose2D) -> bool:
        """True if the footprint clears the map at every heading, turning in place here."""
        if self._clearance_at(pose.x, pose.y) > self.footprint.circumscribed_radius + 0.1:
            return True
        grid, footprint = self.costmap.grid, self.footprint
        return not any(
            footprint_collides(grid, footprint, Pose2D(pose.x, pose.y, pose.yaw + k * math.pi / 16))
            for k in range(1, 32)
        )

    def _first_safe(
        self,
        pose: Pose2D,
        v: float,
        w: float,
        dt: float,
        commands: list[tuple[float, float]],
        recovery: _Recovery,
    ) -> tuple[float, float] | None:
        """The behaviour's command if safe (the first that is, chosen once), else None."""
        if recovery.command is not None:
            commands = [recovery.command]
        for command in commands:
            if self._command_is_safe(pose, v, w, *command, dt):
                recovery.command = command
                return command
        return None

    def _plan_on(self, costmap: Costmap, start: Pose2D, goal: Pose2D) -> Plan | None:
        end = self.goal_point(goal, costmap)
        if end is None:
            return None
        from_x, from_y = self._planning_start(costmap, start)
        plan = plan_path(costmap, (from_x, from_y), end)
        if plan is None:
            return None
        return _with_exact_ends(plan, (start.x, start.y), end)

    def _why_no_plan(self, start: Pose2D, goal: Pose2D) -> str:
        costmap = self.costmap
        if not costmap.grid.contains(goal.x, goal.y):
            return f"no plan: goal ({goal.x:.2f}, {goal.y:.2f}) is outside the map"
        if self.goal_point(goal) is None:
            return (
                f"no plan: goal ({goal.x:.2f}, {goal.y:.2f}) is in an obstacle "
                "or too close to one for the robot" + self._tolerance_note()
            )
        from_x, from_y = self._planning_start(costmap, start)
        if not costmap.is_free(from_x, from_y):
            return f"no plan: the robot at ({start.x:.2f}, {start.y:.2f}) is in an obstacle"
        return f"no plan: goal ({goal.x:.2f}, {goal.y:.2f}) is unreachable"

    def _tolerance_note(self) -> str:
        """Text for a goal with no free cell near: how near was searched, if at all."""
        tolerance = self.params.planner_tolerance
        return f", no free cell within {tolerance:g} m" if tolerance > 0.0 else ""

    def _planning_start(self, costmap: Costmap, start: Pose2D) -> tuple[float, float]:
        """Where to plan from: the robot, or the nearest free point if it is not free."""
        if costmap.is_free(start.x, start.y):
            return start.x, start.y
        grid = costmap.grid
        row, col = grid.world_to_cell(start.x, start.y)
        reach = math.ceil(self.params.start_search_radius / grid.resolution)
        top, left = max(row - reach, 0), max(col - reach, 0)
        window = costmap.free_mask()[top : row + reach + 1, left : col + reach + 1]
        rows, cols = np.nonzero(window)
        if rows.size == 0:
            return start.x, start.y
        nearest = np.argmin((rows + top - row) ** 2 + (cols + left - col) ** 2)
        if (rows[nearest] + top - row) ** 2 + (cols[nearest] + left - col) ** 2 > reach * reach:
            return start.x, start.y
        return grid.cell_to_world(int(rows[nearest] + top), int(cols[nearest] + left))

    def _clearance_at(self, x: float, y: float) -> float:
        row, col = self.costmap.grid.world_to_cell(x, y)
        clearance = self._clearance
        if 0 <= row < clearance.shape[0] and 0 <= col < clearance.shape[1]:
            return float(clearance[row, col])
        return 0.0

    def _evasive_command(
        self, pose: Pose2D, v: float, w: float, cmd_v: float, cmd_w: float, dt: float
    ) -> tuple[float, float] | None:
        """A safe move when the controller's is not, or None: the robot is boxed in.

        A blocked turn in place is tried the long way round; otherwise the robot creeps
        straight forward or back, whichever leads to more clearance, until the
        controller's own command is safe again (move_base's recovery, in small).
        """
        candidates: list[tuple[float, float]] = []
        if cmd_v == 0.0 and cmd_w != 0.0:
            candidates.append((0.0, -cmd_w))
        speed = self.params.escape_speed
        step_x, step_y = 0.1 * math.cos(pose.yaw), 0.1 * math.sin(pose.yaw)
        ahead = self._clearance_at(pose.x + step_x, pose.y + step_y)
        behind = self._clearance_at(pose.x - step_x, pose.y - step_y)
        escapes = [(speed, 0.0), (-speed, 0.0)]
        candidates.extend(escapes if ahead >= behind else escapes[::-1])
        for candidate in candidates:
            if self._command_is_safe(pose, v, w, *candidate, dt):
                return candidate
        return None

    def _command_is_safe(
        self,
        pose: Pose2D,
        v: float,
        w: float,
        cmd_v: float,
        cmd_w: float,
        dt: float,
        *,
        with_others: bool = True,
    ) -> bool:
        """True if the robot can take this command for one step and then still brake safely.

        The braking check repeats the robot model step by step (the server does not own
        the robot, so it uses the same limits the body has). Far from obstacles and
        other robots it is skipped: within the braking distance nothing can be reached
        there. ``with_others=False`` leaves the other robots out.
        """
        limits = self.params.limits
        grid = self.costmap.grid
        footprint = self.footprint
        others = self._nearby if with_others else ()
        start = pose
        v, w = next_velocity(limits, v, w, cmd_v, cmd_w, dt)
        pose = integrate_arc(pose.x, pose.y, pose.yaw, v, w, dt)
        clearance = self._clearance_at(pose.x, pose.y)
        # Far from every blocked cell the footprint cannot touch one (clearance_map):
        # the exact test, the dearest part of a step, is needed near walls only.
        near_map = clearance <= footprint.circumscribed_radius + 2.0 * grid.resolution
        if (near_map and footprint_collides(grid, footprint, pose)) or (
            others and self._too_close_to_robot(start, pose, others)
        ):
            return False
        travel = abs(v) * dt + v * v / (2.0 * limits.acc_v)
        margin = footprint.circumscribed_radius + travel + 2.0 * grid.resolution
        if clearance > margin and not (others and self._other_robot_within(pose, others, travel)):
            return True
        while v != 0.0 or w != 0.0:
            v, w = next_velocity(limits, v, w, 0.0, 0.0, dt)
            pose = integrate_arc(pose.x, pose.y, pose.yaw, v, w, dt)
            if footprint_collides(grid, footprint, pose) or (
                others and self._too_close_to_robot(start, pose, others)
            ):
                return False
        return True

    def _too_close_to_robot(self, start: Pose2D, pose: Pose2D, others: OtherRobots) -> bool:
        """True if the robot, moving on from ``start``, may not be at ``pose``.

        It must stay ``robot_margin`` away from the other robots, as their last known
        poses may already be out of date. Within the margin already (another robot came
        that close), it may still move so long as it does not close in or overlap.
        """
        footprint = self.footprint
        margin = self.params.robot_margin
        for at, other in others:
            if not footprints_overlap(footprint, pose, other, at, margin):
                continue
            if footprints_overlap(footprint, pose, other, at) or not footprints_overlap(
                footprint, start, other, at, margin
            ):
                return True
            closer = math.hypot(pose.x - at.x, pose.y - at.y)
            if closer < math.hypot(start.x - at.x, start.y - at.y):
                return True
        return False

    def _other_robot_within(self, pose: Pose2D, others: OtherRobots, travel: float) -> bool:
        """True if some other robot (or its margin) could be reached after the robot centre
        moves ``travel``."""
        own = self.footprint.circumscribed_radius + travel + self.params.robot_margin + 1e-6
        return any(
            math.hypot(at.x - pose.x, at.y - pose.y) < own + fp.circumscribed_radius
            for at, fp in others
        )


@dataclass
class _Recovery:
    """A running recovery behaviour: what is left of its angle (rad) or distance (m)."""

    kind: str
    left: float
    elapsed: float = 0.0
    command: tuple[float, float] | None = None


def _nearest_free(
    costmap: Costmap, x: float, y: float, radius: float
) -> tuple[float, float] | None:
    """The centre of the free cell nearest (x, y) within ``radius`` (m), or None.

    NavFn searches its tolerance square for the reachable point of least potential;
    the nearest free cell is that point wherever it is reachable (a goal beside a thin
    wall whose near side is unreachable may differ: the plan then fails as before).
    """
    grid = costmap.grid
    row, col = grid.world_to_cell(x, y)
    reach = math.ceil(radius / grid.resolution)
    top, left = max(row - reach, 0), max(col - reach, 0)
    window = costmap.free_mask()[top : row + reach + 1, left : col + reach + 1]
    rows, cols = np.nonzero(window)
    if rows.size == 0:
        return None
    centres = [
        grid.cell_to_world(int(r + top), int(c + left)) for r, c in zip(rows, cols, strict=True)
    ]
    points = np.array(centres, dtype=float)
    squared = (points[:, 0] - x) ** 2 + (points[:, 1] - y) ** 2
    nearest = int(np.argmin(squared))
    if squared[nearest] > radius * radius:
        return None
    return float(points[nearest, 0]), float(points[nearest, 1])


def _with_exact_ends(plan: Plan, start: tuple[float, float], goal: tuple[float, float]) -> Plan:
    """The plan with its first and last cell centres replaced by the exact start and goal."""
    points = np.array(plan.points, dtype=float)
    if len(points) == 1:
        points = np.array([start, goal], dtype=float)
    else:
        points[0] = start
        points[-1] = goal
    steps = np.hypot(np.diff(points[:, 0]), np.diff(points[:, 1]))
    return Plan(points=points, length=float(steps.sum()), cost=plan.cost)
