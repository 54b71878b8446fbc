"""A listener that keeps what the report and the picture need from one mission run.

The executor emits events; :class:`RunRecorder` remembers the planned path of every
visit, the robot poses seen in progress events, and how the run ended. It stores
only plain data and never blocks, so it costs nothing noticeable per event.
"""

from __future__ import annotations

import time
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

Path2D = tuple[tuple[float, float], ...]
VisitKey = tuple[int, int]  # (loop, index), both 0-based


@dataclass
class RunRecorder:
    """Collects a run for the report and the picture (call it with every event)."""

    plans: dict[VisitKey, list[Path2D]] = field(default_factory=dict)
    poses: list[tuple[float, float, float, float]] = field(default_factory=list)  # t, x, y, yaw
    started: MissionStarted | None = None
    finished: MissionFinished | None = None
    wall_started: float = field(default_factory=time.time)
    wall_finished: float | None = None
    _loop: int = 0

    def __call__(self, event: MissionEvent) -> None:
        if isinstance(event, WaypointProgress):
            self.poses.append((event.t, event.x, event.y, event.yaw))
        elif isinstance(event, WaypointPlan):
            if event.path:
                self.plans.setdefault((self._loop, event.index), []).append(event.path)
        elif isinstance(event, (WaypointStarted, LoopStarted)):
            self._loop = event.loop
        elif isinstance(event, MissionStarted):
            self.started = event
        elif isinstance(event, MissionFinished):
            self.finished = event
            self.wall_finished = time.time()

    def leg_plans(self) -> list[Path2D]:
        """The first plan of every visit: the path the stack meant to take on each leg."""
        return [paths[0] for _, paths in sorted(self.plans.items()) if paths]

    def trajectory(self) -> list[tuple[float, float, float]]:
        """Robot positions (t, x, y) seen in progress events, oldest first."""
        return [(t, x, y) for t, x, y, _ in self.poses]
