"""The recoveries a navigator without a behaviour server can still run: ``wait`` on its
own clock and ``clear_costmaps`` through its own call (move_base's ``clear_costmaps``).

move_base has no action per behaviour (its recoveries run inside it, when it decides),
so the ``ros1`` navigator runs these two and refuses ``spin`` and ``backup`` before the
run (``NavigatorKind.recoveries``): nothing drives the robot behind move_base's back.
No ROS here: the clock and the clear call are the navigator's.
"""

from __future__ import annotations

from collections.abc import Callable

from navseq.mission.recovery import Recovery
from navseq.navigators.base import RecoveryDone

#: What :class:`PlainRecoveries` runs.
PLAIN_KINDS = frozenset({"wait", "clear_costmaps"})


class PlainRecoveries:
    """``wait`` and ``clear_costmaps`` for a navigator: its events come from :meth:`poll`."""

    def __init__(self, now: Callable[[], float], clear_costmaps: Callable[[], None]) -> None:
        self._now = now
        self._clear_costmaps = clear_costmaps
        self._ended: list[RecoveryDone] = []
        self._waiting: tuple[int, float] | None = None  # (recovery id, when it ends)

    def run(self, recovery_id: int, recovery: Recovery) -> None:
        self.cancel()
        if recovery.kind == "clear_costmaps":
            self._clear_costmaps()
            self._ended.append(RecoveryDone(recovery_id, True))
        elif recovery.kind == "wait":
            self._waiting = (recovery_id, self._now() + (recovery.amount or 0.0))
        else:  # refused before the run; a navigator of the Python API may still ask
            why = f"{recovery.kind} needs a behaviour server this navigator does not have"
            self._ended.append(RecoveryDone(recovery_id, False, why))

    def cancel(self) -> None:
        self._waiting = None

    def poll(self) -> list[RecoveryDone]:
        """Recoveries that ended since the last call."""
        waiting = self._waiting
        if waiting is not None and self._now() >= waiting[1]:
            self._waiting = None
            self._ended.append(RecoveryDone(waiting[0], True))
        ended, self._ended = self._ended, []
        return ended


__all__ = ["PLAIN_KINDS", "PlainRecoveries"]
