"""Shutdown signals while a finished run writes its outputs: counted, not obeyed.

Once the active goal is cancelled, nothing a signal could still stop is worth losing
the report for: an impatient second Ctrl-C, a SIGTERM from a supervisor, or SIGHUP from
a closing terminal must not leave ``report.json`` missing or disagreeing with the exit
status. :class:`DeferredSignals` replaces the handlers of SIGINT, SIGTERM and SIGHUP
with one that only counts; the caller decides what the signals mean afterwards. An
operator who insists (``abort_after`` signals) may abandon a step that may be given up,
such as drawing the picture, never the report: :meth:`DeferredSignals.abortable`.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType
from typing import Any

SHUTDOWN_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class StepAbandoned(Exception):
    """The operator insisted (signalled again) while an abortable step ran."""


class DeferredSignals:
    """Count shutdown signals instead of acting on them, between start() and stop().

    Signal handlers can only be set in the main thread; elsewhere this does nothing
    (and counts nothing). ``received`` lists the signal names in arrival order.
    """

    def __init__(self) -> None:
        self.received: list[str] = []
        self._previous: dict[int, Any] = {}
        self._abort_at: int | None = None

    def start(self) -> DeferredSignals:
        if threading.current_thread() is threading.main_thread() and not self._previous:
            for signum in SHUTDOWN_SIGNALS:
                self._previous[signum] = signal.signal(signum, self._count)
        return self

    def stop(self) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous.clear()

    @contextlib.contextmanager
    def abortable(self, after: int = 2) -> Iterator[None]:
        """Inside, the ``after``-th further signal raises :class:`StepAbandoned`."""
        self._abort_at = len(self.received) + after
        try:
            yield
        finally:
            self._abort_at = None

    def _count(self, signum: int, frame: FrameType | None) -> None:
        self.received.append(signal.Signals(signum).name)
        if self._abort_at is not None and len(self.received) >= self._abort_at:
            self._abort_at = None
            raise StepAbandoned(signal.Signals(signum).name)

    def __enter__(self) -> DeferredSignals:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()


__all__ = ["SHUTDOWN_SIGNALS", "DeferredSignals", "StepAbandoned"]
