"""What a face asks the run service for: a frozen :class:`RunRequest`, checked on creation.

A request says which mission, on which navigator (a kind and its typed settings, or a
navigator the face already has), where the outputs go and which of them are wanted,
which run it continues, and how fast the simulator goes. It holds no parsing and no
defaults that need the mission: those are the service's rules
(:func:`navseq.run.session.prepare`). A value that cannot be right whatever the mission
says is refused here, as a :class:`~navseq.errors.NavseqError` naming the field
(``RunRequest.realtime``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from navseq.errors import NavseqError
from navseq.tasks.options import TaskOptions

if TYPE_CHECKING:
    from navseq.geometry import Pose2D
    from navseq.mission.costmap_filters import CostmapFilter
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.navigators.base import Navigator
    from navseq.navigators.settings import NavigatorSettings
    from navseq.sim.occupancy import OccupancyGrid

#: A loop count, or ``"forever"`` for a patrol that runs until it is stopped.
Loops = int | Literal["forever"]


def _refuse(name: str, message: str) -> NavseqError:
    return NavseqError(message, source=f"RunRequest.{name}")


@dataclass(frozen=True)
class UseNavigator:
    """A navigator the face made itself (a ROS node's, already connected), used as it is.

    ``info`` is the report's ``navigator`` section (``kind`` at least); ``grid`` the map
    the picture is drawn on, if the face has one. The session never closes it: its
    owner does (a node keeps its connection after the mission).
    """

    navigator: Navigator
    info: Mapping[str, Any]
    grid: OccupancyGrid | None = None

    def __post_init__(self) -> None:
        if "kind" not in self.info:
            raise _refuse("navigator", "UseNavigator.info needs a 'kind' (e.g. 'ros1')")


@dataclass(frozen=True)
class Outputs:
    """The files a run leaves in its folder.

    ``folder`` None: ``navseq-out/<mission>-<time>/`` (a resume writes beside its
    journal). ``picture`` None: drawn, or as the resumed run did. The journal (what
    ``resume`` continues) needs the mission as a file. ``record``: write the run as
    MCAP (``run.mcap``, :mod:`navseq.sinks.recording`); None: as the mission's
    ``record:`` says, or as the resumed run did. ``record_format``: ``ros2`` (CDR) or
    ``ros1``; None: ``ros2``, or as the resumed run did.
    """

    folder: Path | None = None
    journal: bool = True
    report: bool = True
    picture: bool | None = None
    record: bool | None = None
    record_format: str | None = None
    record_topics: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for topic in self.record_topics:
            if not topic or any(ch.isspace() for ch in topic):
                raise _refuse("outputs", f"record_topics: {topic!r} is no ROS topic name")
        from navseq.sinks.recording.encoding import FORMATS as formats  # no mcap import

        if self.record_format is not None and self.record_format not in formats:
            raise _refuse(
                "outputs",
                f"record_format must be {' or '.join(formats)}, not {self.record_format!r}",
            )


@dataclass(frozen=True)
class RunRequest:
    """One mission run, as a face asks for it; see the module docstring.

    ``mission``: a mission file, or a :class:`~navseq.mission.model.Mission` already
    loaded (then no journal: a resume needs the file); None only with ``resume``, whose
    journal names the file.

    ``navigator``: the kind's typed settings (:mod:`navseq.navigators.settings`, e.g.
    ``Ros1NavigatorSettings(ns="robot1")``), or :class:`UseNavigator`; None: the simulator, or on
    a resume the journal's kind and settings. ``navigator_options``: settings values by
    field name for a kind not known yet (a resume's comes from its journal); a
    journaled field given here or in ``navigator`` wins over the journal's, with a note.

    ``map``, ``start``, ``robot``, ``loops``: None takes the mission's (on a resume the
    journal's). ``first``/``last``/``only``: run a part of the mission (1-based numbers,
    ``only`` names or numbers, comma-separated). ``outputs`` None writes no file at all.
    ``realtime``: the simulator's pace (None: as fast as it goes). ``tasks``: what the
    waypoints' tasks may do (``run`` programs, simulated ROS tasks); not journaled: a
    resume asks again.
    """

    mission: Path | Mission | None = None
    navigator: NavigatorSettings | UseNavigator | None = None
    navigator_options: Mapping[str, Any] = field(default_factory=dict)
    map: Path | None = None
    start: Pose2D | None = None
    robot: str | RobotProfile | None = None
    loops: Loops | None = None
    first: int | None = None
    last: int | None = None
    only: str | None = None
    preflight: bool = True
    outputs: Outputs | None = field(default_factory=Outputs)
    resume: Path | None = None
    realtime: float | None = None
    server_wait: float = 10.0
    tick: float = 0.1
    tasks: TaskOptions = field(default_factory=TaskOptions)
    # Nav2 costmap filters (--keepout, --speed-mask) in place of the mission's filters:;
    # None: the mission's. Not journaled: a resume gives them again.
    filters: tuple[CostmapFilter, ...] | None = None

    def __post_init__(self) -> None:
        if self.mission is None and self.resume is None:
            raise _refuse(
                "mission",
                "no mission given: name the mission file to run (navseq run MISSION), "
                "or the journal of a run to continue (--resume JOURNAL)",
            )
        if self.realtime is not None and not (math.isfinite(self.realtime) and self.realtime > 0):
            raise _refuse("realtime", f"must be a factor above 0, not {self.realtime}")
        if isinstance(self.loops, bool) or not (
            self.loops is None
            or self.loops == "forever"
            or (isinstance(self.loops, int) and self.loops >= 1)
        ):
            raise _refuse("loops", f"must be a whole number >= 1 or 'forever', not {self.loops!r}")
        for name in ("server_wait", "tick"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise _refuse(name, f"must be a number of seconds above 0, not {value}")
        # A face's own navigator (a fleet's robot) may resume too: the face made it as the
        # journal's run had it; the journal's kind and settings are then not used.
        if self.resume is not None and (self.outputs is None or not self.outputs.journal):
            raise _refuse("outputs", "a resume appends to its journal: ask for one")
        wants_journal = self.outputs is not None and self.outputs.journal
        if wants_journal and self.resume is None and not isinstance(self.mission, Path):
            raise _refuse(
                "outputs",
                "a journal names its mission file, for a resume: give the mission as "
                "a file, or ask for no journal (Outputs(journal=False))",
            )

    @property
    def forever(self) -> bool:
        return self.loops == "forever"


__all__ = ["Loops", "Outputs", "RunRequest", "UseNavigator"]
