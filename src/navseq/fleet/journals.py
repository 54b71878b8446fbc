"""A fleet run folder's robots as their journals say: for ``--resume`` of a fleet run,
on the embedded simulator (:mod:`navseq.fleet.resume`) and on ROS stacks
(:mod:`navseq.fleet.stack_run`) alike."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from navseq.executor.result import WaypointResult
    from navseq.fleet.model import FleetRobot
    from navseq.fleet.run import Member
    from navseq.geometry import Pose2D
    from navseq.journal.state import JournalState


@dataclass(frozen=True)
class RobotJournal:
    """What one robot's folder says: its journal read, where it was, whether it is done."""

    robot: FleetRobot
    journal: Path
    mission: Path
    state: JournalState
    pose: Pose2D
    done: bool


def robot_journal(folder: Path, robot: FleetRobot) -> RobotJournal:
    """A robot's journal by the one-robot rules: read, its mission unchanged, done or not."""
    from navseq.journal.state import NothingToResume
    from navseq.run.resume import read_resume

    own = folder / robot.name
    journal = own / "journal.jsonl"
    mission = own / "mission.yaml"
    for path in (journal, mission):
        if not path.is_file():
            raise NavseqError(
                "is missing; the fleet run cannot be resumed without every robot's journal "
                "and share (mission.yaml) as the run left them",
                source=str(path),
            )
    try:
        _, _, state = read_resume(journal, mission)
        done = False
    except NothingToResume as finished:
        found = finished.state
        if found is None:
            raise
        state, done = found, True
    return RobotJournal(robot, journal, mission, state, last_pose(journal, robot), done)


def last_pose(journal: Path, robot: FleetRobot) -> Pose2D:
    """Where the journal last saw the robot (it journals the pose at every stop), or its
    fleet start when it never moved."""
    from navseq.executor.events import WaypointProgress
    from navseq.geometry import Pose2D
    from navseq.journal.reader import journal_events

    last = None
    for event in journal_events(journal):
        if isinstance(event, WaypointProgress):
            last = event
    return robot.start if last is None else Pose2D(last.x, last.y, last.yaw)


def done_member(found: RobotJournal, waypoints: int) -> Member:
    """A robot whose share was complete: its figures from its journal; it stays parked."""
    from navseq.fleet.run import FinishedShare, Member

    visits = found.state.visits.held()
    counts = _counts(visits)
    member = Member(found.robot, None, None, waypoints, state="done")
    member.counts.update(counts)
    member.finished = FinishedShare(
        time_s=found.state.previous_duration,
        distance_m=sum(visit.distance_driven for visit in visits),
        all_reached=counts["reached"] == waypoints,
        folder=found.journal.parent,
        visits=tuple(visits),
    )
    member.earlier_trail = trail_of(found.state)
    return member


def earlier_counts(found: RobotJournal) -> dict[str, int]:
    """Reached / skipped / failed before the resume: the visits finished for good (the
    rest run again)."""
    log = found.state.visits.log
    return _counts([] if log is None else log.held())


def _counts(visits: list[WaypointResult]) -> dict[str, int]:
    """Reached / skipped / failed of these visits."""
    counts = {"reached": 0, "skipped": 0, "failed": 0}
    for visit in visits:
        outcome = visit.outcome.value
        if outcome in counts:
            counts[outcome] += 1
    return counts


def trail_of(state: JournalState) -> list[tuple[float, float, float]]:
    """The path the journal recorded (its corners), for the fleet picture."""
    import math

    return [
        (row[0], row[1], row[2]) for row in state.recorder.track.rows() if not math.isnan(row[1])
    ]


__all__ = [
    "RobotJournal",
    "done_member",
    "earlier_counts",
    "last_pose",
    "robot_journal",
    "trail_of",
]
