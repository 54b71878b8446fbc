"""A listener that keeps what the report and the picture need from one mission run.

The executor emits events; :class:`RunRecorder` remembers the planned path of every
visit, the robot poses seen in progress events, and how the run ended. It stores
only plain data and never blocks, so it costs nothing noticeable per event.

A run resumed from a journal (``navseq run --resume``) is one mission in several
*segments*, one per process that drove it. :meth:`RunRecorder.from_journal` replays
the earlier segments from the journal, so that the recorder (and the picture drawn
from it) covers the whole mission, not just the part driven after resuming.

Times: events carry the navigator's clock, which starts afresh in every segment (the
simulator counts from zero, ROS time is wall or simulated time). The recorder turns
them into *mission time*: seconds since the first segment started, with every
earlier segment counted for its duration (its first to its last event), the same
way the journal computes ``previous_duration``. So the trajectory's colouring by
mission time continues across a resume instead of starting again.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from dataclasses import dataclass, field

from navseq.executor.events import (
    LoopStarted,
    MissionEvent,
    MissionFinished,
    MissionStarted,
    WaypointPlan,
    WaypointProgress,
    WaypointStarted,
)
from navseq.track import Track

Path2D = tuple[tuple[float, float], ...]
VisitKey = tuple[int, int]  # (loop, index), both 0-based
TimedPoint = tuple[float, float, float]  # mission time t, x, y
#: Separates two run segments in :meth:`RunRecorder.trajectory`: the robot may have
#: been moved (or the simulator restarted at the start pose) between them, so the
#: picture must not draw a line from one to the other.
SEGMENT_BREAK: TimedPoint = (math.nan, math.nan, math.nan)
#: Legs (planned paths) kept for the picture: the latest ones of a long patrol.
MAX_LEGS = 1000


@dataclass
class RunRecorder:
    """Collects a run for the report and the picture (call it with every event).

    What it keeps is bounded however long the run: the positions seen form a
    :class:`~navseq.track.Track` (thinned evenly, a :data:`SEGMENT_BREAK` row between
    run segments), and the legs' plans are the latest :data:`MAX_LEGS`.
    """

    track: Track = field(default_factory=Track)
    started: MissionStarted | None = None  # of the current (last) segment
    finished: MissionFinished | None = None
    wall_started: float = field(default_factory=time.time)
    wall_finished: float | None = None
    _loop: int = 0
    _legs: dict[tuple[VisitKey, int], Path2D] = field(default_factory=dict)  # (visit, segment)
    _segments_started: int = 0
    _time_before: float = 0.0  # mission time of the segments before the current one
    _last_t: float | None = None  # navigator time of the current segment's last event

    @classmethod
    def from_journal(cls, events: Iterable[MissionEvent]) -> RunRecorder:
        """A recorder that has seen these events (e.g. ``journal_events(path)``'s).

        ``read_journal(path).recorder`` is one already: the journal's events replayed.

        Give it to the resumed run as its listener: the picture then shows the path
        driven and the legs planned before the resume as well as after it.
        """
        recorder = cls()
        for event in events:
            recorder(event)
        return recorder

    @property
    def segments(self) -> int:
        """How many run segments (MissionStarted events) the recorder has seen."""
        return self._segments_started

    def mission_time(self, t: float) -> float:
        """The current segment's navigator time ``t`` as mission time (see module doc)."""
        if self.started is None:
            return t
        return self._time_before + t - self.started.t

    def __call__(self, event: MissionEvent) -> None:
        if isinstance(event, MissionStarted):
            self._start_segment(event)
        elif isinstance(event, WaypointProgress):
            self.track.append((self.mission_time(event.t), event.x, event.y))
        elif isinstance(event, WaypointPlan):
            if event.path:
                key = (self._loop, event.index)
                # A visit resumed in a later segment gets its leg again: the robot may
                # have set out from somewhere else.
                self._legs.setdefault((key, self.segments), event.path)
                if len(self._legs) > MAX_LEGS:
                    del self._legs[next(iter(self._legs))]  # the oldest leg
        elif isinstance(event, (WaypointStarted, LoopStarted)):
            self._loop = event.loop
        elif isinstance(event, MissionFinished):
            self.finished = event
            self.wall_finished = time.time()
        self._last_t = event.t

    def _start_segment(self, event: MissionStarted) -> None:
        if self.started is not None:  # a resumed run: close the earlier segment
            if self._last_t is not None:
                self._time_before += max(0.0, self._last_t - self.started.t)
            self.track.append(SEGMENT_BREAK)
            self.finished = None
        self.started = event
        self._segments_started += 1
        self._loop = 0

    def leg_plans(self) -> list[Path2D]:
        """The first plan of every visit in every segment: the path meant for each leg."""
        return [path for _, path in sorted(self._legs.items())]

    def trajectory(self) -> list[TimedPoint]:
        """Robot positions (mission time, x, y) seen in progress events, oldest first.

        A :data:`SEGMENT_BREAK` row (NaNs) separates run segments.
        """
        return [(row[0], row[1], row[2]) for row in self.track]

    def earlier_trajectory(self) -> list[TimedPoint]:
        """:meth:`trajectory` of the segments before the current one, ending in a break.

        Empty for a run that was not resumed. For a navigator that records its own,
        finer trajectory of the current segment (the simulator): put this in front.
        """
        points = self.trajectory()
        breaks = [i for i, row in enumerate(points) if math.isnan(row[1])]
        return points[: breaks[-1] + 1] if breaks else []
