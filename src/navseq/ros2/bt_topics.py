"""bt_navigator's topics on the ROS 2 simulator node: ``behavior_tree_log``
(``nav2_msgs/BehaviorTreeLog``, depth 10, the events of :mod:`navseq.ros2.bt_events`)
and the selectors of nav2_bringup's default trees, ``controller_selector`` and
``planner_selector`` (``std_msgs/String``, subscribed transient local, depth 1, as the
trees' ControllerSelector / PlannerSelector nodes subscribe).

A selection is taken as Nav2 takes it: the trees start with ``FollowPath`` and
``GridBased`` (nav2_bringup's plugin ids) and use whatever was published last. A known
id is logged; an unknown one is logged as a warning, and — as on Nav2, where the
controller or planner server then refuses the id — every ``navigate_to_pose`` /
``navigate_through_poses`` goal (and so every waypoint and docking staging goal) ends
ABORTED with ``INVALID_CONTROLLER`` (101) or ``INVALID_PLANNER`` (201) until a known
id is published.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from nav2_msgs.msg import BehaviorTreeLog, BehaviorTreeStatusChange
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from navseq.ros2.bt_events import TreeLog
from navseq.ros2.messages import time_msg
from navseq.ros2.path_actions import CONTROLLER_IDS, PLANNER_IDS
from navseq.ros2.standin import Ending, Nav2StandIn, Navigator, Outcome

LOG_PERIOD = 0.05  # s of wall time between two looks at the navigators
INVALID_CONTROLLER = 101  # FollowPath INVALID_CONTROLLER
INVALID_PLANNER = 201  # ComputePathToPose INVALID_PLANNER
SELECTOR = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
DEFAULT_CONTROLLER = "FollowPath"
DEFAULT_PLANNER = "GridBased"


class BtTopics:
    """The tree's log and selectors on ``node``; see the module docstring."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        stamp: Callable[[], Any],
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._stamp = stamp
        self._log = node.get_logger()
        self._tree = TreeLog(clock=time.time)
        self.controller = DEFAULT_CONTROLLER
        self.planner = DEFAULT_PLANNER
        self._publisher = node.create_publisher(BehaviorTreeLog, "behavior_tree_log", 10)
        for topic, take in (
            ("controller_selector", self._select_controller),
            ("planner_selector", self._select_planner),
        ):
            node.create_subscription(String, topic, take, SELECTOR, callback_group=group)
        standin.refusal = self._refusal
        node.create_timer(
            LOG_PERIOD,
            self._publish,
            callback_group=group,
            clock=Clock(clock_type=ClockType.STEADY_TIME),
        )

    def _publish(self) -> None:
        with self._lock:
            standin = self._standin
            running = standin.active is not None and standin.active is standin.last_started
            recovery = standin.world.server.recovery_kind if running else None
            events = self._tree.observe(standin.last_started, standin.time, recovery)
        if not events:
            return
        message = BehaviorTreeLog()
        message.timestamp = self._stamp()
        message.event_log = [
            BehaviorTreeStatusChange(
                timestamp=time_msg(event.wall),
                node_name=event.node.name,
                uid=event.node.uid,
                previous_status=event.previous,
                current_status=event.current,
            )
            for event in events
        ]
        self._publisher.publish(message)

    def _select_controller(self, message: String) -> None:
        with self._lock:
            self.controller = message.data
        self._selected("controller_selector", message.data, CONTROLLER_IDS, "controller_server")

    def _select_planner(self, message: String) -> None:
        with self._lock:
            self.planner = message.data
        self._selected("planner_selector", message.data, PLANNER_IDS, "planner_server")

    def _selected(self, topic: str, plugin: str, known: tuple[str, ...], server: str) -> None:
        ids = ", ".join(name for name in known if name)
        if plugin in known:
            self._log.info(f"{topic}: {plugin or 'the default plugin'} selected")
            return
        self._log.warning(
            f"{topic}: {plugin!r} is not a plugin of {server} ({ids}): navigation goals "
            "fail as on Nav2 until a known one is selected"
        )

    def _refusal(self, _navigator: Navigator) -> Ending | None:
        """Called by the stand-in (under the lock) for each navigation goal."""
        if self.planner not in PLANNER_IDS:
            text = (
                f"planner {self.planner} is not a valid planner. Planner names are: "
                f"{DEFAULT_PLANNER}"
            )
            self._log.error(text)
            return Ending(Outcome.ABORTED, INVALID_PLANNER, text)
        if self.controller not in CONTROLLER_IDS:
            text = (
                f"FollowPath called with controller name {self.controller}, which does not "
                f"exist. Available controllers are: {DEFAULT_CONTROLLER} ."
            )
            self._log.error(text)
            return Ending(Outcome.ABORTED, INVALID_CONTROLLER, text)
        return None


__all__ = ["BtTopics"]
