"""Which progress events the journal keeps: the driven path as a thinned polyline.

The executor reports the robot's pose many times a second. The journal keeps what a
resume and a rebuilt picture draw the driven path from, no more: the corners of a
polyline that stays within :data:`PATH_TOLERANCE` of every pose reported. A straight
corridor costs two lines however long it is; a lap of a patrol costs its corners. A
line is also written every :data:`HEARTBEAT` seconds of mission time, however still
the robot (a ``kill -9`` loses at most that much of the run's duration), at every
arrival (so the path reaches each waypoint where the robot was), and whenever the
stack's recovery count changes (Nav2 counts them; the report lists them per attempt).

The polyline is found online, one pose at a time, in constant time and memory per
pose (Williams' cone intersection, the "sleeve" method): from the last pose journaled
(the anchor), every direction in which a straight line passes within the tolerance
of all the poses since is an interval of angles; a pose whose direction falls outside
it (or that comes back towards the anchor) cannot end a straight stretch, so the pose
before it is journaled and becomes the anchor. Every pose not journaled lies within
about the tolerance (at most √2 times it) of the journaled polyline.
"""

from __future__ import annotations

import math

from navseq.executor.events import WaypointProgress

#: How far (m) the journaled path may pass from a pose the robot reported: a cell of
#: a typical map (0.05 m), far below what a picture of a whole mission shows.
PATH_TOLERANCE = 0.05
#: The longest mission time (s) between two journaled progress events.
HEARTBEAT = 30.0


class ProgressThinner:
    """Decides which :class:`WaypointProgress` events to journal (see module doc).

    Offer it every progress event in order: :meth:`offer` returns those to journal now
    (none, one or two); :meth:`flush` returns the latest pose if it is not journaled
    yet (call it before a visit's end is journaled).
    """

    def __init__(self, tolerance: float = PATH_TOLERANCE, heartbeat: float = HEARTBEAT):
        self.tolerance = tolerance
        self.heartbeat = heartbeat
        self._anchor: WaypointProgress | None = None  # the last one journaled
        self._latest: WaypointProgress | None = None  # offered since, not journaled
        self._reset()

    def _reset(self) -> None:
        self._direction: float | None = None  # reference direction of the cone (rad)
        self._low = self._high = 0.0  # the cone, relative to the reference direction
        self._farthest = 0.0  # from the anchor, of the poses since

    def restart(self) -> None:
        """Forget the path so far (a new run segment: its clock starts afresh)."""
        self._anchor = self._latest = None
        self._reset()

    def offer(self, event: WaypointProgress) -> list[WaypointProgress]:
        anchor = self._anchor
        if anchor is None or not math.isfinite(event.x) or not math.isfinite(event.y):
            return self._journal(event)
        kept: list[WaypointProgress] = []
        if self._latest is not None and self._breaks(event):
            kept += self._journal(self._latest)
        self._include(event)
        self._latest = event
        anchor = self._anchor
        assert anchor is not None
        # A resumed run's clock may start again from zero: t < anchor.t journals too.
        # A new recovery count is journaled as it comes: the report counts recoveries.
        if not 0.0 <= event.t - anchor.t < self.heartbeat or event.recoveries != (
            anchor.recoveries
        ):
            kept += self._journal(event)
        return kept

    def flush(self) -> WaypointProgress | None:
        """The latest pose offered, if not journaled yet (it is now the anchor)."""
        latest = self._latest
        if latest is None:
            return None
        self._journal(latest)
        return latest

    def _journal(self, event: WaypointProgress) -> list[WaypointProgress]:
        self._anchor = event
        self._latest = None
        self._reset()
        return [event]

    def _breaks(self, event: WaypointProgress) -> bool:
        """Whether a straight line from the anchor to ``event`` misses a pose since."""
        anchor = self._anchor
        assert anchor is not None
        dx, dy = event.x - anchor.x, event.y - anchor.y
        distance = math.hypot(dx, dy)
        if distance < self._farthest - self.tolerance:
            return True  # it came back: a line ending here would cut off the far poses
        if self._direction is None or distance == 0.0:
            return False
        relative = _wrapped(math.atan2(dy, dx) - self._direction)
        return not self._low <= relative <= self._high

    def _include(self, event: WaypointProgress) -> None:
        """Narrow the cone of directions by ``event`` (it is now a pose to stay near)."""
        anchor = self._anchor
        assert anchor is not None
        dx, dy = event.x - anchor.x, event.y - anchor.y
        distance = math.hypot(dx, dy)
        self._farthest = max(self._farthest, distance)
        if distance <= self.tolerance:
            return  # within the tolerance of the anchor: any line passes near it
        half_width = math.asin(self.tolerance / distance)
        heading = math.atan2(dy, dx)
        if self._direction is None:
            self._direction = heading
            self._low, self._high = -half_width, half_width
            return
        relative = _wrapped(heading - self._direction)
        self._low = max(self._low, relative - half_width)
        self._high = min(self._high, relative + half_width)


def _wrapped(angle: float) -> float:
    """``angle`` in [-π, π)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


__all__ = ["HEARTBEAT", "PATH_TOLERANCE", "ProgressThinner"]
