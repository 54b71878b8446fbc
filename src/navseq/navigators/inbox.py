"""Where a ROS navigator's callbacks leave news for the executor's thread.

A client library calls back on its own threads (actionlib's, rclpy's executor); the
executor may only be touched by the thread running the mission. So a callback only
records: it :meth:`~EventInbox.put`\\ s a navigator event and wakes the run's thread,
which is waiting in ``Navigator.spin`` and collects everything with
:meth:`~EventInbox.drain` in ``Navigator.poll``. Shared by the ROS 1 and ROS 2
navigators; nothing here knows ROS.
"""

from __future__ import annotations

import queue
import threading

from navseq.navigators.base import NavEvent


class EventInbox:
    """A thread-safe queue of navigator events, and the wake-up of whoever waits on it."""

    def __init__(self) -> None:
        self._events: queue.SimpleQueue[NavEvent] = queue.SimpleQueue()
        self._wake = threading.Event()

    def put(self, event: NavEvent) -> None:
        """Leave ``event`` for :meth:`drain` and wake a :meth:`wait` (any thread)."""
        self._events.put(event)
        self._wake.set()  # after the put, so that a woken waiter finds the event

    def wake(self) -> None:
        """Wake a :meth:`wait` without an event: something else may have changed (the
        clock moved, a server's status arrived) and is worth a look."""
        self._wake.set()

    def has_events(self) -> bool:
        return not self._events.empty()

    def drain(self) -> list[NavEvent]:
        """Every event put so far, in order; the inbox is empty after."""
        events: list[NavEvent] = []
        while True:
            try:
                events.append(self._events.get_nowait())
            except queue.Empty:
                return events

    def wait(self, seconds: float) -> None:
        """Sleep until woken or ``seconds`` have passed; a wake-up from before the call
        counts (it is cleared only after the sleep, and a later one sets it anew)."""
        self._wake.wait(seconds)
        self._wake.clear()
