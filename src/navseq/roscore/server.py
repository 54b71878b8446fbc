"""When the action server counts as lost, and when as back: one rule for both ROS.

A server is **lost** once it has shown no sign of life for ``lost_after`` seconds of
wall time (ROS 1: no status message for ``status_timeout`` — move_base publishes at
5 Hz; ROS 2: gone from the graph, which DDS notices after its lease). The goal died
with it: the navigator stops tracking it, and the executor waits (at most the
mission's ``server_timeout``) and resends the same attempt once the server is
**back**, i.e. ready to take a goal again (ROS 1: publishing *and* connected to our
goal and cancel topics, so a resent goal cannot vanish in transit). The loss is not
the waypoint's fault, so it costs no attempt. Wall time, not ROS time: a stopped
simulator stops its clock too, and a loss must still be noticed.
"""

from __future__ import annotations

import time
from collections.abc import Callable


def server_lost_text(action: str, why: str) -> str:
    """The reason a :class:`~navseq.navigators.base.ServerLost` gives, alike on both ROS."""
    return f"the action server {action} is gone ({why})"


class ServerWatch:
    """Tells, each time it is asked, whether the server was just lost or is just back.

    ``present()``: the server shows signs of life now; ``ready()``: it can take a goal.
    Before :meth:`found` (or the first :meth:`check`) nothing is reported.
    """

    def __init__(
        self,
        present: Callable[[], bool],
        ready: Callable[[], bool],
        lost_after: float,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._present = present
        self._ready = ready
        self.lost_after = lost_after
        self._clock = clock
        self.up: bool | None = None  # None: not looked at yet
        self._absent_since: float | None = None

    def found(self) -> None:
        """The server was found ready (the wait for it at the start succeeded)."""
        self.up = True
        self._absent_since = None

    def forget(self) -> None:
        """The server forgot our goal (LOST): report it back once it is ready again."""
        self.up = False

    def news(self) -> bool:
        """:meth:`check` would report a change now."""
        if self.up is None:
            return False
        if not self.up:
            return self._ready()
        if self._present():
            self._absent_since = None
            return False
        now = self._clock()
        if self._absent_since is None:
            self._absent_since = now
        return now - self._absent_since >= self.lost_after

    def check(self) -> str | None:
        """``"lost"`` or ``"back"`` when that just happened, else None."""
        if self.up is None:
            self.up = self._ready()
            return None
        if not self.news():
            return None
        self.up = not self.up
        self._absent_since = None
        return "back" if self.up else "lost"
