"""What the node's pause / resume / skip / cancel services answer, alike on both ROS.

Each ROS node offers five ``std_srvs`` Trigger services (ROS 1 ``~pause``, ROS 2
``~/pause`` ...). Their answers are decided here:

- once the mission is over for good, every request is refused with why
  ("nothing to pause: the mission has ended (succeeded)");
- ``skip`` is answered at once: refused when no waypoint is underway (filed then, it
  would skip whichever waypoint comes next), else "waypoint N skipped; going on with
  the next one";
- ``pause``, ``resume`` and ``cancel`` are carried out by the mission's thread, which
  answers within one tick; a run that does not answer within
  :data:`SERVICE_ANSWER_WAIT` seconds is said to, and the service returns;
- ``confirm`` answers the ``input`` task waiting for an operator (Nav2's
  InputAtWaypoint), at once: refused when none waits (a confirmation is never kept
  for a later prompt).

How a request waits for its answer is the client library's business: rospy serves each
call on a thread of its own and may block (:meth:`OperatorDesk.answer_blocking`); an
rclpy handler must not hold the node's executor, so it awaits a future woken by
:meth:`OperatorDesk.submit`'s callback and then reads :meth:`OperatorDesk.answer_of`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from navseq.executor.control import MissionControl, OperatorRequest, operator_reason
from navseq.sinks.mission_status import MissionStatus

if TYPE_CHECKING:
    from navseq.tasks.runner import TaskRunner

OPERATOR_SERVICES = ("pause", "resume", "skip", "cancel")
#: The service confirming an ``input`` task (answered by :meth:`OperatorDesk.confirm`).
CONFIRM_SERVICE = "confirm"
SERVICE_ANSWER_WAIT = 5.0  # s of wall time a service waits for the mission's answer

Answer = tuple[bool, str]


class OperatorDesk:
    """Answers the operator services of one node run.

    ``service_name(kind)`` is the service's name as the node offers it (``~cancel``,
    ``~/cancel``): the executor's reasons, and so the logs and status, name it.
    """

    def __init__(
        self,
        control: MissionControl,
        state: MissionStatus,
        service_name: Callable[[str], str],
        tasks: TaskRunner | None = None,
    ) -> None:
        self.control = control
        self.state = state
        self.service_name = service_name
        self.tasks = tasks

    def confirm(self) -> Answer:
        """``confirm``: the ``input`` task waiting now is confirmed; refused when none waits."""
        if self.state.over is not None:
            return False, f"nothing to confirm: {self.state.over}"
        service = self.service_name(CONFIRM_SERVICE)
        if self.tasks is None or not self.tasks.confirm_waiting(f"confirmed by {service}"):
            return False, "no input task is waiting for a confirmation"
        return True, "input confirmed; going on"

    def answer_at_once(self, kind: str) -> Answer | None:
        """The answer when it needs no word from the mission's thread, else None."""
        if self.state.over is not None:
            # Nobody takes requests any more: a request would only be refused.
            return False, f"nothing to {kind}: {self.state.over}"
        if kind != "skip":
            return None
        index = self.state.active_waypoint
        if index is None:
            # Filed now, the request would skip whichever waypoint comes next.
            return False, "no waypoint is underway"
        self.control.request_skip(self._reason("skip"))
        return True, f"waypoint {index + 1} skipped; going on with the next one"

    def submit(self, kind: str, on_answer: Callable[[OperatorRequest], None]) -> OperatorRequest:
        """File ``kind`` for the mission's thread; ``on_answer`` runs once it is answered."""
        return self.control.submit(kind, self._reason(kind), on_answer)

    @staticmethod
    def answer_of(request: OperatorRequest) -> Answer:
        """The service's answer to ``request`` once answered or waited for long enough."""
        if not request.done.is_set():
            return False, (
                f"{request.kind}: the mission did not respond within {SERVICE_ANSWER_WAIT:g} s"
            )
        return request.ok, request.message

    def answer_blocking(self, kind: str) -> Answer:
        """The whole answer, waiting (bounded) on this thread for the mission's."""
        at_once = self.answer_at_once(kind)
        if at_once is not None:
            return at_once
        request = self.submit(kind, lambda _request: None)
        request.done.wait(SERVICE_ANSWER_WAIT)
        return self.answer_of(request)

    def _reason(self, kind: str) -> str:
        return operator_reason(kind, self.service_name(kind))
