"""ROS tasks on ROS 2: :class:`~navseq.tasks.ros_port.RosPort` over rclpy.

Types load through ``rosidl_runtime_py.utilities`` (``pkg/Type`` is asked for as
``pkg/msg/Type`` or ``pkg/srv/Type``); requests and messages are filled by
``set_message_fields``; a message's YAML is ``message_to_yaml``. Everything lives on the
navigator's node, which its session's executor already spins: subscriptions take every
publisher (best effort), publishers keep their message for late subscribers (reliable,
transient local), and a call goes out once the service is there; a cancelled task's
subscription and client are destroyed on the executor's thread.
"""

from __future__ import annotations

import importlib.util
import threading
from collections.abc import Callable, Mapping
from typing import Any

from rclpy.qos import (
    DurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)
from rosidl_runtime_py import message_to_yaml, set_message_fields
from rosidl_runtime_py.utilities import get_message, get_service

from navseq.ros2.session import Ros2Session
from navseq.tasks.ros_port import Stop, StopSet

#: Seconds between looks for a service that is not there yet.
SERVICE_LOOK = 0.1
#: What a publish task's publisher offers: reliable, kept for a subscriber that comes late.
PUBLISH_QOS = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def _loaded(type_name: str, *, service: bool) -> Any:
    """The class of ``pkg/Type``; ValueError saying why it does not load."""
    package, _, name = type_name.partition("/")
    full = f"{package}/{'srv' if service else 'msg'}/{name}"
    try:
        return get_service(full) if service else get_message(full)
    except (ValueError, ModuleNotFoundError, AttributeError, ImportError):
        what = "service" if service else "message"
        try:
            installed = importlib.util.find_spec(package) is not None
        except (ImportError, ValueError):
            installed = False
        if installed:
            raise ValueError(f"{package} has no {what} {name}") from None
        raise ValueError(
            f"the package {package} is not in this ROS 2 (is it installed, and sourced?)"
        ) from None


class Ros2Types:
    def type_problem(self, type_name: str, *, service: bool = False) -> str | None:
        try:
            _loaded(type_name, service=service)
        except ValueError as error:
            return str(error)
        return None

    def fields_problem(
        self, type_name: str, fields: Mapping[str, Any], *, service: bool = False
    ) -> str | None:
        try:
            loaded = _loaded(type_name, service=service)
            _filled((loaded.Request if service else loaded)(), fields)
        except ValueError as error:
            return str(error)
        return None


def ros_types() -> Ros2Types:
    return Ros2Types()


def _filled(message: Any, fields: Mapping[str, Any]) -> Any:
    try:
        set_message_fields(message, dict(fields))
    except (AttributeError, TypeError, ValueError, AssertionError) as error:
        raise ValueError(str(error)) from None
    return message


class _Publisher:
    def __init__(self, session: Ros2Session, topic: str, message_class: Any) -> None:
        self._class = message_class
        self.publisher = session.node.create_publisher(message_class, topic, PUBLISH_QOS)

    def subscriber_count(self) -> int:
        return int(self.publisher.get_subscription_count())

    def publish(self, fields: Mapping[str, Any]) -> None:
        self.publisher.publish(_filled(self._class(), fields))


class Ros2TaskPort(Ros2Types):
    """The ROS exchanges of tasks on ``session``'s node."""

    def __init__(self, session: Ros2Session) -> None:
        self._session = session
        self._node = session.node
        self._lock = threading.Lock()
        self._publishers: dict[tuple[str, str], _Publisher] = {}
        self._stops = StopSet()

    def subscribe(self, topic: str, type_name: str, on_message: Callable[[Any], None]) -> Stop:
        subscription = self._node.create_subscription(
            _loaded(type_name, service=False), topic, on_message, qos_profile_sensor_data
        )
        return self._stops.keep(
            lambda: self._session.call_soon(self._node.destroy_subscription, subscription)
        )

    def advertise(self, topic: str, type_name: str) -> _Publisher:
        key = (topic, type_name)
        with self._lock:
            if key not in self._publishers:
                message_class = _loaded(type_name, service=False)
                self._publishers[key] = _Publisher(self._session, topic, message_class)
            return self._publishers[key]

    def call(
        self,
        service: str,
        type_name: str,
        fields: Mapping[str, Any],
        on_answer: Callable[[Any, str | None], None],
    ) -> Stop:
        service_class = _loaded(type_name, service=True)
        request = _filled(service_class.Request(), fields)
        client = self._node.create_client(service_class, service)
        dropped = threading.Event()

        def answered(future: Any) -> None:
            if dropped.is_set():
                return
            error = future.exception()
            if error is not None:
                on_answer(None, f"{service} failed: {error}")
            else:
                on_answer(future.result(), None)

        def send() -> None:
            if not dropped.is_set():
                client.call_async(request).add_done_callback(answered)

        def wait_then_send() -> None:
            while not dropped.is_set() and self._session.ok():
                if client.wait_for_service(timeout_sec=SERVICE_LOOK):
                    self._session.call_soon(send)
                    return

        threading.Thread(target=wait_then_send, name="navseq-call-task", daemon=True).start()

        def stop() -> None:
            dropped.set()
            self._session.call_soon(self._node.destroy_client, client)

        return self._stops.keep(stop)

    def to_yaml(self, message: Any) -> str:
        return str(message_to_yaml(message))

    def close(self) -> None:
        with self._lock:
            publishers, self._publishers = list(self._publishers.values()), {}
        self._stops.stop_all()
        for publisher in publishers:
            self._session.call_soon(self._node.destroy_publisher, publisher.publisher)


__all__ = ["Ros2TaskPort", "Ros2Types", "ros_types"]
