"""Operator requests that reach a running mission from other threads.

The executor is single-threaded: only the thread inside
:func:`~navseq.executor.runner.run_mission` may touch it. A ROS service handler, a
signal handler or a UI thread instead files a request on a :class:`MissionControl`
passed to ``run_mission``; the run's thread carries it out at its next look at the
mission (within one tick) as an executor input (``skip``, ``pause``, ``resume``,
``cancel``) and answers it. This is the one operator path of every face of navseq:
the ROS nodes' services and the CLI's signals file requests here.

``stop_reason``, if given, is asked at every look too: a reason it returns ends the
run as :class:`StopRequested` (the process around the mission is being shut down,
e.g. ``rosnode kill``), before the navigator's events of that moment are applied.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field

#: What an operator can ask of a running mission.
REQUESTS = ("skip", "pause", "resume", "cancel")

#: How the reason of a mission the operator cancelled starts: the status topics and the
#: nodes' exit logs tell a cancel from a failure or an interruption by it.
CANCELLED = "cancelled"


def operator_reason(kind: str, service: str) -> str:
    """The executor's reason for an operator request made through ``service``
    (``~cancel``, ``~/cancel``): ``"cancelled by the operator (~cancel)"``."""
    done = {"pause": "paused", "resume": "resumed", "cancel": CANCELLED, "skip": "skipped"}
    return f"{done[kind]} by the operator ({service})"


def cancelled_by_operator(reason: str) -> bool:
    """Whether a mission's reason says the operator cancelled it."""
    return reason.startswith(CANCELLED)


def ended_from_outside(reason: str) -> bool:
    """Whether a visit's or mission's reason says it was cut short from outside (the
    operator's cancel, a signal, a crash of the process) rather than failed by the
    robot: such a visit was stopped, not failed."""
    return cancelled_by_operator(reason) or reason.startswith("interrupted")


class StopRequested(Exception):
    """The process running the mission is being shut down; ``str()`` says why."""


@dataclass
class OperatorRequest:
    """One request and, once the run's thread carried it out, its answer."""

    kind: str
    reason: str = ""
    ok: bool = False
    message: str = ""
    done: threading.Event = field(default_factory=threading.Event, repr=False)
    # Called once with the request when it is answered (on the answering thread): lets a
    # face that must not block, such as an rclpy service handler, wake on the answer.
    on_answer: Callable[[OperatorRequest], None] | None = field(default=None, repr=False)

    def answer(self, ok: bool, message: str) -> None:
        self.ok, self.message = ok, message
        self.done.set()
        if self.on_answer is not None:
            self.on_answer(self)


class MissionControl:
    """A thread-safe mailbox of operator requests for one mission run."""

    def __init__(self, stop_reason: Callable[[], str | None] | None = None) -> None:
        self._lock = threading.Lock()
        self._requests: list[OperatorRequest] = []
        self._closed: str | None = None  # why no request is taken any more
        self.stop_reason = stop_reason

    def request(self, kind: str, reason: str = "", timeout: float | None = 5.0) -> tuple[bool, str]:
        """File ``kind`` (one of :data:`REQUESTS`); wait up to ``timeout`` s for its answer.

        Returns (ok, message), as a ``std_srvs/Trigger`` response wants them. With
        ``timeout=None`` the request is only filed: (True, "requested").
        """
        request = self.submit(kind, reason)
        if request.done.is_set():
            return request.ok, request.message
        if timeout is None:
            return True, "requested"
        if not request.done.wait(timeout):
            return False, f"{kind}: the mission did not respond within {timeout:g} s"
        return request.ok, request.message

    def submit(
        self,
        kind: str,
        reason: str = "",
        on_answer: Callable[[OperatorRequest], None] | None = None,
    ) -> OperatorRequest:
        """File ``kind`` without waiting; the request, answered at once when refused.

        ``on_answer`` is called with the request once it is answered (also when that
        is at once, on this thread).
        """
        request = OperatorRequest(kind, reason, on_answer=on_answer)
        if kind not in REQUESTS:
            request.answer(False, f"unknown request {kind!r}; one of {', '.join(REQUESTS)}")
            return request
        with self._lock:
            closed = self._closed
            if closed is None:
                self._requests.append(request)
        if closed is not None:
            request.answer(False, f"nothing to {kind}: {closed}")
        return request

    def request_skip(self, reason: str = "skipped by operator") -> None:
        """Skip the waypoint being pursued now and go on with the next one."""
        self.request("skip", reason, timeout=None)

    def take_requests(self) -> list[OperatorRequest]:
        """The requests filed since the last call, oldest first (the run's thread)."""
        with self._lock:
            requests, self._requests = self._requests, []
        return requests

    def close(self, why: str) -> None:
        """The run is over: refuse pending and later requests with ``why``."""
        with self._lock:
            self._closed = why
            pending, self._requests = self._requests, []
        for request in pending:
            request.answer(False, f"nothing to {request.kind}: {why}")
