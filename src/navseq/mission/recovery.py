"""Recovery behaviours a retry runs first: the model and the kinds navseq knows.

A waypoint's policy may name recoveries (``recovery: [spin: 90, backup: 0.15, wait: 2,
clear_costmaps]``): after a failed attempt, when another attempt follows, they run in
order before the goal is sent again — what Nav2's recovery subtree does between
re-plans. Each kind is one entry of :data:`RECOVERY_KINDS` (its amount's unit and
limits); the navigators say which kinds they can run (``NavigatorKind.recoveries``), and
pre-flight refuses a mission whose recoveries the chosen navigator cannot run, before
anything moves. Plain data: no I/O here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType


@dataclass(frozen=True)
class RecoveryKind:
    """What one kind of recovery takes: ``unit`` of its amount (None: it takes none),
    the largest magnitude allowed, and whether a negative amount means something."""

    name: str
    unit: str | None
    maximum: float = 0.0
    signed: bool = False
    meaning: str = ""


#: Every recovery kind, by the name mission files write.
RECOVERY_KINDS: Mapping[str, RecoveryKind] = MappingProxyType(
    {
        kind.name: kind
        for kind in (
            RecoveryKind(
                "spin",
                "degrees",
                maximum=360.0,
                signed=True,
                meaning="turn in place by this angle (counter-clockwise; negative: clockwise)",
            ),
            RecoveryKind("backup", "m", maximum=5.0, meaning="drive straight backwards this far"),
            RecoveryKind("wait", "s", maximum=3600.0, meaning="stand still this long"),
            RecoveryKind("clear_costmaps", None, meaning="forget the obstacles the costmaps hold"),
        )
    }
)

#: How long a recovery may take before the executor gives up on it, beyond what its
#: amount needs (a slow robot turning a full circle, a backup blocked by an obstacle).
RECOVERY_TIMEOUT_S = 30.0
#: m/s a backup drives at: Nav2's default trees (``<BackUp backup_speed="0.15"/>``).
BACKUP_SPEED_MPS = 0.15


@dataclass(frozen=True)
class Recovery:
    """One recovery: ``kind`` (a key of :data:`RECOVERY_KINDS`) and its amount in the
    kind's unit (degrees, metres, seconds; None for ``clear_costmaps``)."""

    kind: str
    amount: float | None = None

    def describe(self) -> str:
        """``spin 90°``, ``backup 0.15 m``, ``wait 2 s``, ``clear_costmaps``."""
        if self.amount is None:
            return self.kind
        unit = RECOVERY_KINDS[self.kind].unit
        shown = f"{self.amount:g}"
        return f"{self.kind} {shown}°" if unit == "degrees" else f"{self.kind} {shown} {unit}"

    @property
    def timeout_s(self) -> float:
        """Seconds the executor waits for it to end: what its amount takes (a wait's
        length, a backup's distance at :data:`BACKUP_SPEED_MPS`), plus slack."""
        amount = abs(self.amount or 0.0)
        own = {"wait": amount, "backup": amount / BACKUP_SPEED_MPS}.get(self.kind, 0.0)
        return own + RECOVERY_TIMEOUT_S


__all__ = ["BACKUP_SPEED_MPS", "RECOVERY_KINDS", "RECOVERY_TIMEOUT_S", "Recovery", "RecoveryKind"]
