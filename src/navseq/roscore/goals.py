"""Which goal a ROS navigator tracks, and whether the server answered its cancel.

Client libraries call back on their own threads, about goals that may have been
replaced long ago (pass-through sends a new goal over an active one; pause/resume
sends the same goal again). Every send gets a new number; a callback carries the
number it was made for and counts only while that is still the tracked send. Shared
by both ROS navigators; no ROS here.
"""

from __future__ import annotations

import threading
from typing import Any


class GoalBook:
    """The tracked send: its number, the executor's goal id, the client's handle.

    Read and change the fields under :attr:`lock` (callbacks run on other threads).
    """

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.seq = 0  # goes up with every goal sent, and when one is dropped
        self.goal_id: int | None = None  # the executor's id of the tracked goal
        self.handle: Any = None  # the client library's handle of it, once there is one
        self.accepted = False
        self._cancel_seq = 0  # the send a cancel was asked for (0: none)
        self.cancel_answered = threading.Event()
        self.cancel_answered.set()  # nothing to wait for

    def start(self, goal_id: int) -> int:
        """Track a new send of ``goal_id`` (the previous one is simply no longer
        tracked: the server preempts it with this one); its number. Under :attr:`lock`."""
        self.seq += 1
        self.goal_id = goal_id
        self.handle = None
        self.accepted = False
        self.cancel_answered.set()
        return self.seq

    def is_current(self, seq: int, goal_id: int | None = None) -> bool:
        """The callback of send ``seq`` (about ``goal_id``) is about the tracked goal."""
        if seq != self.seq or self.goal_id is None:
            return False
        return goal_id is None or goal_id == self.goal_id

    def drop(self) -> int | None:
        """Stop tracking the goal (finished, died with its server, or given up);
        its id, if one was tracked. Under :attr:`lock`."""
        goal_id, self.goal_id, self.handle = self.goal_id, None, None
        self.seq += 1  # late callbacks of the dropped send are ignored
        self.cancel_answered.set()  # a goal no longer tracked needs no cancel answer
        return goal_id

    def ask_cancel(self) -> tuple[bool, Any]:
        """Record a cancel of the tracked send: (whether one is to be sent now, the
        handle to send it with). Once per send; under :attr:`lock`."""
        if self.goal_id is None or self._cancel_seq == self.seq:
            return False, None
        self._cancel_seq = self.seq
        self.cancel_answered.clear()
        return True, self.handle

    def cancel_pending(self, seq: int) -> bool:
        """A cancel was asked for send ``seq`` before its handle came (send it now)."""
        return self._cancel_seq == seq
