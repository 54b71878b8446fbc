"""Seeing a waypoint-following goal through, for ``follow_waypoints`` and
``follow_gps_waypoints`` alike: the stand-in's :class:`~navseq.ros2.standin.WaypointRun`
is waited for with feedback, a cancel cancels it, and the result names the missed
waypoints with their error codes, as Nav2's waypoint_follower does."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from nav2_msgs.msg import MissedWaypoint

from navseq.ros2.messages import finish_goal, pose_stamped
from navseq.ros2.standin import Ending, Nav2StandIn, WaypointRun

FEEDBACK_PERIOD = 0.1  # s of wall time between two feedback messages


def see_waypoints_through(
    handle: Any,
    run: WaypointRun | None,
    refused: Ending | None,
    *,
    standin: Nav2StandIn,
    lock: threading.Lock,
    action: Any,
    frame: str,
    stamp: Callable[[], Any],
) -> Any:
    """``action``'s result for ``run`` once it ended, or for ``refused`` (the goal's
    ending when no run could start); ``handle`` is ended with the outcome."""
    result = action.Result()
    ending = refused
    if run is not None:
        while not run.done.wait(FEEDBACK_PERIOD):
            if handle.is_cancel_requested:
                with lock:
                    standin.cancel_waypoints(run)
                break
            handle.publish_feedback(action.Feedback(current_waypoint=run.current))
        assert run.ending is not None
        ending = run.ending
        now = stamp()
        result.missed_waypoints = [
            MissedWaypoint(
                index=missed.index,
                goal=pose_stamped(missed.pose, frame, now),
                error_code=int(missed.error_code),
            )
            for missed in run.missed
        ]
    assert ending is not None
    result.error_code = int(ending.error_code)
    result.error_msg = ending.error_msg
    finish_goal(handle, ending.outcome.value)
    return result


__all__ = ["FEEDBACK_PERIOD", "see_waypoints_through"]
