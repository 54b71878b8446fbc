"""The status changes Nav2's default behaviour trees log for a goal, without ROS.

bt_navigator publishes every status change of its tree's nodes on
``behavior_tree_log`` (``nav2_msgs/BehaviorTreeLog``: ``BehaviorTreeStatusChange``
events with the node's name, its uid in the tree and the statuses IDLE, RUNNING,
SUCCESS, FAILURE). The stand-in's navigators are rules in Python, not a tree, so
:class:`TreeLog` writes the events nav2_bringup's trees would write for the phases of a
goal the stand-in runs, with their node names and uids (depth-first, from 1):

- ``navigate_to_pose_w_replanning_and_recovery.xml``: NavigateRecovery (1),
  NavigateWithReplanning (2), ControllerSelector (3), PlannerSelector (4),
  RateController (5, 1 Hz), the ComputePathToPose recovery node (6) and action (7), the
  FollowPath recovery node (11) and action (12);
- ``navigate_through_poses_w_replanning_and_recovery.xml``: the same with a 0.333 Hz
  RateController over ComputePathThroughPoses (6), ReactiveSequence (7),
  RemovePassedGoals (8) and ComputePathThroughPoses (9); FollowPath (13, 14).

The sequences are those measured on Nav2 Jazzy for a ``navigate_to_pose`` goal that
succeeds: the tree starts and plans, FollowPath runs, every rate-controller period the
planner runs again, and at the end everything returns to IDLE. Like Nav2's
bt_navigator, which flushes the log at each tick of a running tree only, the events
after a goal's last tick (its SUCCESS or FAILURE and the halt to IDLE) are published
with the next goal's first message. When the stand-in's navigation server runs one of
its recovery behaviours, FollowPath fails and the root's recovery branch runs the
RoundRobin child it stands for (clear costmaps: ClearingActions, rotate: Spin, back
up: BackUp), then the navigation starts again. A failed goal logs the failing action and
the nodes above it as FAILURE; a cancel halts every node to IDLE. A goal that preempts
one of the same navigator goes on in the same tree, with a re-plan.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from navseq.ros2.standin import Navigator, NavTask, Outcome

IDLE, RUNNING, SUCCESS, FAILURE = "IDLE", "RUNNING", "SUCCESS", "FAILURE"
#: The default trees' recovery branch, depth first (its first node's uid: Tree.recovery_base).
RECOVERY_BRANCH = (
    "Sequence",
    "Fallback",
    "WouldAControllerRecoveryHelp",
    "WouldAPlannerRecoveryHelp",
    "RecoveryFallback",
    "GoalUpdated",
    "RecoveryActions",
    "ClearingActions",
    "ClearLocalCostmap-Subtree",
    "ClearGlobalCostmap-Subtree",
    "Spin",
    "Wait",
    "BackUp",
)
#: The stand-in's recovery behaviours as the RoundRobin's children they stand for.
RECOVERY_ACTIONS = {"clear_costmap": "ClearingActions", "rotate": "Spin", "back_up": "BackUp"}


@dataclass(frozen=True)
class TreeNode:
    name: str
    uid: int


@dataclass(frozen=True)
class StatusChange:
    """One ``BehaviorTreeStatusChange``; ``wall`` the event's time (Nav2: wall clock)."""

    node: TreeNode
    previous: str
    current: str
    wall: float


@dataclass(frozen=True)
class Tree:
    """The nodes of one default tree the log speaks of."""

    root: TreeNode
    pipeline: TreeNode
    controller_selector: TreeNode
    planner_selector: TreeNode
    rate: TreeNode
    planning: tuple[TreeNode, ...]  # recovery node, inner nodes, the planner action last
    instant: tuple[TreeNode, ...]  # inner nodes that succeed at once (RemovePassedGoals)
    follow_recovery: TreeNode
    follow: TreeNode
    period: float  # s: the rate controller's
    recovery_base: int  # uid of the recovery branch's Sequence; its nodes follow

    def recovery_node(self, name: str) -> TreeNode:
        """A node of the recovery branch (``Sequence`` ... ``BackUp``) by name."""
        return TreeNode(name, self.recovery_base + RECOVERY_BRANCH.index(name))


def _common(rate_uid: int = 5) -> dict[str, TreeNode]:
    return {
        "root": TreeNode("NavigateRecovery", 1),
        "pipeline": TreeNode("NavigateWithReplanning", 2),
        "controller_selector": TreeNode("ControllerSelector", 3),
        "planner_selector": TreeNode("PlannerSelector", 4),
        "rate": TreeNode("RateController", rate_uid),
    }


TO_POSE_TREE = Tree(
    **_common(),
    planning=(TreeNode("ComputePathToPose", 6), TreeNode("ComputePathToPose", 7)),
    instant=(),
    follow_recovery=TreeNode("FollowPath", 11),
    follow=TreeNode("FollowPath", 12),
    period=1.0,
    recovery_base=16,
)
THROUGH_POSES_TREE = Tree(
    **_common(),
    planning=(
        TreeNode("ComputePathThroughPoses", 6),
        TreeNode("ReactiveSequence", 7),
        TreeNode("RemovePassedGoals", 8),
        TreeNode("ComputePathThroughPoses", 9),
    ),
    instant=(TreeNode("RemovePassedGoals", 8),),
    follow_recovery=TreeNode("FollowPath", 13),
    follow=TreeNode("FollowPath", 14),
    period=1.0 / 0.333,
    recovery_base=18,
)
TREES = {Navigator.TO_POSE: TO_POSE_TREE, Navigator.THROUGH_POSES: THROUGH_POSES_TREE}


class Phase(enum.Enum):
    """Where a failed goal failed: the planner (2xx codes) or the controller."""

    PLANNING = "planning"
    FOLLOWING = "following"


class TreeLog:
    """The log of the trees of one bt_navigator; :meth:`observe` every step or so.

    ``clock`` gives the events' wall time.
    """

    def __init__(self, clock: Callable[[], float]) -> None:
        self._clock = clock
        self._task: NavTask | None = None
        self._seen: NavTask | None = None  # the last goal the tree started for
        self._recovery: str | None = None  # the recovery behaviour running
        self._tree: Tree | None = None
        self._planned_at = 0.0
        self._status: dict[TreeNode, str] = {}
        self._out: list[StatusChange] = []
        self._held: list[StatusChange] = []

    def observe(
        self, started: NavTask | None, now: float, recovery: str | None = None
    ) -> list[StatusChange]:
        """The events to publish now, given the navigator goal started last, the
        simulated time ``now`` and the recovery behaviour the stand-in runs for it."""
        task = self._task
        if task is not None and task.ending is not None:
            if (
                started is not None
                and started is not task
                and started.navigator is task.navigator
                and _preempted(task)
            ):
                self._seen = self._task = started  # the tree goes on: a re-plan
                self._plan(now, first=False)
            else:
                self._end(task)
                self._held.extend(self._take())
                self._task = self._tree = None
        if (
            self._task is None
            and started is not None
            and started is not self._seen
            and started.navigator in TREES
        ):
            self._start(started, now)
        elif self._task is not None and self._tree is not None:
            if recovery != self._recovery:
                self._recover(self._tree, recovery, now)
            elif recovery is None and now - self._planned_at >= self._tree.period - 1e-9:
                self._plan(now, first=False)
        if self._task is None:
            return []
        ready = [*self._held, *self._take()]
        self._held = []
        return ready

    # -- sequences -----------------------------------------------------------------------

    def _start(self, task: NavTask, now: float) -> None:
        self._seen = self._task = task
        self._tree = TREES[task.navigator]
        self._recovery = None
        tree = self._tree
        self._set(tree.root, RUNNING)
        self._set(tree.controller_selector, SUCCESS)
        self._set(tree.planner_selector, SUCCESS)
        self._set(tree.rate, RUNNING)
        self._plan_start(tree)
        self._set(tree.pipeline, RUNNING)
        if task.ending is not None and _phase(task) is Phase.PLANNING:
            return  # the planner fails: settled by _end on the next observation
        self._plan_done(tree, first=True)
        self._planned_at = now

    def _plan(self, now: float, *, first: bool) -> None:
        tree = self._tree
        assert tree is not None
        self._plan_start(tree)
        self._plan_done(tree, first=first)
        self._planned_at = now

    def _plan_start(self, tree: Tree) -> None:
        for node in tree.planning:
            self._set(node, SUCCESS if node in tree.instant else RUNNING)

    def _plan_done(self, tree: Tree, *, first: bool) -> None:
        action, recovery, inner = tree.planning[-1], tree.planning[0], tree.planning[1:-1]
        self._set(action, SUCCESS)
        self._set(action, IDLE)
        for node in reversed(inner):
            self._set(node, IDLE)
        self._set(recovery, IDLE)
        self._set(recovery, SUCCESS)
        self._set(tree.rate, SUCCESS)
        self._set(recovery, IDLE)
        if first or self._status.get(tree.follow, IDLE) == IDLE:
            self._set(tree.follow_recovery, RUNNING)
            self._set(tree.follow, RUNNING)
        self._set(tree.rate, RUNNING)

    def _recover(self, tree: Tree, recovery: str | None, now: float) -> None:
        """The navigation failed and a recovery runs (the root's recovery branch, its
        RoundRobin's child for the stand-in's behaviour), or the one running ended and
        the navigation starts again."""
        node = tree.recovery_node
        if self._recovery is not None:
            action = node(RECOVERY_ACTIONS.get(self._recovery, "ClearingActions"))
            for done in (
                action,
                node("RecoveryActions"),
                node("RecoveryFallback"),
                node("Sequence"),
            ):
                self._set(done, SUCCESS)
            self._halt(tree, [node(name) for name in reversed(RECOVERY_BRANCH)])
            self._recovery = None
            self._set(tree.controller_selector, SUCCESS)
            self._set(tree.planner_selector, SUCCESS)
            self._set(tree.rate, RUNNING)
            self._plan_start(tree)
            self._set(tree.pipeline, RUNNING)
            self._plan_done(tree, first=True)
            self._planned_at = now
        if recovery is None:
            return
        self._set(tree.follow, FAILURE)
        self._set(tree.follow, IDLE)
        self._set(tree.follow_recovery, FAILURE)
        self._set(tree.pipeline, FAILURE)
        self._halt(
            tree,
            (tree.controller_selector, tree.planner_selector, tree.rate, tree.follow_recovery),
        )
        self._set(tree.pipeline, IDLE)
        self._set(node("Sequence"), RUNNING)
        self._set(node("WouldAControllerRecoveryHelp"), SUCCESS)
        self._set(node("Fallback"), SUCCESS)
        self._set(node("RecoveryFallback"), RUNNING)
        self._set(node("GoalUpdated"), FAILURE)
        self._set(node("RecoveryActions"), RUNNING)
        action = node(RECOVERY_ACTIONS.get(recovery, "ClearingActions"))
        self._set(action, RUNNING)
        if action.name == "ClearingActions":
            self._set(node("ClearLocalCostmap-Subtree"), SUCCESS)
            self._set(node("ClearGlobalCostmap-Subtree"), SUCCESS)
        self._recovery = recovery

    def _end(self, task: NavTask) -> None:
        tree = self._tree
        assert tree is not None and task.ending is not None
        outcome = task.ending.outcome
        if outcome is Outcome.SUCCEEDED:
            self._set(tree.follow, SUCCESS)
            self._set(tree.follow, IDLE)
            self._set(tree.follow_recovery, IDLE)
            self._set(tree.follow_recovery, SUCCESS)
            self._halt(tree, (tree.controller_selector, tree.planner_selector, tree.rate))
            self._halt(tree, (tree.follow_recovery,))
            self._set(tree.pipeline, SUCCESS)
            self._set(tree.pipeline, IDLE)
            self._set(tree.root, IDLE)
            self._set(tree.root, SUCCESS)
            self._set(tree.root, IDLE)
        elif outcome is Outcome.ABORTED:
            if _phase(task) is Phase.PLANNING:
                failed: Sequence[TreeNode] = (tree.planning[-1], *tree.planning[:-1], tree.rate)
            else:
                failed = (tree.follow, tree.follow_recovery)
            for node in failed:
                self._set(node, FAILURE)
            self._set(tree.pipeline, FAILURE)
            self._halt(tree, self._order(tree))
            self._set(tree.root, FAILURE)
            self._set(tree.root, IDLE)
        else:  # CANCELED: the tree is halted
            self._halt(tree, self._order(tree))
            self._set(tree.root, IDLE)

    def _order(self, tree: Tree) -> tuple[TreeNode, ...]:
        """The nodes a halt returns to IDLE, in the order Nav2's halt reaches them."""
        return (
            tree.follow,
            tree.follow_recovery,
            *reversed(tree.planning),
            tree.controller_selector,
            tree.planner_selector,
            tree.rate,
            tree.pipeline,
            *(tree.recovery_node(name) for name in reversed(RECOVERY_BRANCH)),
        )

    def _halt(self, tree: Tree, nodes: Sequence[TreeNode]) -> None:
        for node in nodes:
            self._set(node, IDLE)

    def _set(self, node: TreeNode, status: str) -> None:
        previous = self._status.get(node, IDLE)
        if previous != status:
            self._status[node] = status
            self._out.append(StatusChange(node, previous, status, self._clock()))

    def _take(self) -> list[StatusChange]:
        out, self._out = self._out, []
        return out


def _preempted(task: NavTask) -> bool:
    ending = task.ending
    return (
        ending is not None
        and ending.outcome is Outcome.ABORTED
        and ending.error_msg == "preempted by a new goal"
    )


def _phase(task: NavTask) -> Phase:
    code = task.ending.error_code if task.ending is not None else 0
    return Phase.PLANNING if 200 <= code < 300 else Phase.FOLLOWING


__all__ = ["THROUGH_POSES_TREE", "TO_POSE_TREE", "StatusChange", "TreeLog", "TreeNode"]
