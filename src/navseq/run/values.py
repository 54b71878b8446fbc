"""A run's option values written as text: a pose ``x,y,yaw``, a loop count, a pace.

The command line and a journal's recorded run options are read by the same rules here;
each reader raises ValueError with a message a user can act on (the CLI turns it into
its usage error, a journal into a :class:`~navseq.errors.NavseqError` naming the line).
"""

from __future__ import annotations

import math

from navseq.geometry import Pose2D
from navseq.mission.fields import MAX_COORDINATE, MAX_YAW_DEGREES, normalized_yaw


def pose_from_text(text: str) -> Pose2D:
    """``x,y,yaw`` (metres, metres, degrees — like mission files) as a Pose2D in radians."""
    parts = [part.strip() for part in text.split(",")]
    if len(parts) not in (2, 3):
        raise ValueError(f"expected x,y,yaw (metres, metres, degrees), got {text!r}")
    try:
        values = [float(part) for part in parts]
    except ValueError:
        raise ValueError(
            f"expected numbers x,y,yaw (metres, metres, degrees), got {text!r}"
        ) from None
    if not all(math.isfinite(value) for value in values):
        raise ValueError(f"x,y,yaw must be finite numbers, got {text!r}")
    # The limits of mission files: beyond them map arithmetic overflows.
    if any(abs(value) > MAX_COORDINATE for value in values[:2]):
        raise ValueError(f"x and y must be within ±{MAX_COORDINATE:g} m, got {text!r}")
    yaw_degrees = values[2] if len(values) == 3 else 0.0
    if abs(yaw_degrees) > MAX_YAW_DEGREES:
        raise ValueError(f"yaw must be within ±{MAX_YAW_DEGREES:g} degrees, got {text!r}")
    return Pose2D(values[0], values[1], normalized_yaw(math.radians(yaw_degrees)))


def pose_degrees(pose: Pose2D) -> list[float]:
    """``[x, y, yaw in degrees]``, rounded to the micrometre: how a journal records a pose."""
    return [round(pose.x, 6), round(pose.y, 6), round(math.degrees(pose.yaw), 6)]


def format_pose(pose: Pose2D) -> str:
    """``(1.00, -0.50, 90°)``: a pose as messages show it."""
    return f"({pose.x:.2f}, {pose.y:.2f}, {math.degrees(pose.yaw):.0f}°)"


def loops_from_text(text: str) -> int | None:
    """A loop count >= 1, or ``forever`` (None)."""
    if text.strip().lower() == "forever":
        return None
    try:
        loops = int(text)
    except ValueError:
        raise ValueError(f"expected a whole number >= 1 or 'forever', got {text!r}") from None
    if loops < 1:
        raise ValueError(f"loops must be >= 1 (or 'forever'), got {loops}")
    return loops


def realtime_from_text(text: str) -> float:
    """A real-time factor > 0 (``2``: twice as fast as real time)."""
    try:
        factor = float(text)
    except ValueError:
        raise ValueError(
            f"expected a speed factor such as 1 or 0.5, got {text!r} (its FACTOR is optional: "
            "put MISSION before --realtime, or give one, e.g. --realtime 1)"
        ) from None
    if not (math.isfinite(factor) and factor > 0):
        raise ValueError(f"the factor must be a number above 0, got {text!r}")
    return factor


__all__ = ["format_pose", "loops_from_text", "pose_degrees", "pose_from_text", "realtime_from_text"]
