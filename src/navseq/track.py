"""Paths kept for pictures and journals, bounded however long a run lasts.

A patrol must run for days: what a run keeps of the robot's path (for the picture) and
of the planned paths (for the picture and the journal) may not grow with every step.

- :func:`simplify_path` drops the points of a polyline that lie within ``tolerance`` of
  the line through their neighbours (Ramer–Douglas–Peucker): a 600-point plan along two
  corridors becomes a handful of corners, and nothing a picture shows is lost.
- :class:`Track` keeps a driven path: a point once the robot moved ``min_step`` or
  ``min_interval`` seconds passed (so a stop shows as time spent in place); when
  ``max_points`` are held it keeps every other one and doubles its step and interval,
  so its size stays bounded and its spacing even, from the first lap to the last.

Rows are tuples whose item 0 is the time and items 1 and 2 are x and y (``(t, x, y)``);
a row of NaNs is a break between run segments and is always kept.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

import numpy as np

Point = tuple[float, float]


def simplify_path(points: Sequence[Point], tolerance: float) -> tuple[Point, ...]:
    """``points`` without those within ``tolerance`` (m) of the simplified line."""
    return tuple(
        (float(points[i][0]), float(points[i][1])) for i in kept_indices(points, tolerance)
    )


def kept_indices(points: Sequence[Point], tolerance: float) -> list[int]:
    """Indices of the points :func:`simplify_path` keeps, in order (always both ends)."""
    count = len(points)
    if count < 3 or tolerance <= 0.0:
        return list(range(count))
    xy = np.asarray(points, dtype=float)
    keep = np.zeros(count, dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, count - 1)]
    while stack:
        first, last = stack.pop()
        if last - first < 2:
            continue
        start, end = xy[first], xy[last]
        inner = xy[first + 1 : last]
        chord = end - start
        offsets = inner - start
        # Distance to the segment, not to its line: a path that doubles back beyond an
        # end (a turn-around) must keep its far point.
        length_squared = float(chord @ chord)
        along = offsets @ chord / length_squared if length_squared > 0.0 else 0.0 * offsets[:, 0]
        nearest = np.clip(along, 0.0, 1.0)[:, np.newaxis] * chord
        distances = np.hypot(offsets[:, 0] - nearest[:, 0], offsets[:, 1] - nearest[:, 1])
        farthest = int(np.argmax(distances))
        if distances[farthest] > tolerance:
            split = first + 1 + farthest
            keep[split] = True
            stack.append((first, split))
            stack.append((split, last))
    return [int(i) for i in np.flatnonzero(keep)]


class Track:
    """A bounded, evenly thinned record of a driven path (see the module docstring)."""

    def __init__(
        self, min_step: float = 0.01, min_interval: float = 0.5, max_points: int = 50_000
    ) -> None:
        if max_points < 4:
            raise ValueError("a track keeps at least 4 points")
        self.min_step = min_step
        self.min_interval = min_interval
        self.max_points = max_points
        self._rows: list[tuple[float, ...]] = []
        self._last: tuple[float, ...] | None = None  # the last row kept, not a break

    def append(self, row: tuple[float, ...]) -> None:
        if math.isnan(row[1]):  # a segment break
            self._rows.append(row)
            self._last = None
            return
        last = self._last
        if (
            last is not None
            and math.hypot(row[1] - last[1], row[2] - last[2]) < self.min_step
            and row[0] - last[0] < self.min_interval - 1e-9
        ):
            return
        self._rows.append(row)
        self._last = row
        if len(self._rows) >= self.max_points:
            self._halve()

    def _halve(self) -> None:
        """Keep every other point (breaks and the newest point always), double the step."""
        rows = self._rows
        kept = [row for i, row in enumerate(rows) if i % 2 == 0 or math.isnan(row[1])]
        if kept[-1] is not rows[-1]:
            kept.append(rows[-1])
        self._rows = kept
        self.min_step *= 2.0
        self.min_interval *= 2.0

    def __len__(self) -> int:
        return len(self._rows)

    def __iter__(self) -> Iterator[tuple[float, ...]]:
        return iter(self._rows)

    def __getitem__(self, index: int) -> tuple[float, ...]:
        return self._rows[index]

    def rows(self) -> list[tuple[float, ...]]:
        return list(self._rows)


__all__ = ["Track", "kept_indices", "simplify_path"]
