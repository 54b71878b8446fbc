"""Where a resumed mission run picks up (built from a journal, consumed by the executor)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from navseq.errors import NavseqError
from navseq.executor.result import TaskResult, VisitLog, WaypointResult
from navseq.mission.model import Mission


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
    (seconds), added to the result's duration. ``tasks_done``: how many of the visit's
    tasks succeeded before (the robot is sent there again, then the task that was
    running at the end runs again and those before it do not).
    """

    loop: int
    index: int
    done: tuple[WaypointResult, ...] = field(default=())
    previous_duration: float = 0.0
    earlier: VisitLog | None = None
    tasks_done: int = 0
    tasks: tuple[TaskResult, ...] = ()  # the visit's task runs before, for its result


def check_resume_point(mission: Mission, resume: ResumePoint) -> None:
    """Refuse a resume point that does not fit ``mission`` (a journal of another mission)."""
    count = len(mission)
    if not 0 <= resume.index < count:
        raise NavseqError(
            f"the journal resumes at waypoint {resume.index + 1}, "
            f"but the mission has only {count} waypoint(s)",
            source=mission.source,
        )
    if resume.loop < 0 or (mission.loops is not None and resume.loop >= mission.loops):
        raise NavseqError(
            f"the journal resumes in loop {resume.loop + 1}, "
            f"but the mission runs {mission.loops} loop(s)",
            source=mission.source,
        )
    if resume.earlier is not None and resume.earlier.waypoint_count != count:
        raise NavseqError(
            f"the journal records a mission of {resume.earlier.waypoint_count} waypoint(s), "
            f"but the mission has {count}",
            source=mission.source,
        )
    for done in resume.done:
        if not 0 <= done.index < count:
            raise NavseqError(
                f"the journal records waypoint {done.index + 1}, "
                f"but the mission has only {count} waypoint(s)",
                source=mission.source,
            )


def visit_log(mission: Mission, resume: ResumePoint | None) -> VisitLog:
    """The visits finished before this run: none, or the earlier runs' (a fresh copy)."""
    log = VisitLog(mission.waypoints, mission.loops)
    if resume is None:
        return log
    if resume.earlier is not None:  # a copy: the point may be used again
        log = resume.earlier.relabelled(mission.waypoints, mission.loops)
    for done in sorted(resume.done, key=lambda v: (v.loop, v.index)):
        log.add(_result_for(mission, done))
    return log


def _result_for(mission: Mission, done: WaypointResult) -> WaypointResult:
    """An earlier run's visit, with the waypoint's details taken from the mission."""
    waypoint = mission.waypoints[done.index]
    return replace(done, name=waypoint.name, x=waypoint.x, y=waypoint.y, yaw_rad=waypoint.yaw_rad)


__all__ = ["ResumePoint", "check_resume_point", "visit_log"]
