"""Operator controls (pause, resume, cancel) layered on any navigator, for the ROS node.

The executor has no notion of pausing, and it must not be touched from a ROS service
thread. :class:`OperatorNavigator` therefore sits between the executor and the real
navigator and does it with the navigator interface alone:

- **pause** cancels the active goal on the real navigator (the robot stops), hides that
  goal's events from the executor and freezes the clock the executor sees, so no goal
  timeout, dwell or back-off runs out while paused. Goals the executor sends meanwhile
  are held back.
- **resume** sends the held goal again (same goal id) and lets the clock run on.
- **cancel** raises :class:`OperatorCancel` out of :meth:`poll`; the runner then cancels
  the active goal and ends the mission like any interruption.

Besides the operator, the process around the mission may have to stop it (the ROS node
being shut down): ``stop_reason`` is asked at every poll, and a reason it gives is
raised as :class:`NodeShutdown` the same way.

Requests come from any thread (:meth:`request`), are queued and applied on the
executor's thread in :meth:`poll`; the caller waits (bounded) for the outcome.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from navseq.geometry import Pose2D
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    GoalPlan,
    NavEvent,
    Navigator,
)

REQUESTS = ("pause", "resume", "cancel")


class OperatorCancel(Exception):
    """The operator asked to end the mission (the ``~cancel`` service)."""


class NodeShutdown(Exception):
    """The process running the mission is being shut down; ``str()`` says why."""


@dataclass
class _Request:
    kind: str
    done: threading.Event = field(default_factory=threading.Event)
    ok: bool = False
    message: str = ""


class OperatorNavigator:
    """A :class:`~navseq.navigators.base.Navigator` that adds pause/resume/cancel to ``inner``.

    ``stop_reason``, if given, is called from :meth:`poll` and returns why the mission
    must end now, or None to go on.
    """

    def __init__(self, inner: Navigator, stop_reason: Callable[[], str | None] | None = None):
        self.inner = inner
        self._stop_reason = stop_reason
        self._requests: queue.SimpleQueue[_Request] = queue.SimpleQueue()
        self._active: Goal | None = None  # the goal the executor believes is out
        self._held: Goal | None = None  # while paused: the goal to send on resume
        self._paused_at: float | None = None  # inner clock time when paused
        self._paused_total = 0.0  # inner clock seconds spent paused so far
        self._cancel_requested = False

    @property
    def paused(self) -> bool:
        return self._paused_at is not None

    # -- requests (any thread) -------------------------------------------------------

    def request(self, kind: str, timeout: float = 5.0) -> tuple[bool, str]:
        """Ask for ``pause``, ``resume`` or ``cancel``; wait for the executor's thread.

        Returns (ok, message) for a ``std_srvs/Trigger`` response.
        """
        if kind not in REQUESTS:
            return False, f"unknown request {kind!r}; one of {', '.join(REQUESTS)}"
        request = _Request(kind)
        self._requests.put(request)
        if not request.done.wait(timeout):
            return False, f"{kind}: the mission did not respond within {timeout:g} s"
        return request.ok, request.message

    def _apply(self, request: _Request) -> None:
        if request.kind == "pause":
            if self.paused:
                request.message = "already paused"
            else:
                self._paused_at = self.inner.now()
                if self._active is not None:
                    self._held = self._active
                    self.inner.cancel_goal()
                request.ok, request.message = True, "paused; the active goal was cancelled"
        elif request.kind == "resume":
            if not self.paused:
                request.message = "not paused"
            else:
                assert self._paused_at is not None
                self._paused_total += self.inner.now() - self._paused_at
                self._paused_at = None
                held, self._held = self._held, None
                if held is not None:
                    self._active = held
                    self.inner.send_goal(held)
                request.ok, request.message = True, "resumed"
        elif request.kind == "cancel":
            self._cancel_requested = True
            request.ok, request.message = True, "mission cancelled; the active goal was cancelled"
        request.done.set()

    # -- Navigator protocol (executor's thread) ----------------------------------------

    def now(self) -> float:
        if self._paused_at is not None:
            return self._paused_at - self._paused_total
        return self.inner.now() - self._paused_total

    def wait_for_server(self, timeout: float) -> bool:
        return self.inner.wait_for_server(timeout)

    def send_goal(self, goal: Goal) -> None:
        self._active = goal
        if self.paused:
            self._held = goal
        else:
            self.inner.send_goal(goal)

    def cancel_goal(self) -> None:
        self._active = None
        self._held = None
        self.inner.cancel_goal()

    def clear_costmaps(self) -> None:
        self.inner.clear_costmaps()

    def robot_pose(self) -> Pose2D | None:
        return self.inner.robot_pose()

    def odometry_pose(self) -> Pose2D | None:
        """The inner navigator's odometry-frame pose; None where it has no such thing."""
        odometry = getattr(self.inner, "odometry_pose", None)
        return odometry() if callable(odometry) else None

    def poll(self) -> list[NavEvent]:
        while True:
            try:
                self._apply(self._requests.get_nowait())
            except queue.Empty:
                break
        if self._cancel_requested:
            raise OperatorCancel("mission cancelled by the operator (~cancel)")
        events = []
        for event in self.inner.poll():
            goal_events = (GoalAccepted, GoalFeedback, GoalPlan, GoalDone)
            if self.paused and isinstance(event, goal_events):
                continue  # the paused goal's cancellation is ours, not the mission's
            active = self._active
            if isinstance(event, GoalDone) and active and event.goal_id == active.goal_id:
                self._active = None
            events.append(event)
        # Asked after taking the events: a shutdown is announced before it cancels the
        # goal, so the PREEMPTED end that cancel causes is always dropped here, never
        # passed on as a failed waypoint.
        stop = self._stop_reason() if self._stop_reason is not None else None
        if stop is not None:
            raise NodeShutdown(stop)
        return events

    def spin(self, seconds: float) -> None:
        self.inner.spin(seconds)

    def close(self) -> None:
        self.inner.close()
