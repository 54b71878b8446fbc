"""Nav2 results of every release read alike: Humble's have no error_code / error_msg.

Plain classes stand in for each release's generated message (pytest's process never
imports ROS 2); the navigator hands its result to :func:`navseq.ros2.results.goal_done`.
"""

from __future__ import annotations

from navseq.navigators.base import GoalOutcome
from navseq.ros2.results import goal_done, result_words


class HumbleNavigateToPoseResult:
    """Humble's ``nav2_msgs/action/NavigateToPose_Result``: an empty message."""

    __slots__ = ()


class HumbleSpinResult:
    """Humble's ``Spin_Result``: only the elapsed time."""

    __slots__ = ("total_elapsed_time",)

    def __init__(self) -> None:
        self.total_elapsed_time = object()


class JazzyNavigateToPoseResult:
    __slots__ = ("error_code", "error_msg")

    def __init__(self, error_code: int = 0, error_msg: str = "") -> None:
        self.error_code = error_code
        self.error_msg = error_msg


def test_a_humble_success_is_a_success_with_no_words() -> None:
    done = goal_done(3, (GoalOutcome.SUCCEEDED, "SUCCEEDED"), HumbleNavigateToPoseResult())
    assert (done.goal_id, done.outcome, done.status, done.text) == (
        3,
        GoalOutcome.SUCCEEDED,
        "SUCCEEDED",
        "",
    )


def test_a_humble_abort_fails_the_attempt_with_the_status_only() -> None:
    done = goal_done(4, (GoalOutcome.FAILED, "ABORTED"), HumbleNavigateToPoseResult())
    assert (done.outcome, done.status, done.text) == (GoalOutcome.FAILED, "ABORTED", "")


def test_a_humble_result_the_server_does_not_know_is_lost_and_says_why() -> None:
    done = goal_done(5, None, HumbleNavigateToPoseResult())
    assert done.outcome is GoalOutcome.LOST
    assert "restarted" in done.text


def test_a_jazzy_result_keeps_nav2s_words() -> None:
    done = goal_done(
        6, (GoalOutcome.FAILED, "ABORTED"), JazzyNavigateToPoseResult(9001, "tree failed")
    )
    assert done.text == "tree failed (error_code 9001)"


def test_a_humble_behaviour_result_has_no_words() -> None:
    assert result_words(HumbleSpinResult()) == ""
