"""Where a resumed mission run picks up (built from a journal, consumed by the executor)."""

from __future__ import annotations

from dataclasses import dataclass, field

from navseq.executor.result import WaypointResult


@dataclass(frozen=True)
class ResumePoint:
    """The visit to start at, and what earlier runs of the same mission already did.

    ``loop`` and ``index`` (both 0-based) name the visit that was active when the
    earlier run ended; it is run again from its first attempt. ``done`` holds the
    visits that earlier runs finished (reached or skipped): they are not run again,
    but they appear in the final :class:`~navseq.executor.result.MissionResult`, so
    the report and the exit code describe the whole mission. ``previous_duration``
    is the mission time those runs took (seconds), added to the result's duration.
    """

    loop: int
    index: int
    done: tuple[WaypointResult, ...] = field(default=())
    previous_duration: float = 0.0
