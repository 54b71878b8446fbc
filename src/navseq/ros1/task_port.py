"""ROS tasks on ROS 1: :class:`~navseq.tasks.ros_port.RosPort` over rospy.

Types load through ``roslib.message`` (``pkg/Type``); requests and messages are filled
from the mission's mappings by ``genpy.message.fill_message_args`` (as ``rostopic pub``
does); a message's YAML is ``str(message)``. Subscriptions and publishers belong to the
process's node (the navigator's); a service call blocks in rospy, so it runs on a
thread of its own, which drops its answer once the task is cancelled.
"""

from __future__ import annotations

import importlib.util
import io
import struct
import threading
from collections.abc import Callable, Mapping
from typing import Any

import genpy.message
import roslib.message
import rospy

from navseq.tasks.ros_port import Stop, StopSet

#: Bytes rospy reads a message into at once: an image's megabytes in one go (rospy's
#: 64 KiB default takes many reads for one camera frame).
RECEIVE_BUFFER = 1 << 24
#: Seconds between looks for a service that is not there yet (a cancel is seen as soon).
SERVICE_LOOK = 0.2


class Ros1Types:
    """Which types load here: :meth:`type_problem`."""

    def type_problem(self, type_name: str, *, service: bool = False) -> str | None:
        try:
            loaded = _service_class(type_name) if service else _message_class(type_name)
        except ValueError as error:
            return str(error)
        return None if loaded is not None else "not found"

    def fields_problem(
        self, type_name: str, fields: Mapping[str, Any], *, service: bool = False
    ) -> str | None:
        try:
            made = (
                _service_class(type_name)._request_class if service else _message_class(type_name)
            )
            _serialised(_filled(made(), fields))
        except ValueError as error:
            return str(error)
        return None


def ros_types() -> Ros1Types:
    return Ros1Types()


def _message_class(type_name: str) -> Any:
    found = roslib.message.get_message_class(type_name)
    if found is None:
        raise ValueError(_missing(type_name, "msg"))
    return found


def _service_class(type_name: str) -> Any:
    found = roslib.message.get_service_class(type_name)
    if found is None:
        raise ValueError(_missing(type_name, "srv"))
    return found


def _missing(type_name: str, kind: str) -> str:
    """Why ``pkg/Type`` does not load: the package is not there, or has no such type."""
    package, name = type_name.split("/", 1)
    try:
        installed = importlib.util.find_spec(f"{package}.{kind}") is not None
    except (ImportError, ValueError):
        installed = False
    what = "message" if kind == "msg" else "service"
    if installed:
        return f"{package} has no {what} {name}"
    return (
        f"the package {package} is not installed (on Debian: python3-{package.replace('_', '-')})"
    )


def _filled(message: Any, fields: Mapping[str, Any]) -> Any:
    """``message`` with ``fields`` set; ValueError naming what does not fit."""
    try:
        genpy.message.fill_message_args(message, [dict(fields)])
    except (
        genpy.message.MessageException,
        TypeError,
        ValueError,
        AttributeError,
        KeyError,
    ) as error:
        raise ValueError(str(error)) from None
    return message


def _serialised(message: Any) -> bytes:
    """The message's bytes; ValueError when a value is not of its field's type (genpy
    fills fields without looking at their types: serialising does)."""
    buffer = io.BytesIO()
    try:
        message.serialize(buffer)
    except (genpy.SerializationError, struct.error, TypeError, ValueError, AttributeError) as error:
        raise ValueError(f"a value does not fit its field: {error}") from None
    return buffer.getvalue()


class _Publisher:
    def __init__(self, topic: str, message_class: Any) -> None:
        self._class = message_class
        # Latched: a subscriber that connects after the publish still gets the message.
        self.publisher = rospy.Publisher(topic, message_class, queue_size=1, latch=True)

    def subscriber_count(self) -> int:
        return int(self.publisher.get_num_connections())

    def publish(self, fields: Mapping[str, Any]) -> None:
        message = _filled(self._class(), fields)
        _serialised(message)  # a bad value: ValueError here, not rospy's error mid-run
        self.publisher.publish(message)


class Ros1TaskPort(Ros1Types):
    """The ROS exchanges of tasks on this process's rospy node."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._publishers: dict[tuple[str, str], _Publisher] = {}
        self._stops = StopSet()

    def subscribe(self, topic: str, type_name: str, on_message: Callable[[Any], None]) -> Stop:
        subscriber = rospy.Subscriber(
            topic, _message_class(type_name), on_message, buff_size=RECEIVE_BUFFER
        )
        return self._stops.keep(subscriber.unregister)

    def advertise(self, topic: str, type_name: str) -> _Publisher:
        key = (topic, type_name)
        with self._lock:
            if key not in self._publishers:
                self._publishers[key] = _Publisher(topic, _message_class(type_name))
            return self._publishers[key]

    def call(
        self,
        service: str,
        type_name: str,
        fields: Mapping[str, Any],
        on_answer: Callable[[Any, str | None], None],
    ) -> Stop:
        service_class = _service_class(type_name)
        request = _filled(service_class._request_class(), fields)
        dropped = threading.Event()

        def answer(response: Any, error: str | None) -> None:
            if not dropped.is_set():
                on_answer(response, error)

        def call() -> None:
            while not dropped.is_set() and not rospy.is_shutdown():
                try:
                    rospy.wait_for_service(service, timeout=SERVICE_LOOK)
                    break
                except rospy.ROSException:
                    continue  # not there yet: the task's timeout says how long to wait
            if dropped.is_set() or rospy.is_shutdown():
                return
            try:
                response = rospy.ServiceProxy(service, service_class)(request)
            except (rospy.ServiceException, rospy.ROSException, genpy.SerializationError) as error:
                answer(None, f"{service} failed: {error}")
                return
            answer(response, None)

        threading.Thread(target=call, name="navseq-call-task", daemon=True).start()
        return self._stops.keep(dropped.set)

    def to_yaml(self, message: Any) -> str:
        return str(message) + "\n"

    def close(self) -> None:
        with self._lock:
            publishers, self._publishers = list(self._publishers.values()), {}
        self._stops.stop_all()
        for publisher in publishers:
            publisher.publisher.unregister()


__all__ = ["Ros1TaskPort", "Ros1Types", "ros_types"]
