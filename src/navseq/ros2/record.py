"""``navseq run --navigator nav2 --record-topics``: a ROS 2 stack's topics as published.

Each topic is subscribed as soon as the ROS graph says its type (a topic nobody
publishes yet is looked for again every :data:`LOOK` s of wall time), with
``raw=True``: the messages arrive as the publisher serialised them (CDR), whatever
their type, and go into the recording as they are. The schema is the type's full
definition, as ``ros2 bag`` writes it: the type's ``.msg`` file from the sourced ROS 2's
``share/``, then each type it uses after a line of ``=`` and ``MSG: pkg/Type``
(:func:`full_definition`), so the file reads back where that type is not installed.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
from rclpy.qos import qos_profile_sensor_data
from rosidl_runtime_py.utilities import get_message

from navseq.navigators.base import PublishedSink
from navseq.ros2.session import Ros2Session

LOOK = 0.5  # s of wall time between two looks for the topics not yet subscribed
SEPARATOR = "=" * 80
_PRIMITIVES = {
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string", "wstring",
}  # fmt: skip
_BOUNDS = re.compile(r"\[[^\]]*\]|<=[0-9]+")


def msg_text(type_name: str) -> str:
    """The ``.msg`` file of ``pkg/Type`` in the sourced ROS 2; LookupError without one."""
    package, name = type_name.split("/")
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError:
        raise LookupError(f"package {package} is not installed") from None
    path = share / "msg" / f"{name}.msg"
    try:
        return path.read_text()
    except OSError:
        raise LookupError(f"no {path}") from None


def _used_types(package: str, text: str) -> list[str]:
    used = []
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        field_type = _BOUNDS.sub("", line.split()[0])
        if field_type in _PRIMITIVES:
            continue
        used.append(field_type if "/" in field_type else f"{package}/{field_type}")
    return used


def full_definition(type_name: str, text_of: Callable[[str], str] = msg_text) -> str:
    """``pkg/Type``'s definition with every type it uses, as ``ros2msg`` schemas hold it."""
    first = text_of(type_name)
    parts, seen = [first], {type_name}
    todo = _used_types(type_name.split("/")[0], first)
    while todo:
        used = todo.pop(0)
        if used in seen:
            continue
        seen.add(used)
        text = text_of(used)
        parts.append(f"{SEPARATOR}\nMSG: {used}\n{text}")
        todo.extend(_used_types(used.split("/")[0], text))
    return "\n".join(part.rstrip("\n") for part in parts) + "\n"


class TopicTap:
    """Records ``topics`` from ``session``'s node into ``write`` until :meth:`close`.

    ``now`` stamps each message (the clock the stack uses); ``warn`` says once why a
    topic cannot be recorded (its type's definition is not found).
    """

    def __init__(
        self,
        session: Ros2Session,
        topics: Sequence[str],
        write: PublishedSink,
        now: Callable[[], float],
        warn: Callable[[str], None],
    ) -> None:
        self._session = session
        self._node = session.node
        self._write = write
        self._now = now
        self._warn = warn
        self._pending = {self._node.resolve_topic_name(topic): topic for topic in topics}
        self._subscriptions: list[Any] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._look, name="navseq-record-topics", daemon=True)
        self._thread.start()

    def _look(self) -> None:
        while self._pending and not self._stop.is_set() and self._session.ok():
            types = dict(self._node.get_topic_names_and_types())
            for resolved in [name for name in self._pending if types.get(name)]:
                self._subscribe(resolved, types[resolved][0])
            self._stop.wait(LOOK)

    def _subscribe(self, resolved: str, ros_type: str) -> None:
        self._pending.pop(resolved)
        type_name = ros_type.replace("/msg/", "/")
        try:
            definition = full_definition(type_name)
            message_class = get_message(ros_type)
        except (LookupError, ValueError, ModuleNotFoundError, AttributeError) as error:
            self._warn(f"--record-topics: {resolved} ({type_name}) is not recorded: {error}")
            return

        def record(data: bytes) -> None:
            self._write(resolved, type_name, definition, bytes(data), self._now())

        self._subscriptions.append(
            self._node.create_subscription(
                message_class, resolved, record, qos_profile_sensor_data, raw=True
            )
        )

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2 * LOOK)
        for subscription in self._subscriptions:
            self._session.call_soon(self._node.destroy_subscription, subscription)
        self._subscriptions = []


__all__ = ["LOOK", "TopicTap", "full_definition", "msg_text"]
