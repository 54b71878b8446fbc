"""Operator requests that reach a running mission from other threads.

The executor is single-threaded: only the thread inside
:func:`~navseq.executor.runner.run_mission` may touch it. A ROS service handler or a
UI thread instead files a request on a :class:`MissionControl` passed to
``run_mission``; the run's thread carries it out at its next look at the mission
(within one tick).
"""

from __future__ import annotations

import threading


class MissionControl:
    """A thread-safe mailbox of operator requests for one mission run."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._skips: list[str] = []

    def request_skip(self, reason: str = "skipped by operator") -> None:
        """Skip the waypoint being pursued now and go on with the next one."""
        with self._lock:
            self._skips.append(reason)

    def take_skips(self) -> list[str]:
        """The skip requests filed since the last call (the run's thread calls this)."""
        with self._lock:
            skips, self._skips = self._skips, []
        return skips
