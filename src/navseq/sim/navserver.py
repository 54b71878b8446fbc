"""A navigation server in the spirit of move_base: plan, follow, replan, succeed or abort.

The server is independent of any robot body: each control step it is given the robot's
pose and current velocity and answers with a velocity command, so the same object
drives the in-process :class:`navseq.sim.world.SimWorld` and the ROS navigation node.

Life of a goal (``state``): :meth:`set_goal` makes it ACTIVE (replacing any other);
the first control step plans on the costmap. It ends

- SUCCEEDED when the controller has the robot within the xy and yaw tolerances;
- ABORTED when no plan exists (start or goal not free, goal unreachable) or when the
  next step could not be taken without the footprint touching an obstacle and no
  evasive move (turning the other way, creeping forward or back) is safe either, or
  evading has not brought the robot 0.2 m closer within ``blocked_patience`` seconds —
  the command is then zero, so the robot stops rather than collides;
- CANCELED on :meth:`cancel`.

Replanning happens when the robot strays more than ``stray_distance`` from the plan
and, if ``replan_period`` is set, periodically. Every new plan bumps ``plan_version``.

Collision safety: every step, the footprint at the pose the next command leads to is
tested with :func:`footprint_collides`. Near obstacles the test is extended to the
whole braking manoeuvre that would follow, so that when the server must stop, the
robot can still come to rest without touching anything.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from navseq.geometry import Pose2D
from navseq.sim.controller import ControllerParams, RegulatedPurePursuit
from navseq.sim.costmap import INSCRIBED, Costmap
from navseq.sim.footprint import (
    TURTLEBOT3_BURGER,
    Footprint,
    clearance_map,
    footprint_collides,
)
from navseq.sim.planner import Plan, plan_path
from navseq.sim.robot import integrate_arc, next_velocity


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
    """

    stray_distance: float = 0.3
    replan_period: float | None = None  # the simulated world is static: off by default
    start_search_radius: float = 0.25
    escape_speed: float = 0.05  # m/s, forward or back, when the controller's move is unsafe
    escape_distance: float = 0.1  # m crept before the controller gets another try
    blocked_patience: float = 10.0  # s blocked without 0.2 m of progress before ABORT


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
        self._since_plan = 0.0
        self._goal_time = 0.0
        self._blocked_since = None
        self._remaining_when_blocked = math.inf
        self._escape_command = (0.0, 0.0)
        self._escape_time_left = 0.0
        self._use_costmap(costmap)

    # -- goal life cycle -------------------------------------------------------------

    def set_goal(self, goal: Pose2D) -> None:
        """Pursue ``goal`` from the next control step on; replaces (preempts) any active goal."""
        self.goal = goal
        self.state = NavState.ACTIVE
        self.status_text = ""
        self.distance_remaining = None
        self._needs_plan = True
        self._goal_time = 0.0
        self._blocked_since: float | None = None  # goal time the controller was first blocked
        self._remaining_when_blocked = math.inf
        self._escape_time_left = 0.0

    def cancel(self) -> None:
        """Stop pursuing the active goal (state CANCELED); nothing happens when idle."""
        if self.state is NavState.ACTIVE:
            self._finish(NavState.CANCELED, "canceled")

    def compute_velocity(
        self, pose: Pose2D, v: float, w: float, dt: float
    ) -> tuple[float, float]:
        """Velocity command for the next ``dt`` seconds; (0, 0) unless a goal is ACTIVE."""
        if self.state is not NavState.ACTIVE or self.goal is None:
            return 0.0, 0.0
        controller = self.controller
        self._since_plan += dt
        period = self.params.replan_period
        wants_plan = (
            self._needs_plan
            or controller.distance_to_path > self.params.stray_distance
            or (period is not None and self._since_plan >= period)
        )
        if wants_plan and not self._replan(pose):
            return 0.0, 0.0

        self._goal_time += dt
        if self._blocked_since is not None and (
            self._goal_time - self._blocked_since > self.params.blocked_patience
        ):
            self._finish(NavState.ABORTED, "stopped: blocked by an obstacle, no way around it")
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
        if self._blocked_since is not None and remaining < self._remaining_when_blocked - 0.2:
            self._blocked_since = None  # real progress since: the obstacle is behind us
        if self._command_is_safe(pose, v, w, cmd_v, cmd_w, dt):
            return cmd_v, cmd_w

        if self._blocked_since is None:
            self._blocked_since = self._goal_time
            self._remaining_when_blocked = remaining
        evasion = self._evasive_command(pose, v, w, cmd_v, cmd_w, dt)
        if evasion is None:
            self._finish(NavState.ABORTED, "stopped: the footprint would hit an obstacle")
            return 0.0, 0.0
        if evasion[0] != 0.0:  # creep on for a while, or the controller steers straight back
            self._escape_command = evasion
            self._escape_time_left = self.params.escape_distance / self.params.escape_speed
        else:
            controller.turn_the_long_way(cmd_w)
        return evasion

    # -- services ------------------------------------------------------------------------

    def make_plan(self, start: Pose2D, goal: Pose2D) -> Plan | None:
        """A plan from ``start`` to ``goal`` (exact end points), or None; no goal is started."""
        from_x, from_y = self._planning_start(start)
        plan = plan_path(self.costmap, (from_x, from_y), (goal.x, goal.y))
        if plan is None:
            return None
        return _with_exact_ends(plan, (start.x, start.y), (goal.x, goal.y))

    def clear_costmaps(self) -> None:
        """Rebuild the costmap from the map (drops anything transient) and replan."""
        self._use_costmap(Costmap.from_grid(self.costmap.grid, self.costmap.params))
        if self.state is NavState.ACTIVE:
            self._needs_plan = True

    # -- internals -----------------------------------------------------------------------

    def _use_costmap(self, costmap: Costmap) -> None:
        self.costmap = costmap
        self.controller.set_costmap(costmap)
        self._clearance = clearance_map(costmap.grid)

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
            self._finish(NavState.ABORTED, self._why_no_plan(pose, goal))
            return False
        self.plan = plan
        self.plan_version += 1
        self.controller.set_path(plan.points, goal)
        return True

    def _why_no_plan(self, start: Pose2D, goal: Pose2D) -> str:
        costmap = self.costmap
        if not costmap.grid.contains(goal.x, goal.y):
            return f"no plan: goal ({goal.x:.2f}, {goal.y:.2f}) is outside the map"
        if not costmap.is_free(goal.x, goal.y):
            return (
                f"no plan: goal ({goal.x:.2f}, {goal.y:.2f}) is in an obstacle "
                "or too close to one for the robot"
            )
        from_x, from_y = self._planning_start(start)
        if not costmap.is_free(from_x, from_y):
            return f"no plan: the robot at ({start.x:.2f}, {start.y:.2f}) is in an obstacle"
        return f"no plan: goal ({goal.x:.2f}, {goal.y:.2f}) is unreachable"

    def _planning_start(self, start: Pose2D) -> tuple[float, float]:
        """Where to plan from: the robot, or the nearest free point if it is not free."""
        costmap = self.costmap
        if costmap.is_free(start.x, start.y):
            return start.x, start.y
        grid = costmap.grid
        row, col = grid.world_to_cell(start.x, start.y)
        reach = math.ceil(self.params.start_search_radius / grid.resolution)
        top, left = max(row - reach, 0), max(col - reach, 0)
        window = costmap.cost[top : row + reach + 1, left : col + reach + 1]
        rows, cols = np.nonzero(window < INSCRIBED)
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
        self, pose: Pose2D, v: float, w: float, cmd_v: float, cmd_w: float, dt: float
    ) -> bool:
        """True if the robot can take this command for one step and then still brake safely.

        The braking check repeats the robot model step by step (the server does not own
        the robot, so it uses the same limits the body has). Far from obstacles it is
        skipped: within the braking distance nothing can be reached there.
        """
        limits = self.params.limits
        grid = self.costmap.grid
        footprint = self.footprint
        v, w = next_velocity(limits, v, w, cmd_v, cmd_w, dt)
        pose = integrate_arc(pose.x, pose.y, pose.yaw, v, w, dt)
        if footprint_collides(grid, footprint, pose):
            return False
        travel = abs(v) * dt + v * v / (2.0 * limits.acc_v)
        margin = footprint.circumscribed_radius + travel + 2.0 * grid.resolution
        if self._clearance_at(pose.x, pose.y) > margin:
            return True
        while v != 0.0 or w != 0.0:
            v, w = next_velocity(limits, v, w, 0.0, 0.0, dt)
            pose = integrate_arc(pose.x, pose.y, pose.yaw, v, w, dt)
            if footprint_collides(grid, footprint, pose):
                return False
        return True


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
