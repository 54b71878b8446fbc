"""Where a resumed mission run picks up (built from a journal, consumed by the executor)."""

from __future__ import annotations

from dataclasses import dataclass, field

from navseq.executor.result import VisitLog, WaypointResult


@dataclass(frozen=True)
class ResumePoint:
    """The visit to start at, and what earlier runs of the same mission already did.

    ``loop`` and ``index`` (both 0-based) name the visit that was active when the
    earlier run ended; it is run again from its first attempt. The visits that earlier
    runs finished (reached or skipped) are not run again, but they appear in the final
    :class:`~navseq.executor.result.MissionResult`, so the report and the exit code
    describe the whole mission. They come either as ``earlier``, a visit log (what
    reading a journal folds them into: every visit counted per waypoint, the latest
    kept in full, so that a patrol of weeks resumes in bounded memory; its waypoints
    are relabelled with the mission's), or listed one by one in ``done`` (added after
    ``earlier``'s). ``previous_duration`` is the mission time those runs took
    (seconds), added to the result's duration.
    """

    loop: int
    index: int
    done: tuple[WaypointResult, ...] = field(default=())
    previous_duration: float = 0.0
    earlier: VisitLog | None = None
