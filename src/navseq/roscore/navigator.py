"""The half of a ROS navigator that does not depend on the client library.

:class:`NavigatorCore` keeps the events for the executor's thread, the tracked goal,
the server watch and the clock rules, and decides what each situation becomes, the
same way on ROS 1 and ROS 2 (the ``ros1`` and ``ros2`` navigators hold one and add
only what actionlib or rclpy needs):

- the clock: :mod:`navseq.roscore.clock` (no valid time yet; time jumping back ends
  the tracked goal as a failed attempt, cancelled);
- a server that vanishes: :mod:`navseq.roscore.server` (``ServerLost``, then
  ``ServerBack`` and a resend by the executor);
- a rejected goal: a failed attempt ``REJECTED``, with the server's words when it gave
  any, else the likely cause (:func:`rejected`); the retry policy decides;
- a cancel never answered (on close: Ctrl-C, SIGTERM, shutdown): waited for at most
  ``cancel_wait`` seconds of wall time, then a warning that the robot may still be
  driving to its goal, and the process goes on ending (a wedged server must not keep
  a stopped mission from exiting; the warning says what the operator must check).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from navseq.navigators.base import REJECTED_STATUS, GoalDone, NavEvent, ServerBack, ServerLost
from navseq.navigators.inbox import EventInbox
from navseq.navigators.plans import PlanMatcher
from navseq.roscore.client import ClientLibrary
from navseq.roscore.clock import (
    CLOCK_JUMP_STATUS,
    ClockJump,
    ClockWatch,
    spin_on_ros_time,
    wait_for_valid_time,
)
from navseq.roscore.goals import GoalBook
from navseq.roscore.server import ServerWatch, server_lost_text

CANCEL_WAIT = 2.0  # s of wall time to wait for the server's answer to a cancel on close
SERVER_POLL = 0.02  # s of wall time between looks for the server at the start
CLOCK_TICK_WAIT = 5.0  # s of wall time for a returned server's clock to tick


def rejected(goal_id: int, server_text: str, likely_cause: str) -> GoalDone:
    """A goal the server refused: a failed attempt ``REJECTED``, alike on both ROS."""
    why = server_text.strip() or likely_cause
    return GoalDone.failed(goal_id, REJECTED_STATUS, f"the server rejected the goal: {why}")


def cancel_unanswered_text(action: str, waited: float) -> str:
    return (
        f"{action} did not answer the cancel of the active goal within {waited:g} s: "
        "the robot may still be driving to it"
    )


class NavigatorCore:
    """What the ``ros1`` and ``ros2`` navigators share; ``client`` is their library's side.

    ``action`` names the server in messages. ``server_present`` / ``server_ready`` and
    ``lost_after`` define the server watch (:class:`~navseq.roscore.server.ServerWatch`).
    ``on_drop`` runs (under the goal book's lock) whenever the tracked goal is dropped
    by the core, for the navigator's own per-goal state.
    """

    def __init__(
        self,
        client: ClientLibrary,
        action: str,
        *,
        lost_after: float,
        cancel_wait: float = CANCEL_WAIT,
        on_drop: Callable[[], None] | None = None,
    ) -> None:
        self.client = client
        self.action = action
        self.cancel_wait = cancel_wait
        self.inbox = EventInbox()  # callbacks leave events here and wake spin()
        self.plans = PlanMatcher()  # a plan is the goal's it ends at (a stale one is not)
        self.book = GoalBook()
        self.watch = ServerWatch(client.server_present, client.server_ready, lost_after)
        self._on_drop = on_drop
        self._clock_watch = ClockWatch()
        self._warned: set[str] = set()

    # -- time ------------------------------------------------------------------------

    def spin(self, seconds: float, has_news: Callable[[], bool]) -> None:
        """Wait ``seconds`` of ROS time or until ``has_news()`` (see :mod:`.clock`)."""
        jump = spin_on_ros_time(
            seconds,
            self._clock_watch,
            self.client.now,
            has_news,
            self.inbox.wait,
            self.client.check_running,
            clock_wakes=self.client.clock_wakes(),
        )
        if jump is not None:
            self.time_jumped_back(jump)

    def time_jumped_back(self, jump: ClockJump) -> None:
        """End the tracked goal as a failed attempt and cancel it (module :mod:`.clock`)."""
        with self.book.lock:
            tracked = self.book.goal_id is not None
        if not tracked:
            # Nothing to fail: the executor's next wait simply runs on the new clock.
            self.client.warn(f"ROS time jumped back {jump.seconds:.1f} s")
            return
        self.client.warn(jump.text)
        self.client.cancel_goal()
        with self.book.lock:
            goal_id = self.book.drop()
            if self._on_drop is not None:
                self._on_drop()
        if goal_id is not None:
            self.inbox.put(GoalDone.failed(goal_id, CLOCK_JUMP_STATUS, jump.text))

    def sending_goal(self) -> None:
        """Look at the clock as a goal goes out. A jump back seen now came before this
        goal, which is stamped and timed on the new clock: it fails nothing (a restarted
        simulator whose server came back gets the goal resent, and that one stands)."""
        jump = self._clock_watch.look(self.client.now())
        if jump is not None:
            self.client.warn(f"ROS time jumped back {jump.seconds:.1f} s")

    def wait_for_valid_time(self, clock_wait: float, how_to_fix: str) -> None:
        wait_for_valid_time(self.client.now, self.client.check_running, clock_wait, how_to_fix)

    # -- the server ------------------------------------------------------------------

    def wait_for_server(self, timeout: float, stopping: Callable[[], bool]) -> bool:
        """Wait (wall time, at most ``timeout``) until the server can take a goal."""
        deadline = time.monotonic() + timeout
        while not self.client.server_ready():
            if time.monotonic() >= deadline or stopping():
                return False
            time.sleep(SERVER_POLL)
        self.watch.found()
        return True

    def check_server(self, why_lost: str) -> list[NavEvent]:
        """``ServerLost`` (the tracked goal dropped: the executor resends) or ``ServerBack``."""
        change = self.watch.check()
        if change == "lost":
            with self.book.lock:
                self.book.drop()
                if self._on_drop is not None:
                    self._on_drop()
            return [ServerLost(server_lost_text(self.action, why_lost))]
        if change == "back":
            self._await_clock_tick()
            return [ServerBack()]
        return []

    def _await_clock_tick(self) -> None:
        """On ``/clock``, wait (wall time, bounded) for the clock to tick once after the
        server came back. A restarted simulator serves its action before its new clock
        runs: a goal resent at once would be stamped on the old clock and failed by the
        jump back that follows. Seen now, the jump fails nothing (no goal is out)."""
        if not self.client.clock_wakes():
            return
        stale = self.client.now()
        deadline = time.monotonic() + CLOCK_TICK_WAIT
        while self.client.now() == stale and time.monotonic() < deadline:
            self.client.check_running()
            time.sleep(SERVER_POLL)
        jump = self._clock_watch.look(self.client.now())
        if jump is not None:
            self.client.warn(f"ROS time jumped back {jump.seconds:.1f} s (the server restarted)")

    def has_news(self) -> bool:
        """An event is queued, or the server was just lost or is back."""
        return self.inbox.has_events() or self.watch.news()

    # -- retries ---------------------------------------------------------------------

    def warn_once(self, key: str, text: str) -> None:
        """Warn ``text`` the first time ``key`` comes up. A clear-costmaps service that
        is missing or silent is said once per run: a warning on every retry would bury
        the rest of the log, and the retry goes out anyway (after a bounded wait)."""
        if key not in self._warned:
            self._warned.add(key)
            self.client.warn(text)

    # -- closing -----------------------------------------------------------------------

    def cancel_and_wait(self) -> bool:
        """Cancel the tracked goal and wait (bounded) for the server's answer; a warning
        when none came. True when answered (or nothing was out)."""
        self.client.cancel_goal()
        if self.book.cancel_answered.wait(self.cancel_wait):
            return True
        self.client.warn(cancel_unanswered_text(self.action, self.cancel_wait))
        return False
