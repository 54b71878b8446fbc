"""What the shared core asks of one ROS client library (rospy + actionlib, or rclpy).

The core never calls ROS itself: a navigator hands it an object with these few
methods, written for its own client library, as a reader core is handed a storage
back-end. Everything about goals, clocks and servers that is the same on both
ROS versions is then decided once, in :mod:`navseq.roscore.navigator`.
"""

from __future__ import annotations

from typing import Protocol


class ClientLibrary(Protocol):
    """One ROS client library, as the shared navigator core sees it."""

    def now(self) -> float:
        """ROS time in seconds: the navigation stack's clock (0.0 before a simulated
        clock has started)."""
        ...

    def clock_wakes(self) -> bool:
        """Whether every ``/clock`` message wakes a waiting :meth:`EventInbox.wait`
        (then a wait must not trust wall time to tell how much ROS time passed)."""
        ...

    def check_running(self) -> None:
        """Raise the client library's own "shutting down" exception when it is."""
        ...

    def server_present(self) -> bool:
        """The action server shows signs of life now (it may not take goals yet)."""
        ...

    def server_ready(self) -> bool:
        """The action server can take a goal now (found and connected)."""
        ...

    def cancel_goal(self) -> None:
        """Ask the server to cancel the tracked goal (the navigator's own cancel)."""
        ...

    def warn(self, text: str) -> None:
        """Log ``text`` as a warning, the client library's way."""
        ...
