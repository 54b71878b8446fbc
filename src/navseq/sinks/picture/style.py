"""How the mission picture looks: outcome colours, sizes, the layout's inches, budgets.

Shared by the modules that draw the picture (:mod:`navseq.sinks.picture.draw` and its
helpers), so that a colour or a size is said once.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np


class Status(str, enum.Enum):
    """What a waypoint's marker says about it (one per waypoint, over all its visits)."""

    REACHED = "reached"
    SKIPPED = "skipped"
    FAILED = "failed"
    INTERRUPTED = "interrupted"  # its only visits were cut short by a signal or crash
    NOT_RUN = "not_run"


STATUS_COLOURS = {
    Status.REACHED: "#2ca02c",
    Status.SKIPPED: "#ff8c00",
    Status.FAILED: "#d62728",
    Status.INTERRUPTED: "#e7298a",
    Status.NOT_RUN: "#8c8c8c",
}
STATUS_LABELS = {
    Status.REACHED: "reached",
    Status.SKIPPED: "skipped (went on)",
    Status.FAILED: "failed (stopped)",
    Status.INTERRUPTED: "interrupted",
    Status.NOT_RUN: "not run",
}
STATUSES = tuple(Status)
# Markers drawn bottom to top: the ones a reader looks for on top.
DRAW_ORDER = (Status.NOT_RUN, Status.REACHED, Status.SKIPPED, Status.INTERRUPTED, Status.FAILED)
PLAN_COLOUR = "#1f5fbf"
START_COLOUR = "#7b2cbf"
MAP_BORDER_COLOUR = "#6b7785"

# Layout, inches: the map axes, then the legend and colour bar in a side panel.
AXES_WIDTH = 7.0
AXES_HEIGHT_RANGE = (4.2, 9.0)
LEFT, GAP, SIDE, RIGHT = 0.75, 0.3, 2.2, 0.1
BOTTOM, TOP = 0.55, 0.6
# Waypoint markers, points.
DISC = 15.0  # a numbered disc
DISC_MIN = 11.0
DOT_RANGE = (2.5, 8.0)
NUMBERED_MAX = 300  # more discs than this are never numbered one by one
DOT_LABELS = 50  # labels shown when the mission is too crowded to label everything
LABEL_FONT = 7.0
LABEL_PAD = 0.15  # fraction of the font size, around a label's text
PLAN_SEGMENTS = 3_000
DOTS_DRAWN = 6_000  # beyond this, dots covering one another are drawn once
OFF_VIEW_DRAWN = 200  # beyond this, triangles on one stretch of the border are drawn once
ALARMING = (Status.FAILED, Status.INTERRUPTED)
COINCIDENT = 0.02  # m: closer than this, two waypoints are one spot
TRAJECTORY_SEGMENTS = 6_000


@dataclass(frozen=True)
class WaypointOutcomes:
    """Per waypoint: its :class:`Status` code and visit counts (arrays of one length).

    ``status[i]`` indexes ``tuple(Status)``; ``reached`` and ``ended`` count the visits
    that reached it and that ran to an end (reached, skipped or failed);
    ``interrupted`` says a visit to it was cut short (the run ended while driving there).
    """

    status: np.ndarray
    reached: np.ndarray
    ended: np.ndarray
    interrupted: np.ndarray

    def __getitem__(self, index: int) -> Status:
        return STATUSES[int(self.status[index])]

    def __len__(self) -> int:
        return len(self.status)

    def count(self, status: Status) -> int:
        return int(np.count_nonzero(self.status == STATUSES.index(status)))
