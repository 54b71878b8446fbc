"""The behaviour tree log the ROS 2 stand-in writes for its navigators' goals
(:mod:`navseq.ros2.bt_events`), checked without ROS against the sequence measured on
Nav2 Jazzy's bt_navigator for one navigate_to_pose goal."""

from __future__ import annotations

from navseq.geometry import Pose2D
from navseq.ros2.bt_events import StatusChange, TreeLog
from navseq.ros2.standin import Ending, Navigator, NavTask, Outcome


def _goal(started: float = 0.0) -> NavTask:
    return NavTask(Navigator.TO_POSE, (Pose2D(1.0, 0.0, 0.0),), started)


def _changes(events: list[StatusChange]) -> list[tuple[str, int, str, str]]:
    return [(e.node.name, e.node.uid, e.previous, e.current) for e in events]


def test_a_goal_starts_plans_and_follows_as_nav2s_tree_logs_it() -> None:
    log = TreeLog(clock=lambda: 0.0)
    assert _changes(log.observe(_goal(), 0.0)) == [
        ("NavigateRecovery", 1, "IDLE", "RUNNING"),
        ("ControllerSelector", 3, "IDLE", "SUCCESS"),
        ("PlannerSelector", 4, "IDLE", "SUCCESS"),
        ("RateController", 5, "IDLE", "RUNNING"),
        ("ComputePathToPose", 6, "IDLE", "RUNNING"),
        ("ComputePathToPose", 7, "IDLE", "RUNNING"),
        ("NavigateWithReplanning", 2, "IDLE", "RUNNING"),
        ("ComputePathToPose", 7, "RUNNING", "SUCCESS"),
        ("ComputePathToPose", 7, "SUCCESS", "IDLE"),
        ("ComputePathToPose", 6, "RUNNING", "IDLE"),
        ("ComputePathToPose", 6, "IDLE", "SUCCESS"),
        ("RateController", 5, "RUNNING", "SUCCESS"),
        ("ComputePathToPose", 6, "SUCCESS", "IDLE"),
        ("FollowPath", 11, "IDLE", "RUNNING"),
        ("FollowPath", 12, "IDLE", "RUNNING"),
        ("RateController", 5, "SUCCESS", "RUNNING"),
    ]


def test_the_planner_runs_again_each_second_and_the_end_comes_with_the_next_goal() -> None:
    log = TreeLog(clock=lambda: 0.0)
    first = _goal()
    log.observe(first, 0.0)
    assert log.observe(first, 0.5) == []
    replan = _changes(log.observe(first, 1.0))
    assert replan[0] == ("ComputePathToPose", 6, "IDLE", "RUNNING")
    assert ("FollowPath", 12, "IDLE", "RUNNING") not in replan  # FollowPath keeps running
    first.end(Ending(Outcome.SUCCEEDED))
    assert log.observe(first, 1.2) == []  # as Nav2: nothing published once the tree stopped
    second = _goal(2.0)
    published = _changes(log.observe(second, 2.0))
    assert published[:4] == [
        ("FollowPath", 12, "RUNNING", "SUCCESS"),
        ("FollowPath", 12, "SUCCESS", "IDLE"),
        ("FollowPath", 11, "RUNNING", "IDLE"),
        ("FollowPath", 11, "IDLE", "SUCCESS"),
    ]
    end = published.index(("NavigateRecovery", 1, "IDLE", "SUCCESS"))
    assert published[end + 1 : end + 3] == [
        ("NavigateRecovery", 1, "SUCCESS", "IDLE"),
        ("NavigateRecovery", 1, "IDLE", "RUNNING"),  # the second goal's tree starts
    ]


def test_a_failed_plan_and_a_cancel_leave_every_node_idle() -> None:
    log = TreeLog(clock=lambda: 0.0)
    failing = _goal()
    failing.end(Ending(Outcome.ABORTED, 208, "no valid path"))
    started = _changes(log.observe(failing, 0.0))
    assert ("FollowPath", 12, "IDLE", "RUNNING") not in started
    canceled = _goal(1.0)
    published = _changes(log.observe(canceled, 1.0))
    assert ("ComputePathToPose", 7, "RUNNING", "FAILURE") in published
    assert ("NavigateRecovery", 1, "RUNNING", "FAILURE") in published
    canceled.end(Ending(Outcome.CANCELED))
    log.observe(canceled, 1.5)
    last = _changes(log.observe(_goal(2.0), 2.0))
    halted = last[: last.index(("NavigateRecovery", 1, "IDLE", "RUNNING"))]
    assert ("FollowPath", 12, "RUNNING", "IDLE") in halted
    assert halted[-1] == ("NavigateRecovery", 1, "RUNNING", "IDLE")
    assert all(current == "IDLE" for *_, current in halted)


def test_a_preempting_goal_goes_on_in_the_same_tree() -> None:
    log = TreeLog(clock=lambda: 0.0)
    first = _goal()
    log.observe(first, 0.0)
    first.end(Ending(Outcome.ABORTED, 0, "preempted by a new goal"))
    second = _goal(0.3)
    replan = _changes(log.observe(second, 0.3))
    assert replan[0] == ("ComputePathToPose", 6, "IDLE", "RUNNING")
    assert all(name != "NavigateRecovery" for name, *_ in replan)


def test_a_recovery_runs_the_root_recovery_branch_then_the_navigation_again() -> None:
    log = TreeLog(clock=lambda: 0.0)
    goal = _goal()
    log.observe(goal, 0.0)
    spinning = _changes(log.observe(goal, 0.3, "rotate"))
    assert spinning[:3] == [
        ("FollowPath", 12, "RUNNING", "FAILURE"),
        ("FollowPath", 12, "FAILURE", "IDLE"),
        ("FollowPath", 11, "RUNNING", "FAILURE"),
    ]
    assert spinning[-2:] == [
        ("RecoveryActions", 22, "IDLE", "RUNNING"),
        ("Spin", 26, "IDLE", "RUNNING"),
    ]
    assert log.observe(goal, 2.0, "rotate") == []  # no re-plan while the tree recovers
    again = _changes(log.observe(goal, 2.5))
    assert again[0] == ("Spin", 26, "RUNNING", "SUCCESS")
    assert ("NavigateWithReplanning", 2, "IDLE", "RUNNING") in again
    assert again[-3:] == [
        ("FollowPath", 11, "IDLE", "RUNNING"),
        ("FollowPath", 12, "IDLE", "RUNNING"),
        ("RateController", 5, "SUCCESS", "RUNNING"),
    ]
