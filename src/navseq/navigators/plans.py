"""Which goal a published global plan belongs to.

Navigation stacks publish their global plan on a topic that names no goal, so after
one goal replaced another the old goal's plan can still arrive: Nav2's default tree
re-plans at 1 Hz and follows the old path meanwhile; move_base's planner thread may
be part-way through the old goal. A plan is taken for a goal only when it ends at that
goal, and until one has, the stack's "distance remaining" (measured along whichever
plan it follows) says nothing about this goal either. Shared by the ROS 1 and ROS 2
navigators; no ROS here.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

from navseq.geometry import Pose2D
from navseq.navigators.base import GoalPlan

#: A plan ending this far from the goal or nearer is the goal's (m). Nav2's planner
#: ends within its ``tolerance`` (0.5 m in nav2_bringup) of a goal it cannot reach
#: exactly; move_base's NavFn within its ``default_tolerance`` (0 by default).
PLAN_END_WITHIN = 0.5


class PlanMatcher:
    """Tells plans (and the stack's distance remaining) of the tracked goal from stale ones.

    Call :meth:`track` when a goal is sent (``None`` when none is tracked any more),
    :meth:`plan_for` with every plan message's points. Safe to call from two threads.
    """

    def __init__(self, within: float = PLAN_END_WITHIN) -> None:
        self.within = within
        self._lock = threading.Lock()
        self._goal_id: int | None = None
        self._goal: Pose2D | None = None
        self._frame = ""
        self._matched = False
        self._plans_seen = False

    def track(self, goal_id: int | None, pose: Pose2D | None = None, frame: str = "") -> None:
        """Follow the goal just sent (its pose in ``frame``); None: no goal any more."""
        with self._lock:
            self._goal_id, self._goal, self._frame = goal_id, pose, frame
            self._matched = False

    def plan_for(self, points: Sequence[tuple[float, float]], frame: str = "") -> GoalPlan | None:
        """The plan as the tracked goal's, or None: no goal, an empty or a stale plan.

        A plan in another frame than the goal's cannot be compared and is taken as is.
        """
        with self._lock:
            self._plans_seen = True
            goal_id, goal = self._goal_id, self._goal
            if goal_id is None or not points:
                return None
            comparable = not frame or not self._frame or frame == self._frame
            if goal is not None and comparable:
                end_x, end_y = points[-1]
                if (end_x - goal.x) ** 2 + (end_y - goal.y) ** 2 > self.within**2:
                    return None
            self._matched = True
            return GoalPlan(goal_id, tuple(points))

    def distance_is_this_goals(self) -> bool:
        """Whether the stack's distance remaining can be taken for the tracked goal.

        Yes once a plan to it came; also where no plan was ever seen (the plan topic is
        not there to tell), as before plans were watched.
        """
        with self._lock:
            return self._matched or not self._plans_seen
