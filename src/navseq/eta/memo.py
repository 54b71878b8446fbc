"""Legs driven on paper, kept: the studio predicts the mission again after every edit.

:func:`~navseq.eta.drive.drive_path` is a pure function of its inputs (the path, the
robot's state at its start, the goal) for one robot model and speed cap, so its answer
for inputs seen before is the one it gave then. After a waypoint is moved, the visits
whose inputs did not change (all but the one or two after the waypoint, as a stopping
leg ends where the robot latches onto its goal whatever came before) are taken from
here instead of being driven again: 500 planned visits took 250 ms on each check.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Sequence
from typing import TYPE_CHECKING

from navseq.eta.drive import DriveModel, DrivenPath, Point, SpeedCap, drive_path

if TYPE_CHECKING:
    from navseq.mission.robot import RobotProfile
    from navseq.route.legs import Legs

#: Legs kept: every planned visit of two loops of the biggest mission predicted, and more.
DRIVES_KEPT = 4096

_Key = tuple[tuple[Point, ...], float | None, float, float | None, float | None, Point | None]


class RememberedDrives:
    """:func:`drive_path` for one robot model and speed cap, answers kept by inputs.

    Called as ``drive_path`` is (its ``model`` and ``speed_cap`` must be this one's,
    :attr:`model` and :attr:`speed_cap`); :func:`~navseq.eta.predict.predict_legs`
    takes it as ``drives``.
    """

    def __init__(
        self, model: DriveModel, speed_cap: SpeedCap | None, capacity: int = DRIVES_KEPT
    ) -> None:
        self.model = model
        self.speed_cap = speed_cap
        self._kept: OrderedDict[_Key, DrivenPath] = OrderedDict()
        self._capacity = capacity
        self._lock = threading.Lock()
        self.driven = 0  # legs driven (not recalled), for tests and benchmarks

    @classmethod
    def on(cls, legs: Legs, robot: RobotProfile) -> RememberedDrives:
        """For ``robot`` on the legs' costmap (its slowdown near obstacles), if any."""
        from navseq.eta.predict import costmap_speed_cap

        model = DriveModel.of(robot)
        costmap = getattr(legs, "costmap", None)
        return cls(model, costmap_speed_cap(costmap, model) if costmap is not None else None)

    def __call__(
        self,
        points: Sequence[Point],
        model: DriveModel,
        *,
        start_heading: float | None,
        start_speed: float = 0.0,
        goal_yaw: float | None = None,
        pass_radius: float | None = None,
        goal: Point | None = None,
        speed_cap: SpeedCap | None = None,
    ) -> DrivenPath:
        if model is not self.model or speed_cap is not self.speed_cap:
            raise ValueError("RememberedDrives called with another model or speed cap")
        key: _Key = (
            tuple((float(x), float(y)) for x, y in points),
            start_heading,
            start_speed,
            goal_yaw,
            pass_radius,
            goal,
        )
        with self._lock:
            kept = self._kept.get(key)
            if kept is not None:
                self._kept.move_to_end(key)
                return kept
        driven = drive_path(
            points,
            model,
            start_heading=start_heading,
            start_speed=start_speed,
            goal_yaw=goal_yaw,
            pass_radius=pass_radius,
            goal=goal,
            speed_cap=speed_cap,
        )
        with self._lock:
            self.driven += 1
            self._kept[key] = driven
            while len(self._kept) > self._capacity:
                self._kept.popitem(last=False)
        return driven


__all__ = ["DRIVES_KEPT", "RememberedDrives"]
