"""The ROS tasks as jobs over a :class:`~navseq.tasks.ros_port.RosPort`, written once
for both ROS.

- ``wait_for``: subscribed until a message meets the condition; a field the message
  does not have fails the task (the path is wrong, waiting cannot help).
- ``snapshot``: the next message, saved into the run folder
  (:mod:`navseq.tasks.snapshots`); the report lists the file.
- ``call``: the service called once it is there; the task succeeds when the answer's
  ``success_field`` is true (none: any answer).
- ``publish``: the topic advertised (latched on ROS 1, transient local on ROS 2, so a
  subscriber that connects a little late still gets it), published once a subscriber
  is connected or after :data:`SUBSCRIBER_WAIT` seconds without one.

Callbacks only store what came; :meth:`poll` (the run's thread) decides and writes
files. Cancelling (timeout, skip, pause, cancel, the run's end) stops the subscription
or drops the pending call: nothing of the task is left behind.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from navseq.mission.tasks import CallTask, PublishTask, SnapshotTask, WaitForTask
from navseq.tasks.base import TaskDone
from navseq.tasks.ros_fields import FieldMissing, condition_met, field_value, shown
from navseq.tasks.ros_port import RosPort, RosPublisher, Stop
from navseq.tasks.snapshots import SnapshotError, save_snapshot, snapshot_of

#: Seconds (wall time) a ``publish`` waits for a first subscriber before publishing anyway.
SUBSCRIBER_WAIT = 2.0


def _never() -> None:
    pass


class _Inbox:
    """The first thing a callback hands over, for the run's thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._value: Any = None
        self._has = False

    def put(self, value: Any) -> bool:
        """Keep ``value`` unless one is kept already; whether it was kept."""
        with self._lock:
            if self._has:
                return False
            self._value, self._has = value, True
            return True

    def take(self) -> tuple[bool, Any]:
        with self._lock:
            return self._has, self._value


class WaitForJob:
    """``wait_for``: until a message on the topic meets the condition."""

    real_time = False

    def __init__(self, task_id: int, task: WaitForTask, port: RosPort) -> None:
        self._task_id = task_id
        self._task = task
        self._seen = 0
        self._end = _Inbox()  # TaskDone, once decided
        self._stop: Stop = _never
        try:
            self._stop = port.subscribe(task.topic, task.type, self._on_message)
        except (ValueError, RuntimeError) as error:
            self._end.put(TaskDone(task_id, False, f"cannot subscribe to {task.topic}: {error}"))

    def _on_message(self, message: Any) -> None:
        task = self._task
        self._seen += 1
        try:
            value = field_value(message, task.field_path)
            met = condition_met(value, task.relation, task.value)
        except (FieldMissing, TypeError, ValueError) as error:
            self._end.put(TaskDone(self._task_id, False, f"{task.topic}: {error}"))
            return
        if met:
            self._end.put(
                TaskDone(
                    self._task_id,
                    True,
                    f"{task.topic} {task.field_path} = {shown(value)} "
                    f"({task.relation} {task.value!r}; message {self._seen})",
                )
            )

    def poll(self, now: float) -> TaskDone | None:
        has, done = self._end.take()
        if not has:
            return None
        self.cancel()
        result: TaskDone = done
        return result

    def cancel(self) -> None:
        stop, self._stop = self._stop, _never
        stop()


class SnapshotJob:
    """``snapshot``: the next message on the topic, saved into the run folder."""

    real_time = False

    def __init__(
        self,
        task_id: int,
        task: SnapshotTask,
        port: RosPort,
        folder: Path | None,
        stem: str,
    ) -> None:
        self._task_id = task_id
        self._task = task
        self._port = port
        self._folder = folder
        self._stem = stem
        self._message = _Inbox()
        self._failed: TaskDone | None = None
        self._stop: Stop = _never
        if folder is None:
            self._failed = TaskDone(task_id, False, "no run folder to save the snapshot into")
            return
        try:
            self._stop = port.subscribe(task.topic, task.type, self._keep)
        except (ValueError, RuntimeError) as error:
            self._failed = TaskDone(task_id, False, f"cannot subscribe to {task.topic}: {error}")

    def _keep(self, message: Any) -> None:
        self._message.put(message)  # the first one; later ones are dropped

    def poll(self, now: float) -> TaskDone | None:
        if self._failed is not None:
            return self._failed
        has, message = self._message.take()
        if not has:
            return None
        self.cancel()
        assert self._folder is not None
        task = self._task
        try:
            snapshot = snapshot_of(task.type, message, self._port.to_yaml)
            path = save_snapshot(self._folder, self._stem, snapshot)
        except SnapshotError as error:
            return TaskDone(self._task_id, False, f"{task.topic}: {error}")
        except OSError as error:
            return TaskDone(self._task_id, False, f"cannot save the snapshot: {error}")
        written = path.relative_to(self._folder).as_posix()
        return TaskDone(
            self._task_id, True, f"{snapshot.what} of {task.topic}: {written}", files=(written,)
        )

    def cancel(self) -> None:
        stop, self._stop = self._stop, _never
        stop()


class CallJob:
    """``call``: the service's answer decides."""

    real_time = False

    def __init__(self, task_id: int, task: CallTask, port: RosPort) -> None:
        self._task_id = task_id
        self._task = task
        self._answer = _Inbox()
        self._stop: Stop = _never
        try:
            self._stop = port.call(task.service, task.type, task.request, self._on_answer)
        except (ValueError, RuntimeError) as error:
            self._answer.put((None, f"cannot call {task.service}: {error}"))

    def _on_answer(self, response: Any, error: str | None) -> None:
        self._answer.put((response, error))

    def poll(self, now: float) -> TaskDone | None:
        has, answer = self._answer.take()
        if not has:
            return None
        self.cancel()  # the answer is in: the client goes
        response, error = answer
        if error is not None:
            return TaskDone(self._task_id, False, error)
        return self._judge(response)

    def _judge(self, response: Any) -> TaskDone:
        task = self._task
        said = _said(response)
        if task.success_field is None:
            return TaskDone(self._task_id, True, f"{task.service} answered{said}")
        try:
            value = field_value(response, task.success_field)
        except FieldMissing as error:
            return TaskDone(self._task_id, False, f"{task.service}'s answer: {error}")
        return TaskDone(
            self._task_id,
            bool(value),
            f"{task.service}: {task.success_field} {str(bool(value)).lower()}{said}",
        )

    def cancel(self) -> None:
        stop, self._stop = self._stop, _never
        stop()


def _said(response: Any) -> str:
    """``, message 'ready'``: the answer's ``message`` text (Trigger's), if any."""
    try:
        text = field_value(response, "message")
    except FieldMissing:
        return ""
    if not isinstance(text, str) or not text:
        return ""
    return f", message {text[:200]!r}"


class PublishJob:
    """``publish``: one message, once a subscriber listens or after a short wait."""

    real_time = False

    def __init__(
        self,
        task_id: int,
        task: PublishTask,
        port: RosPort,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._task_id = task_id
        self._task = task
        self._clock = clock
        self._since = clock()
        self._publisher: RosPublisher | None = None
        self._failed: TaskDone | None = None
        try:
            self._publisher = port.advertise(task.topic, task.type)
        except (ValueError, RuntimeError) as error:
            self._failed = TaskDone(task_id, False, f"cannot advertise {task.topic}: {error}")

    def poll(self, now: float) -> TaskDone | None:
        if self._failed is not None:
            return self._failed
        assert self._publisher is not None
        listeners = self._publisher.subscriber_count()
        if listeners == 0 and self._clock() - self._since < SUBSCRIBER_WAIT:
            return None
        try:
            self._publisher.publish(self._task.message)
        except (ValueError, TypeError, AttributeError) as error:
            return TaskDone(
                self._task_id, False, f"the message does not fit {self._task.type}: {error}"
            )
        return TaskDone(
            self._task_id,
            True,
            f"published on {self._task.topic} ({_subscribers(listeners)})",
        )

    def cancel(self) -> None:
        pass  # nothing went out yet; the publisher stays for the run (latched)


def _subscribers(count: int) -> str:
    return "no subscriber yet" if count == 0 else f"{count} subscriber" + ("s" if count > 1 else "")


__all__ = ["SUBSCRIBER_WAIT", "CallJob", "PublishJob", "SnapshotJob", "WaitForJob"]
