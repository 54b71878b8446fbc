"""Nav2's behaviour server actions on the ROS 2 simulator node: spin, backup,
drive_on_heading, wait and assisted_teleop (``nav2_msgs/action/...``), as nav2_bringup
names them, and assisted teleop's two topics: ``cmd_vel_teleop``
(``geometry_msgs/Twist``, the operator's command) and ``preempt_teleop``
(``std_msgs/Empty``, the operator is done), both with the system default QoS as Nav2's.

The rules are :class:`navseq.sim.behaviors.BehaviorServer`'s (the stand-in steps it with
the robot); this module only translates goals, feedback (every cycle: radians turned,
metres driven, time left, time run) and results (``total_elapsed_time``, ``error_code`` — the
action's own constant for the error's name — and, as in Nav2, no ``error_msg``).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import Twist
from nav2_msgs.action import AssistedTeleop, BackUp, DriveOnHeading, Spin, Wait
from rclpy.node import Node
from rclpy.qos import qos_profile_system_default
from std_msgs.msg import Empty

from navseq.ros2.lifecycle import Nav2Lifecycle
from navseq.ros2.messages import duration_msg, finish_goal
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.behaviors import Behavior, BehaviorEnding, BehaviorGoal

#: Wall seconds between two feedback messages (Nav2's behaviours publish every cycle, 10 Hz).
FEEDBACK_PERIOD = 0.1

_ACTIONS: dict[Behavior, Any] = {
    Behavior.SPIN: Spin,
    Behavior.BACKUP: BackUp,
    Behavior.DRIVE_ON_HEADING: DriveOnHeading,
    Behavior.WAIT: Wait,
    Behavior.ASSISTED_TELEOP: AssistedTeleop,
}


class BehaviorActions:
    """The behaviour action servers on ``node``, acting on ``standin`` under ``lock``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        lifecycle: Nav2Lifecycle,
    ) -> None:
        self._node = node
        self._standin = standin
        self._lock = lock
        self._log = node.get_logger()
        self.servers = lifecycle.action_servers(
            node,
            group,
            self._log.info,
            [
                (action, behavior.value, self._executor(behavior, action))
                for behavior, action in _ACTIONS.items()
            ],
        )
        node.create_subscription(
            Twist,
            "cmd_vel_teleop",
            self._on_teleop,
            qos_profile_system_default,
            callback_group=group,
        )
        node.create_subscription(
            Empty,
            "preempt_teleop",
            self._on_preempt_teleop,
            qos_profile_system_default,
            callback_group=group,
        )

    def _on_teleop(self, message: Twist) -> None:
        with self._lock:
            self._standin.behaviors.teleop(float(message.linear.x), float(message.angular.z))

    def _on_preempt_teleop(self, _message: Empty) -> None:
        with self._lock:
            self._standin.behaviors.preempt_teleop()

    def _executor(self, behavior: Behavior, action: Any) -> Callable[[Any], Any]:
        return lambda handle: self._execute(handle, behavior, action)

    def _execute(self, handle: Any, behavior: Behavior, action: Any) -> Any:
        with self._lock:
            goal = self._start(behavior, handle.request)
        self._log.info(f"Running {behavior.value}")
        feedback = action.Feedback()
        while not goal.done.wait(FEEDBACK_PERIOD):
            if handle.is_cancel_requested:
                with self._lock:
                    self._standin.behaviors.cancel(goal, self._standin.time)
                break
            _set_feedback(feedback, behavior, goal.progress)
            handle.publish_feedback(feedback)
        ending = goal.ending
        assert ending is not None
        return self._result(handle, action, behavior, ending)

    def _start(self, behavior: Behavior, request: Any) -> BehaviorGoal:
        server, now = self._standin.behaviors, self._standin.time
        if behavior is Behavior.SPIN:
            allowance = _seconds(request.time_allowance)
            return server.spin(now, float(request.target_yaw), allowance)
        if behavior is Behavior.WAIT:
            return server.wait(now, _seconds(request.time))
        if behavior is Behavior.ASSISTED_TELEOP:
            return server.assisted_teleop(now, _seconds(request.time_allowance))
        target = (float(request.target.x), float(request.target.y), float(request.target.z))
        allowance = _seconds(request.time_allowance)
        return server.drive(behavior, now, target, float(request.speed), allowance)

    def _result(self, handle: Any, action: Any, behavior: Behavior, ending: BehaviorEnding) -> Any:
        result = action.Result()
        result.total_elapsed_time = duration_msg(ending.elapsed)
        if ending.error:
            result.error_code = int(getattr(action.Result, ending.error))
        if ending.log:
            self._log.warning(f"{behavior.value}: {ending.log}")
        status = finish_goal(handle, ending.outcome.value)
        if status == "SUCCEEDED":
            self._log.info(f"{behavior.value} completed successfully")
        elif status == "ABORTED":
            self._log.warning(f"{behavior.value} failed")
        return result


def _set_feedback(feedback: Any, behavior: Behavior, progress: float) -> None:
    if behavior is Behavior.SPIN:
        feedback.angular_distance_traveled = float(progress)
    elif behavior is Behavior.WAIT:
        feedback.time_left = duration_msg(progress)
    elif behavior is Behavior.ASSISTED_TELEOP:
        feedback.current_teleop_duration = duration_msg(progress)
    else:
        feedback.distance_traveled = float(progress)


def _seconds(duration: Any) -> float:
    return float(duration.sec) + float(duration.nanosec) * 1e-9


__all__ = ["BehaviorActions"]
