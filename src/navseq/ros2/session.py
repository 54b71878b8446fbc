"""One rclpy node with an executor spinning it on a thread of its own.

The ``nav2`` navigator needs a node to talk to Nav2; the ROS 2 ``navseq_node`` also
needs one, for its parameters, topics and services, and wants them all on *one* node
(``/navseq``), as a ROS user expects from ``ros2 node info``. So the node lives here and
both use it: :class:`~navseq.ros2.navigator.Nav2Navigator` makes a session of its own
when given none (``navseq run --navigator nav2``) and otherwise only adds its clients
and subscriptions to the node it is handed.

rclpy is initialised in a context of the session's own, without rclpy's signal
handlers: navseq's runner turns SIGINT/SIGTERM into a cancel of the active goal, and
rclpy's handlers would shut the context down before that cancel could go out.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Sequence
from typing import Any

import rclpy
from rclpy.executors import (
    ExternalShutdownException,
    ShutdownException,
    SingleThreadedExecutor,
)
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions

SHUTDOWN_WAIT = 2.0  # s of wall time for the executor thread to end


class Ros2Session:
    """A context, one node in it, and a single-threaded executor spinning on a thread.

    ``args``: the process's command line, so that ``--ros-args -p name:=value -r
    __ns:=/robot1`` reach the node (None: none of it). ``any_parameter``: accept every
    parameter given on the command line or in a params file without declaring it first,
    as ROS 1's parameter server did (the node reads them with
    :meth:`given_parameters`).
    """

    def __init__(
        self,
        node_name: str,
        *,
        namespace: str | None = None,
        args: Sequence[str] | None = None,
        parameter_overrides: Sequence[Parameter] = (),
        any_parameter: bool = False,
        thread_name: str = "navseq-ros2",
    ) -> None:
        self.context = rclpy.Context()
        rclpy.init(
            args=list(args) if args is not None else None,
            context=self.context,
            signal_handler_options=SignalHandlerOptions.NO,
        )
        try:
            self.node = Node(
                node_name,
                namespace=namespace or None,
                context=self.context,
                parameter_overrides=list(parameter_overrides),
                allow_undeclared_parameters=any_parameter,
                automatically_declare_parameters_from_overrides=any_parameter,
            )
        except BaseException:
            rclpy.try_shutdown(context=self.context)
            raise
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._closed = False
        self._thread = threading.Thread(target=self._spin, name=thread_name, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        spin_until_shutdown(self.executor, lambda: self._closed)

    def call_soon(self, callback: Callable[..., Any], *args: Any) -> None:
        """Run ``callback(*args)`` on the executor's thread (rclpy is not used from two)."""
        if not self._closed:
            self.executor.create_task(callback, *args)

    def ok(self) -> bool:
        return self.context.ok()

    def given_parameters(self) -> dict[str, Parameter]:
        """Parameters given to the node from outside (command line, params file, launch).

        rclpy's own ``use_sim_time`` is left out unless it was given: it is declared on
        every node, so its mere presence says nothing.
        """
        overrides: dict[str, Parameter] = dict(getattr(self.node, "_parameter_overrides", {}))
        return {name: self.node.get_parameter(name) for name in overrides}

    def close(self, *entities: Any) -> None:
        """Stop the executor, destroy ``entities`` (action clients: a node does not
        destroy them) and the node, shut the context down (idempotent). Nothing is
        destroyed while the executor still spins: its next wait would use it."""
        if self._closed:
            return
        self._closed = True
        self.executor.shutdown(timeout_sec=SHUTDOWN_WAIT)
        self._thread.join(timeout=SHUTDOWN_WAIT)
        for entity in entities:
            with contextlib.suppress(Exception):
                entity.destroy()
        with contextlib.suppress(Exception):
            self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def spin_until_shutdown(executor: Any, closing: Callable[[], bool]) -> None:
    """Spin ``executor`` until it is shut down. Once ``closing()`` says the owner is
    shutting it down, an error from a callback still in flight meeting a handle already
    destroyed (rclpy's ``InvalidHandle`` and the like) is part of going away, not a fault
    to print as a thread's traceback."""
    try:
        executor.spin()
    except (ExternalShutdownException, ShutdownException):
        pass
    except Exception:
        if not closing():
            raise
