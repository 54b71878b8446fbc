"""A Nav2 action's result in navseq's words, for every Nav2 release navseq meets.

Nav2's results changed between releases: Iron and later put ``error_code`` and
``error_msg`` into ``NavigateToPose``'s result (and an ``error_code`` into the
behaviours' ``Spin``, ``BackUp`` and ``Wait``), Humble's have neither (its
``NavigateToPose.Result`` is empty, its behaviours give only ``total_elapsed_time``).
Everything here reads a result by what it has, never by what one release declares, so
``--navigator nav2`` works with Humble's nav2_msgs as with Jazzy's. No ROS import: the
status comes in as already read (:func:`navseq.ros2.messages.terminal_status`), and the
rules are tested with plain classes standing in for each release's message.
"""

from __future__ import annotations

from typing import Any

from navseq.navigators.base import GoalDone, GoalOutcome
from navseq.ros2.error_codes import describe_result

#: What a result whose status is not terminal (or unreadable) counts as.
LOST = (GoalOutcome.LOST, "LOST")


def result_words(result: Any) -> str:
    """Nav2's own words about ``result``: ``error_msg`` and ``error_code`` by name when
    the release has them (Iron and later), else ``""`` (Humble)."""
    code = getattr(result, "error_code", 0)
    message = getattr(result, "error_msg", "")
    return describe_result(int(code or 0), str(message or ""))


def goal_done(goal_id: int, terminal: tuple[GoalOutcome, str] | None, result: Any) -> GoalDone:
    """The :class:`GoalDone` of a ``NavigateToPose`` result with status ``terminal``
    (None: not a terminal status, the server does not know the goal)."""
    outcome, status = terminal or LOST
    text = result_words(result)
    if outcome is GoalOutcome.LOST and not text:
        text = "the server does not know the goal (restarted?)"
    return GoalDone(goal_id, outcome, status, text)


__all__ = ["goal_done", "result_words"]
