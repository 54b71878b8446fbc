"""Durations as people read them, for every face that prints the ETA."""

from __future__ import annotations

import math


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


__all__ = ["format_duration"]
