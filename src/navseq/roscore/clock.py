"""Waiting on ROS time: a valid clock first, then spins that a jump back cannot fool.

Both ROS versions run on the navigation stack's clock, which under ``use_sim_time`` is
``/clock`` and may not have started yet (time zero) or may jump back (a simulator was
restarted or reset). The rules here are the same for ROS 1 and ROS 2:

- **No valid time yet**: before the mission, wait (wall time, bounded) for a non-zero
  clock, so no timeout or journal time counts from time 0 (actionlib #137); none in
  time is a :class:`NavseqError` naming ``/clock``. A spin begun while the clock is at
  zero lasts until ``seconds`` after it starts.
- **Time jumps back**: the spin ends at once and says so (:class:`ClockJump`). The
  navigator then ends the tracked goal as a failed attempt (status
  :data:`CLOCK_JUMP_STATUS`) and cancels it: its stamp, and every timeout the executor
  counts for it, are on a clock that no longer holds, and a restarted simulator has
  put the robot back where it started, so the goal's progress means nothing either.
  The waypoint's retry policy decides what comes next, and a retry goes out stamped
  on the new clock. Raising instead (rospy's ``ROSTimeMovedBackwardsException``)
  would end the whole mission with a traceback over a simulator reset; silently
  restarting the wait would leave the goal timing out hundreds of seconds late.
  With no goal out (a dwell, a retry back-off) nothing is failed: the wait simply
  goes on from the new time.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from navseq.errors import NavseqError

CLOCK_WAIT = 10.0  # s of wall time for a valid ROS time once the server is found
SPIN_SLICE = 0.1  # longest wall-time wait in a spin between looks at the clock
VALID_TIME_POLL = 0.02  # s of wall time between looks for a valid clock
#: The status of an attempt ended by the clock jumping back (the stack's statuses are
#: upper case; this one is navseq's).
CLOCK_JUMP_STATUS = "CLOCK_JUMPED_BACK"


@dataclass(frozen=True)
class ClockJump:
    """ROS time went back by ``seconds`` during a spin."""

    seconds: float

    @property
    def text(self) -> str:
        return (
            f"ROS time jumped back {self.seconds:.1f} s (was the simulator restarted?); "
            "the goal is cancelled and its timeouts start again on the new clock"
        )


class ClockWatch:
    """Remembers the latest ROS time seen, so a jump back is noticed whenever it fell:
    also between two spins (the executor's own work runs between them)."""

    def __init__(self) -> None:
        self._latest = 0.0

    def look(self, now: float) -> ClockJump | None:
        """The jump back since the last look, if time went back; ``now`` is remembered."""
        latest, self._latest = self._latest, now
        return ClockJump(latest - now) if now < latest else None


def spin_on_ros_time(
    seconds: float,
    watch: ClockWatch,
    now: Callable[[], float],
    has_news: Callable[[], bool],
    wait: Callable[[float], None],
    check_running: Callable[[], None],
    *,
    clock_wakes: bool,
) -> ClockJump | None:
    """Wait until ``seconds`` of ROS time have passed or ``has_news()``; a jump back
    (seen by ``watch``) ends the wait early and is returned.

    ``wait(wall_seconds)`` sleeps until woken (an event, a ``/clock`` message when
    ``clock_wakes``) or the time is up; ``check_running`` raises on shutdown.
    """
    start = now()
    jump = watch.look(start)
    if jump is not None:
        return jump
    while not has_news():
        current = now()
        jump = watch.look(current)
        if jump is not None:
            return jump
        if start == 0.0:
            start = current  # the simulated clock has not started: wait from when it does
        elif current - start >= seconds:
            return None
        check_running()
        slice_ = SPIN_SLICE
        if not clock_wakes:
            # ROS time runs with wall time here: sleep no longer than what is left.
            slice_ = min(slice_, max(start + seconds - current, 0.0))
        wait(slice_)
    return None


def wait_for_valid_time(
    now: Callable[[], float],
    check_running: Callable[[], None],
    clock_wait: float,
    how_to_fix: str,
) -> None:
    """Block (wall time) until ROS time is not zero; a :class:`NavseqError` after
    ``clock_wait`` seconds. ``how_to_fix`` ends the message (it names the client
    library's own switch for sim time)."""
    deadline = time.monotonic() + clock_wait
    while now() <= 0.0:
        if time.monotonic() >= deadline:
            raise NavseqError(
                f"ROS time is still 0 after {clock_wait:g} s: use_sim_time is on but nothing "
                f"publishes /clock. Start the simulator that drives /clock, or {how_to_fix}",
                source="/clock",
            )
        check_running()
        time.sleep(VALID_TIME_POLL)
