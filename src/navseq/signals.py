"""Shutdown signals during a run: the first one stops the robot, later ones are counted.

navseq drives a robot, so SIGINT, SIGTERM and SIGHUP (a closed terminal, a dropped ssh)
must all reach the run and cancel its goal — even where the process was started with
SIGINT ignored, as a background job of a shell script is. But once the run is being
stopped, nothing a signal could still stop is worth losing the report for: an impatient
second Ctrl-C, a supervisor's SIGTERM after a SIGINT, must neither cut the cancel short
nor leave ``report.json`` missing or disagreeing with the exit status.

:class:`SignalGuard` has two phases. *Armed*: SIGINT raises KeyboardInterrupt, SIGTERM
and SIGHUP raise :class:`Terminated`; the handler switches the guard to *deferring*
before it raises, so a second signal that follows at once finds no gap. *Deferring*:
signals are only counted; an operator who insists (signals twice more) may give up a
step that may be given up, such as drawing the picture (:meth:`SignalGuard.abortable`),
never the report. :meth:`SignalGuard.restore` puts the original handlers back.

A signal raised in the middle of a navigator call could leave a goal sent but not yet
recorded as sent: the cancel that follows would then not know it, and the robot would
drive on. :meth:`SignalGuard.held` marks such calls: a signal that arrives inside is
raised as soon as the call is over, with the goal's book in order.
Handlers can only be set in the main thread; elsewhere the guard does nothing, and a
guard made with ``install=False`` never sets any (a run hosted by a library, a fleet or
a worker thread: signals are the host's business there).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType
from typing import Any

SHUTDOWN_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Terminated(BaseException):
    """SIGTERM or SIGHUP ended the run; a BaseException so no ``except Exception`` in a
    sink or navigator swallows it."""

    def __init__(self, signal_name: str = "SIGTERM"):
        super().__init__(signal_name)
        self.signal_name = signal_name


class StepAbandoned(Exception):
    """The operator insisted (signalled again) while an abortable step ran."""


class SignalGuard:
    """The run's handling of SIGINT, SIGTERM and SIGHUP; see the module docstring.

    ``received`` lists the names of the signals that arrived, in order. With
    ``install=False`` the guard touches no handler at all.
    """

    def __init__(self, *, install: bool = True) -> None:
        self.install = install
        self.received: list[str] = []
        self._original: dict[int, Any] = {}
        self._abort_at: int | None = None
        self._armed = False
        self._held: list[int] = []  # signals that came inside a held() block

    def arm(self) -> SignalGuard:
        """From now on a shutdown signal raises (and defers the ones after it)."""
        if self._save_originals():
            self._armed = True
            for signum in SHUTDOWN_SIGNALS:
                signal.signal(signum, self._raise)
        return self

    def defer(self) -> SignalGuard:
        """From now on shutdown signals are only counted."""
        if self._save_originals():
            self._armed = False
            for signum in SHUTDOWN_SIGNALS:
                signal.signal(signum, self._count)
        return self

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """Inside, a shutdown signal waits: it is raised when the block ends (a block
        that raised first keeps its own exception, and the guard then defers)."""
        if not self._armed or not self._save_originals():
            yield
            return
        for signum in SHUTDOWN_SIGNALS:
            signal.signal(signum, self._hold)
        try:
            yield
        except BaseException:
            self.defer()
            raise
        if not self._held:
            self.arm()
            return
        first, self._held = self._held[0], []
        self.defer()
        if first == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(signal.Signals(first).name)

    def restore(self) -> None:
        """Put back the handlers the process had before the guard."""
        for signum, handler in self._original.items():
            if handler is not None:  # None: not set from Python, cannot be put back
                signal.signal(signum, handler)
        self._original.clear()

    @contextlib.contextmanager
    def abortable(self, after: int = 2) -> Iterator[None]:
        """Inside, the ``after``-th further signal raises :class:`StepAbandoned`."""
        self._abort_at = len(self.received) + after
        try:
            yield
        finally:
            self._abort_at = None

    def _save_originals(self) -> bool:
        if not self.install or threading.current_thread() is not threading.main_thread():
            return False
        if not self._original:
            self._original = {signum: signal.getsignal(signum) for signum in SHUTDOWN_SIGNALS}
        return True

    def _raise(self, signum: int, frame: FrameType | None) -> None:
        name = signal.Signals(signum).name
        self.received.append(name)
        self.defer()  # first: a signal right behind this one must not interrupt the stop
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(name)

    def _hold(self, signum: int, frame: FrameType | None) -> None:
        self.received.append(signal.Signals(signum).name)
        self._held.append(signum)

    def _count(self, signum: int, frame: FrameType | None) -> None:
        self.received.append(signal.Signals(signum).name)
        if self._abort_at is not None and len(self.received) >= self._abort_at:
            self._abort_at = None
            raise StepAbandoned(signal.Signals(signum).name)


class StopSignals:
    """SIGINT and SIGTERM only noted, for a process that waits for them (a ROS node kept
    up after its mission): :meth:`wait` returns once one came. Use as a context manager,
    in the main thread; the previous handlers are put back on leaving."""

    def __init__(self) -> None:
        self.received: list[str] = []
        self._came = threading.Event()
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> StopSignals:
        for signum in (signal.SIGINT, signal.SIGTERM):
            self._previous[signum] = signal.signal(signum, self._note)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)

    def wait(self, timeout: float) -> bool:
        """True once a signal came (waits at most ``timeout`` seconds for one)."""
        return self._came.wait(timeout)

    def _note(self, signum: int, frame: FrameType | None) -> None:
        self.received.append(signal.Signals(signum).name)
        self._came.set()


def ignore_until_exit() -> None:
    """Ignore shutdown signals from now on: the process's exit status is decided, and a
    late Ctrl-C must not turn an exit 0 that the report states into a death by SIGINT."""
    if threading.current_thread() is threading.main_thread():
        for signum in SHUTDOWN_SIGNALS:
            signal.signal(signum, signal.SIG_IGN)


__all__ = [
    "SHUTDOWN_SIGNALS",
    "SignalGuard",
    "StepAbandoned",
    "StopSignals",
    "Terminated",
    "ignore_until_exit",
]
