"""Hold a goal's SUCCEEDED until the robot's pose has caught up with it.

The executor judges a SUCCEEDED against the robot's pose as the navigator knows it
then. A ROS navigator knows the pose from ``/tf``, which comes on its own topic: on a
busy machine (measured on the real Nav2 on 2 cores: ``/tf`` up to 1 s late, with 100
to 200 transforms a second queued) the result can be handled before the transforms of
the last second are, and a true arrival is judged on a pose from before it — "succeeded
24° off the goal yaw", a retry for nothing. :class:`ResultHold` keeps such a result
back until a transform stamped no earlier than the result's arrival (less
:data:`STAMP_SLACK`) was taken in, or :data:`MAX_HOLD` wall seconds passed; a pose that
does not come costs that wait once, never a hang. No ROS here: the ROS navigators feed
it stamps and wall time.
"""

from __future__ import annotations

import threading

from navseq.navigators.base import GoalDone, GoalOutcome

#: Longest wait for the pose to catch up, in wall seconds (/tf was seen 1.0 s late).
MAX_HOLD = 1.0
#: A transform stamped this much before the result's arrival still counts (s): the
#: stack judged arrival on a pose at least that old itself.
STAMP_SLACK = 0.1
#: Poses stamped further than this from our clock are on another clock (a stack on
#: simulated time, navseq on wall time): their stamps say nothing, nothing is held (s).
SAME_CLOCK = 30.0


class ResultHold:
    """One held SUCCEEDED at most; :meth:`release` gives it back once the pose is fresh.

    Callbacks call :meth:`hold` (instead of reporting the result) and :meth:`saw_pose`
    with every pose message's stamp, on whatever thread; :meth:`release` and
    :meth:`ready` are asked from the run's thread. Other outcomes are never held.
    """

    def __init__(self, max_hold: float = MAX_HOLD, slack: float = STAMP_SLACK) -> None:
        self.max_hold = max_hold
        self.slack = slack
        self._lock = threading.Lock()
        self._held: GoalDone | None = None
        self._needed_stamp = 0.0
        self._give_up_at = 0.0
        self._latest_stamp = 0.0

    def should_hold(self, event: GoalDone, stamp_now: float) -> bool:
        """Only a SUCCEEDED is judged on the pose, and only when poses come stamped on
        our clock (with none yet, or on another clock, there is nothing to wait for)."""
        with self._lock:
            return (
                event.outcome is GoalOutcome.SUCCEEDED
                and self._latest_stamp > 0.0
                and abs(stamp_now - self._latest_stamp) < SAME_CLOCK
            )

    def hold(self, event: GoalDone, stamp_now: float, wall_now: float) -> None:
        """Keep ``event`` until a pose stamped at ``stamp_now`` (less the slack) came."""
        with self._lock:
            self._held = event
            self._needed_stamp = stamp_now - self.slack
            self._give_up_at = wall_now + self.max_hold

    def saw_pose(self, stamp: float) -> None:
        with self._lock:
            self._latest_stamp = max(self._latest_stamp, stamp)

    def ready(self, wall_now: float) -> bool:
        with self._lock:
            return self._held is not None and self._caught_up(wall_now)

    def release(self, wall_now: float) -> list[GoalDone]:
        """The held result once the pose caught up (or the wait is over), else nothing."""
        with self._lock:
            if self._held is None or not self._caught_up(wall_now):
                return []
            event, self._held = self._held, None
            return [event]

    def drop(self) -> None:
        """Forget a held result: its goal was replaced or its server is gone."""
        with self._lock:
            self._held = None

    def _caught_up(self, wall_now: float) -> bool:
        return self._latest_stamp >= self._needed_stamp or wall_now >= self._give_up_at
