"""How long a failed attempt waits before the next, and how many refusals a waypoint takes.

A failed attempt waits :data:`RETRY_BACKOFF` before the next one goes out, so a failing
stack is not hammered. An ABORTED (or timed-out, stalled ...) attempt already took the
stack's time, so that one second is enough. A goal the stack *rejects* comes back within
milliseconds, and a stack that refuses one goal (bt_navigator not active, a goal off its
map) mostly refuses the next: each rejection in a row doubles the wait, up to
:data:`RETRY_BACKOFF_MAX`, and under ``on_failure: retry`` only so many rejections in a row
are retried (:func:`rejection_limit`) before the waypoint fails and the mission stops,
instead of spinning for ever.
"""

from __future__ import annotations

from navseq.mission.model import Policy

#: Wait (s) after a failed attempt before the next, and after a first rejection.
RETRY_BACKOFF = 1.0
#: The longest wait (s) between rejected goals: 1, 2, 4, 8, 16, 30, 30 ...
RETRY_BACKOFF_MAX = 30.0
#: Rejections in a row retried under ``on_failure: retry`` when the policy's ``retries`` is 0:
#: with the waits above, the stack has 31 s to start taking goals.
REJECTED_RETRIES = 5


def retry_wait(rejections_in_row: int) -> float:
    """The wait before the next attempt, after ``rejections_in_row`` rejections (0: none)."""
    if rejections_in_row <= 1:
        return RETRY_BACKOFF
    # min() on the exponent first: a waypoint refused a thousand times must not overflow
    doublings = min(rejections_in_row - 1, 16)
    return min(RETRY_BACKOFF * 2.0**doublings, RETRY_BACKOFF_MAX)


def rejection_limit(policy: Policy) -> int:
    """Rejections in a row retried under ``on_failure: retry``: ``retries``, else 5."""
    return policy.retries if policy.retries > 0 else REJECTED_RETRIES


__all__ = [
    "REJECTED_RETRIES",
    "RETRY_BACKOFF",
    "RETRY_BACKOFF_MAX",
    "rejection_limit",
    "retry_wait",
]
