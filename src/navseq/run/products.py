"""A session's report and picture: what they say about the run that ended."""

from __future__ import annotations

import contextlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from navseq.executor.result import MissionResult
    from navseq.navigators.base import Navigator
    from navseq.run.session import Session
    from navseq.sinks.recorder import RunRecorder


def build_run_report(
    session: Session,
    result: MissionResult,
    *,
    files: dict[str, str],
    exit_status: int,
    interrupted: str | None,
    clock: dict[str, float | None],
) -> dict[str, Any]:
    """The report of ``session``'s run, naming ``files`` and stating ``exit_status``."""
    from navseq.mission.part import number_visits
    from navseq.sinks.report import build_report, map_summary

    report = build_report(
        session.mission,
        result,
        exit_code=exit_status,
        navigator=session.navigator_info,
        interrupted=interrupted,
        mission_digest=session.digest,
        map_info=map_summary(session.grid, session.map_path)
        if session.grid is not None and session.map_path is not None
        else None,
        start=session.start,
        start_source=session.start_source,
        files=files,
    )
    number_visits(report, session.part)
    # Not in a report rebuilt from the journal (navseq report): it keeps no wall time.
    report["clock"] = clock
    # The ETA's predictions against the actual end (not in a rebuilt report either).
    estimator = session.eta()
    accuracy = estimator.accuracy() if estimator is not None else None
    if accuracy is not None:
        report["eta"] = accuracy
    return report


def import_picture_modules() -> None:
    """Import what the picture draws with now, before the robot moves, not after.

    matplotlib takes about half a second to import; a run stopped by a signal has
    about two seconds to write its outputs and exit, and should not spend a quarter of
    them there. (Not in a thread alongside the run: a daemon thread still importing
    when a refused run exits can crash the interpreter's shutdown.) A failed import is
    left for the picture itself to report.
    """
    from navseq.sinks.picture.draw import import_drawing_modules

    with contextlib.suppress(ImportError):
        import_drawing_modules()


def picture_png(
    session: Session,
    result: MissionResult,
    navigator: Navigator,
    recorder: RunRecorder,
    interrupted: str | None,
) -> bytes:
    """The PNG of ``session``'s run: map, waypoints, planned legs and the path driven."""
    from navseq.sinks.picture.draw import mission_picture_png

    return mission_picture_png(
        session.mission,
        result,
        grid=session.grid,
        # Where the robot really set out from (the planned start if it never said; a
        # resumed run's picture shows the whole mission, so its planned start too).
        start=session.start
        if session.resume is not None and session.start is not None
        else result.start_pose or session.start,
        plans=recorder.leg_plans(),
        trajectory=picture_trajectory(navigator, recorder),
        interrupted=interrupted,
        robot=session.robot,
    )


def picture_trajectory(
    navigator: Navigator, recorder: RunRecorder
) -> list[tuple[float, float, float]]:
    """The driven path to draw, (mission time, x, y), NaN rows between run segments.

    The simulator records every step of this run; other navigators give only what
    their feedback showed (the recorder's progress events). Either way the segments
    before a resume come from the journal, through the recorder.
    """
    stepped = getattr(navigator, "trajectory", None)
    if not stepped:
        return recorder.trajectory()
    now = [(recorder.mission_time(t), x, y) for t, x, y in stepped]
    return [*recorder.earlier_trajectory(), *now]


__all__ = ["build_run_report", "import_picture_modules", "picture_png", "picture_trajectory"]
