"""A retry's recoveries on Nav2: the behaviour server's ``spin``, ``backup`` and ``wait``
actions, and ``clear_costmaps`` through both costmaps' clear services.

:class:`Nav2Recoveries` is the ``nav2`` navigator's half of
:class:`~navseq.navigators.base.RecoveryRunner`: it sends the behaviour goal
:func:`navseq.navigators.recovery_behaviors.behavior_request` gives (Nav2's default
tree's values: backup at 0.15 m/s, a time allowance), and reports the end as
:class:`~navseq.navigators.base.RecoveryDone` into the navigator's inbox: succeeded, or
the status and the result's ``error_code`` by name (Humble's results have none:
:mod:`navseq.ros2.results`). A goal the server refuses, or a server that is not there,
fails the recovery at once; the executor times out one that never ends. Cancelling
sends the action's cancel, which stops the robot (Nav2's behaviours stop on cancel).

rclpy is used on the session's executor thread only (``in_ros``).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import Point
from nav2_msgs.action import BackUp, Spin, Wait
from rclpy.action import ActionClient
from rclpy.node import Node

from navseq.mission.recovery import Recovery
from navseq.navigators.base import NavEvent, RecoveryDone
from navseq.navigators.recovery_behaviors import BehaviorRequest, behavior_request
from navseq.ros2.messages import duration_msg, terminal_status
from navseq.ros2.results import result_words
from navseq.sim.behaviors import Behavior

_ACTIONS: dict[Behavior, Any] = {Behavior.SPIN: Spin, Behavior.BACKUP: BackUp, Behavior.WAIT: Wait}


def behavior_goal(request: BehaviorRequest) -> Any:
    """The ``nav2_msgs`` goal for ``request`` (fields every release since Humble has)."""
    if request.behavior is Behavior.SPIN:
        return Spin.Goal(
            target_yaw=float(request.target), time_allowance=duration_msg(request.time_allowance)
        )
    if request.behavior is Behavior.BACKUP:
        return BackUp.Goal(
            target=Point(x=float(request.target)),
            speed=float(request.speed),
            time_allowance=duration_msg(request.time_allowance),
        )
    return Wait.Goal(time=duration_msg(request.target))


class Nav2Recoveries:
    """Runs one recovery at a time over Nav2's behaviour actions (see the module docstring).

    ``put`` hands an event to the navigator's inbox; ``clear_costmaps`` is the
    navigator's own (bounded) call of both clear services.
    """

    def __init__(
        self,
        node: Node,
        in_ros: Callable[..., None],
        put: Callable[[NavEvent], None],
        clear_costmaps: Callable[[], None],
    ) -> None:
        self._in_ros = in_ros
        self._put = put
        self._clear_costmaps = clear_costmaps
        self._clients = {
            behavior: ActionClient(node, action, behavior.value)
            for behavior, action in _ACTIONS.items()
        }
        self._lock = threading.Lock()
        self._current: int | None = None  # the recovery whose end is news
        self._handle: Any = None  # its goal handle, once accepted
        self._cancel_asked = False

    def run(self, recovery_id: int, recovery: Recovery) -> None:
        self.cancel()
        request = behavior_request(recovery)
        if request is None:
            self._clear_costmaps()
            self._put(RecoveryDone(recovery_id, True))
            return
        client = self._clients[request.behavior]
        if not client.server_is_ready():
            why = f"no {request.behavior.value} action server (is Nav2's behavior_server up?)"
            self._put(RecoveryDone(recovery_id, False, why))
            return
        with self._lock:
            self._current, self._handle, self._cancel_asked = recovery_id, None, False
        self._in_ros(self._send, recovery_id, client, behavior_goal(request))

    def cancel(self) -> None:
        """Cancel the running behaviour (the robot stops); its end is no news any more."""
        with self._lock:
            handle, self._handle = self._handle, None
            was_running = self._current is not None
            self._current = None
            self._cancel_asked = was_running and handle is None
        if handle is not None:
            self._in_ros(handle.cancel_goal_async)

    def destroy(self) -> None:
        for client in self._clients.values():
            client.destroy()

    # -- on the executor's thread ------------------------------------------------------

    def _send(self, recovery_id: int, client: Any, goal: Any) -> None:
        future = client.send_goal_async(goal)
        future.add_done_callback(lambda done: self._on_response(recovery_id, done))

    def _on_response(self, recovery_id: int, future: Any) -> None:
        error = future.exception()
        handle = None if error is not None else future.result()
        with self._lock:
            current = self._current == recovery_id
            if handle is not None and handle.accepted and not current and self._cancel_asked:
                self._cancel_asked = False
                handle.cancel_goal_async()  # cancelled before Nav2 accepted it
                return
            if not current:
                return
            if handle is None or not handle.accepted:
                self._current = None
                why = f"the goal request failed: {error}" if error else "the goal was rejected"
                self._put(RecoveryDone(recovery_id, False, why))
                return
            self._handle = handle
        handle.get_result_async().add_done_callback(lambda done: self._on_result(recovery_id, done))

    def _on_result(self, recovery_id: int, future: Any) -> None:
        with self._lock:
            if self._current != recovery_id:
                return
            self._current, self._handle = None, None
        error = future.exception()
        if error is not None:
            self._put(RecoveryDone(recovery_id, False, f"no result: {error}"))
            return
        response = future.result()
        status = (terminal_status(response.status) or (None, "UNKNOWN"))[1]
        if status == "SUCCEEDED":
            self._put(RecoveryDone(recovery_id, True))
            return
        words = result_words(response.result)
        self._put(RecoveryDone(recovery_id, False, f"{status}: {words}" if words else status))


__all__ = ["Nav2Recoveries", "behavior_goal"]
