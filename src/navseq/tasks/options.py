"""What a run allows its tasks: a frozen :class:`TaskOptions`, part of the run request."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from navseq.errors import NavseqError

#: Seconds a simulated ROS task takes when ``--simulate-tasks`` gives no time.
DEFAULT_SIMULATED_SECONDS = 1.0


@dataclass(frozen=True)
class TaskOptions:
    """``allow_run``: ``run`` tasks may start programs (``navseq run --allow-run``; a
    mission file must not run programs by itself). ``simulate_ros_s``: on a navigator
    without ROS (the simulator), ROS tasks (wait_for, snapshot, call, publish) are logged
    and succeed after that many seconds (``--simulate-tasks[=SECONDS]``); None refuses
    them there. ``snapshot_folder``: where ``snapshot`` tasks write (into its
    ``snapshots/``) for a run that writes no run folder (a navseq node's
    ``snapshot_dir``); None: the run folder."""

    allow_run: bool = False
    simulate_ros_s: float | None = None
    snapshot_folder: Path | None = None

    def __post_init__(self) -> None:
        seconds = self.simulate_ros_s
        if seconds is not None and not (math.isfinite(seconds) and seconds >= 0):
            raise NavseqError(
                f"must be a number of seconds >= 0, not {seconds}",
                source="TaskOptions.simulate_ros_s",
            )


__all__ = ["DEFAULT_SIMULATED_SECONDS", "TaskOptions"]
