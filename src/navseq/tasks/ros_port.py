"""What a ROS navigator offers the task runner: a small, ROS-free interface.

The ``ros1`` and ``nav2`` navigators each implement :class:`RosPort` over their client
library (:mod:`navseq.ros1.task_port`, :mod:`navseq.ros2.task_port`); the jobs built on
it (:mod:`navseq.tasks.ros_jobs`) are written once. Message and service types are
named ``pkg/Type`` (the mission reader settles ``pkg/msg/Type`` to that); a port turns
the name into its library's class. Messages are passed around as the library's own
objects: the shared code reads them only by attribute (:mod:`navseq.tasks.ros_fields`)
and as YAML (:meth:`RosPort.to_yaml`).

Callbacks (``on_message``, ``on_answer``) run on the library's threads: they only
store what they got, and the jobs look at it from the run's thread.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from typing import Any, Protocol

#: Stops what was started (a subscription, a pending call): no callback follows.
Stop = Callable[[], None]


class RosTypes(Protocol):
    """Which message and service types the running ROS can load."""

    def type_problem(self, type_name: str, *, service: bool = False) -> str | None:
        """None when ``type_name`` (``pkg/Type``) loads, else why not, in a few words."""

    def fields_problem(
        self, type_name: str, fields: Mapping[str, Any], *, service: bool = False
    ) -> str | None:
        """None when a message of ``type_name`` (a service's request, with ``service``)
        takes ``fields``, else why not (a field it lacks, a value of the wrong kind)."""


class RosPublisher(Protocol):
    """One topic advertised for ``publish`` tasks, kept until the port closes."""

    def subscriber_count(self) -> int:
        """How many subscribers are connected now."""

    def publish(self, fields: Mapping[str, Any]) -> None:
        """Publish a message with ``fields``; ValueError when they do not fit the type."""


class RosPort(RosTypes, Protocol):
    """The ROS exchanges tasks need, on the navigator's own node."""

    def subscribe(self, topic: str, type_name: str, on_message: Callable[[Any], None]) -> Stop:
        """Call ``on_message(message)`` for each message on ``topic`` until stopped."""

    def advertise(self, topic: str, type_name: str) -> RosPublisher:
        """A publisher of ``topic``; the same one for the same topic and type."""

    def call(
        self,
        service: str,
        type_name: str,
        fields: Mapping[str, Any],
        on_answer: Callable[[Any, str | None], None],
    ) -> Stop:
        """Call ``service`` with a request of ``fields`` once it is there; then
        ``on_answer(response, None)``, or ``on_answer(None, why)`` when the call failed.
        Stopping drops the call (no answer is waited for)."""

    def to_yaml(self, message: Any) -> str:
        """The message as YAML text (what ``rostopic echo`` / ``ros2 topic echo`` show)."""

    def close(self) -> None:
        """Drop every publisher, subscription and call still open (the run ended)."""


class StopSet:
    """The stops of a port's running jobs (unsubscribe, drop a call), each done at most
    once: by its job, or all together when the port closes. Thread-safe."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._stops: set[Stop] = set()

    def keep(self, stop: Stop) -> Stop:
        """``stop``, made to run at most once and kept until it ran."""
        done = threading.Event()

        def once() -> None:
            with self._lock:
                self._stops.discard(once)
            if not done.is_set():
                done.set()
                stop()

        with self._lock:
            self._stops.add(once)
        return once

    def stop_all(self) -> None:
        with self._lock:
            stops = list(self._stops)
        for stop in stops:
            stop()


def ros_port_of(navigator: object) -> RosPort | None:
    """The navigator's ROS port (``navigator.ros_tasks()``), or None when it has no ROS."""
    offer = getattr(navigator, "ros_tasks", None)
    if offer is None:
        return None
    port: RosPort = offer()
    return port


__all__ = [
    "RosPort",
    "RosPublisher",
    "RosTypes",
    "Stop",
    "StopSet",
    "ros_port_of",
]
