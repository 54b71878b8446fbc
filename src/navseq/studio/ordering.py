"""The page's Order… as a job: the search runs in its own thread, the page asks how far
it got, and Cancel stops it.

On a 2000 x 2000 map the distances between 400 waypoints spread over it take a minute
of searches; the page waited on one request for all of it, showing only the seconds,
and its Cancel stopped the waiting, not the searches (the cores stayed busy for
everything after). Here the searches report each one done (``navseq plan``'s progress
hooks, :class:`navseq.route.order.OrderProgress`), and a cancelled job stops at the
next one: the searches running finish, the rest are not started; the distances already
measured are kept for the next Order….
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

#: Order jobs kept (their answers asked for once the page polls again).
JOBS_KEPT = 4


class OrderCancelled(Exception):
    """Raised in the ordering thread at its next search once the page cancelled."""


class OrderFailed(Exception):
    """The ordering's error answer (an HTTP status and its JSON), as ``POST /api/order``
    would give it."""

    def __init__(self, status: int, body: dict[str, Any]) -> None:
        super().__init__(body.get("error"))
        self.status = status
        self.body = body


class OrderJob:
    """One Order…: ``work(progress)`` run in a thread, where ``progress`` hears of the
    searches and the solver (:class:`navseq.route.order.OrderProgress`) and raises
    :class:`OrderCancelled` once :meth:`cancel` was called."""

    def __init__(self, number: int, work: Callable[[OrderJob], dict[str, Any]]) -> None:
        self.number = number
        self._work = work
        self._lock = threading.Lock()
        self._cancelled = threading.Event()
        self._began = time.monotonic()
        self.state = "measuring"  # measuring, solving, done, failed, cancelled
        self.searches_done = 0
        self.searches = 0
        self.best: float | None = None  # the solver's best order so far (its cost)
        self.limit_s: float | None = None
        self.answer: dict[str, Any] | None = None
        self.error: tuple[int, dict[str, Any]] | None = None  # (HTTP status, body)
        self.thread = threading.Thread(target=self._run, name=f"navseq-order-{number}", daemon=True)

    def start(self) -> OrderJob:
        self.thread.start()
        return self

    # -- OrderProgress ----------------------------------------------------------------------

    def searching(self, done: int, total: int) -> None:
        with self._lock:
            self.searches_done, self.searches = done, total
        if self._cancelled.is_set():
            raise OrderCancelled

    def solving(self, best: float | None, limit_s: float) -> None:
        # Not raised here: the solver runs in C++ and calls this from there; it ends
        # within its limit (a second) and its answer is then dropped.
        with self._lock:
            self.state = "solving" if self.state == "measuring" else self.state
            self.best, self.limit_s = best, limit_s

    # -- the page's side ---------------------------------------------------------------------

    def cancel(self) -> None:
        self._cancelled.set()
        with self._lock:
            if self.state in ("measuring", "solving"):
                self.state = "cancelled"

    def view(self) -> dict[str, Any]:
        """What the page shows: the state, how far the searches got, the answer."""
        with self._lock:
            view: dict[str, Any] = {
                "job": self.number,
                "state": self.state,
                "elapsed_s": round(time.monotonic() - self._began, 1),
                "searches_done": self.searches_done,
                "searches": self.searches,
            }
            if self.state == "done" and self.answer is not None:
                view.update(self.answer)
            if self.state == "failed" and self.error is not None:
                view["status"], view["failure"] = self.error
            return view

    def _run(self) -> None:
        try:
            answer = self._work(self)
        except OrderCancelled:
            outcome: tuple[str, Any] = ("cancelled", None)
        except OrderFailed as failure:
            outcome = ("failed", (failure.status, failure.body))
        except Exception as error:  # a fault of ours: said to the page, not a hung job
            outcome = ("failed", (500, {"error": f"ordering failed: {error}"}))
        else:
            outcome = ("done", answer)
        with self._lock:
            if self._cancelled.is_set():
                self.state = "cancelled"
            elif outcome[0] == "done":
                self.state, self.answer = "done", outcome[1]
            elif outcome[0] == "failed":
                self.state, self.error = "failed", outcome[1]
            else:
                self.state = "cancelled"


class OrderJobs:
    """The studio's order jobs, by number; a new one cancels the one before (the page
    orders one thing at a time)."""

    def __init__(self) -> None:
        self._jobs: OrderedDict[int, OrderJob] = OrderedDict()
        self._lock = threading.Lock()
        self._count = 0

    def start(self, work: Callable[[OrderJob], dict[str, Any]]) -> OrderJob:
        with self._lock:
            for job in self._jobs.values():
                job.cancel()
            self._count += 1
            job = OrderJob(self._count, work)
            self._jobs[job.number] = job
            while len(self._jobs) > JOBS_KEPT:
                self._jobs.popitem(last=False)
        return job.start()

    def get(self, number: int) -> OrderJob | None:
        with self._lock:
            return self._jobs.get(number)


__all__ = ["JOBS_KEPT", "OrderCancelled", "OrderFailed", "OrderJob", "OrderJobs"]
