"""Durations as people read them, for every face that prints the ETA."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from navseq.eta.predict import MissionPrediction


def format_duration(seconds: float | None) -> str:
    """``1 min 23 s`` / ``45 s`` / ``2 h 05 min``; ``-`` for no figure."""
    if seconds is None or not math.isfinite(seconds):
        return "-"
    whole = round(seconds)
    if whole < 60:
        return f"{whole} s"
    if whole < 3600:
        return f"{whole // 60} min {whole % 60:02d} s"
    return f"{whole // 3600} h {whole % 3600 // 60:02d} min"


def prediction_lines(prediction: MissionPrediction, *, has_start: bool) -> list[str]:
    """What ``navseq plan`` and ``navseq validate`` say about how long the mission takes."""
    notes = []
    if not has_start:
        notes.append("from the first waypoint: the mission has no start:")
    if not prediction.planned:
        notes.append("legs with no path left out")
    if prediction.paced:
        notes.append(
            f"the last {prediction.paced} legs at the pace of the first "
            f"{len(prediction.first_loop) - prediction.paced}, not planned"
        )
    note = f" ({'; '.join(notes)})" if notes else ""
    if prediction.loops is None:
        return [
            f"expected duration: each loop ~{format_duration(prediction.loop_expected_s)}, "
            f"the first ~{format_duration(sum(v.expected_s for v in prediction.first_loop))}"
            f" (loops forever){note}"
        ]
    return [
        f"expected duration: ~{format_duration(prediction.expected_s)}{note}",
        f"upper bound: {format_duration(prediction.upper_s)} (every task at its timeout; "
        "retries and recovery behaviours are not bounded)",
    ]


__all__ = ["format_duration", "prediction_lines"]
