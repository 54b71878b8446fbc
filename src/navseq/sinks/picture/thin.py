"""Thinning for the mission picture: draw no more than the pixels can show.

A 100 000-waypoint mission, a patrol of a thousand laps or a 16-megapixel map would
make matplotlib draw millions of segments, markers and cells that end up on the same
few pixels, and a run waiting for its picture after a signal must end within seconds.
Everything here is numpy, linear in its input, and returns something whose size is
bounded by the picture's pixel count, not by the mission:

- :func:`thin_segments`: a polyline (with time, NaN rows as breaks) as at most
  ``budget`` segments, merged where they fall on the same pixels; a patrol's laps that
  retrace the same route collapse to one pass coloured by its latest time;
- :func:`coincident_groups`: waypoints that would be drawn on top of one another,
  grouped so that the picture draws one marker with a count instead of hiding them;
- :func:`map_image`: the part of a map the view shows, reduced to about one cell per
  pixel, keeping thin walls (the darkest cell of each block wins).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Grey levels (0 black .. 255 white) of the map image, as in map_server and RViz.
FREE_LEVEL = 255
UNKNOWN_LEVEL = 205  # map_server writes unknown cells as 205
OCCUPIED_LEVEL = 31
#: Coarsest grid (pixels) a path is snapped to; beyond it, segments are sampled.
MAX_STEP = 4.0


def thin_segments(
    points: np.ndarray, values: np.ndarray, pixels_per_unit: float, budget: int = 20_000
) -> tuple[np.ndarray, np.ndarray]:
    """At most ``budget`` segments ``(M, 2, 2)`` of a polyline, and a value for each.

    ``points`` (N, 2) are in world units, ``pixels_per_unit`` converts them to pixels;
    ``values`` (N,) is what colours each segment (e.g. the time of its first point). A
    row with a non-finite coordinate or value breaks the line (no segment crosses it).

    Points are snapped to a grid of ``step`` pixels (1 at first): consecutive points in
    the same cell are dropped, and segments joining the same two cells are drawn once,
    with the value of their latest occurrence (the last lap of a patrol, on top). If
    that still leaves more than ``budget`` segments, the step doubles (up to
    :data:`MAX_STEP`; past it an even sample in time is kept). The segments
    keep the original coordinates of the points kept, so the drawn path is exact to
    within ``step`` pixels; they are returned in order of value, latest last.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    values = np.asarray(values, dtype=float).reshape(-1)
    empty = (np.zeros((0, 2, 2)), np.zeros(0))
    if len(points) < 2:
        return empty
    finite = np.isfinite(points).all(axis=1) & np.isfinite(values)
    # Each maximal run of finite rows is a piece of line of its own.
    run_id = np.cumsum(~finite)
    origin = np.nanmin(np.where(finite[:, None], points, np.nan), axis=0)
    if not np.isfinite(origin).all():
        return empty
    # Pixels, bounded so that cell numbers stay small (what lies that far out is off view).
    scaled = np.clip((points - origin) * pixels_per_unit, -1e6, 1e6)
    # Start at the step that leaves about ``budget`` points on the path's length.
    steps = np.hypot(*np.diff(np.where(finite[:, None], scaled, np.nan), axis=0).T)
    length = float(np.nansum(steps))
    step = min(2.0 ** max(0, math.floor(math.log2(max(length / budget, 1.0)))), MAX_STEP)
    while True:
        cells = np.floor(np.where(finite[:, None], scaled, 0.0) / step).astype(np.int64)
        first, second = _kept_pairs(cells, finite, run_id)
        if len(first) <= budget or step >= MAX_STEP:
            break
        step *= 2.0
    if len(first) == 0:
        return empty
    if len(first) > 4 * budget:
        # Far too many even on the coarsest grid: sample evenly before merging.
        sample = np.linspace(0, len(first) - 1, 4 * budget).round().astype(np.int64)
        first, second = first[sample], second[sample]
    # Unordered cell pairs: a route driven there and back is drawn once.
    low_cell = cells[finite].min(axis=0)
    span = int((cells[finite] - low_cell).max()) + 1
    a = (cells[first, 0] - low_cell[0]) * span + (cells[first, 1] - low_cell[1])
    b = (cells[second, 0] - low_cell[0]) * span + (cells[second, 1] - low_cell[1])
    low, high = np.minimum(a, b), np.maximum(a, b)
    # One integer per pair when it fits (a 1-D unique is far faster than a row-wise one).
    keys = low * (span * span) + high if span < 40_000 else np.stack([low, high], axis=1)
    # Latest occurrence of each pair: unique over the reversed order.
    _, reversed_index = np.unique(keys[::-1], axis=0, return_index=True)
    chosen = len(keys) - 1 - reversed_index
    chosen = chosen[np.argsort(values[first[chosen]], kind="stable")]
    if len(chosen) > budget:
        # A path too long for the pixels even then (a scribble over the whole map):
        # an even sample in time keeps its look and its colours.
        chosen = chosen[np.linspace(0, len(chosen) - 1, budget).round().astype(np.int64)]
    segments = np.stack([points[first[chosen]], points[second[chosen]]], axis=1)
    return segments, values[first[chosen]]


def _kept_pairs(
    cells: np.ndarray, finite: np.ndarray, run_id: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Indices (i, j) of consecutive kept points: each a point entering a new cell."""
    moved = np.ones(len(cells), dtype=bool)
    moved[1:] = (cells[1:] != cells[:-1]).any(axis=1) | ~finite[:-1]
    # The last point of each run is kept too, so that a line ends where the robot stopped.
    last_of_run = np.append(run_id[1:] != run_id[:-1], True)
    kept = np.flatnonzero(finite & (moved | last_of_run))
    if len(kept) < 2:
        return kept[:0], kept[:0]
    first, second = kept[:-1], kept[1:]
    same_run = run_id[first] == run_id[second]
    return first[same_run], second[same_run]


@dataclass(frozen=True)
class Groups:
    """Waypoints drawn as one marker each: ``members[g]`` are the indices of group g.

    ``first`` is the smallest member of each group (whose position the marker takes),
    in increasing order; ``of`` maps every waypoint to its group.
    """

    first: np.ndarray
    of: np.ndarray
    sizes: np.ndarray

    def members(self, group: int) -> np.ndarray:
        return np.flatnonzero(self.of == group)

    def __len__(self) -> int:
        return len(self.first)


def coincident_groups(points: np.ndarray, tolerance: float) -> Groups:
    """Group points (N, 2) closer than about ``tolerance`` (snapped to a grid of that size).

    One sort, no pairwise distances: points in the same grid cell share a marker. Two points just
    either side of a cell border stay apart, which only means two markers that touch.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(points) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return Groups(empty, empty, empty)
    tolerance = max(float(tolerance), 1e-9)
    finite = np.where(np.isfinite(points), points, 0.0)
    cells = np.floor(np.clip((finite - finite.min(axis=0)) / tolerance, 0, 2e9)).astype(np.int64)
    span = int(cells.max()) + 1
    # One integer per cell when it fits: a 1-D unique is far faster than a row-wise one.
    keys = cells[:, 0] * span + cells[:, 1] if span < 3_000_000_000 else cells
    _, first_index, inverse, sizes = np.unique(
        keys, axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    inverse = inverse.reshape(-1)
    # Number the groups in the order of their first waypoint.
    order = np.argsort(first_index, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return Groups(first=first_index[order], of=rank[inverse], sizes=sizes[order])


def occupancy_levels(data: np.ndarray) -> np.ndarray:
    """Grey level (uint8) of occupancy values: 0 free white .. 100 dark, -1 unknown grey."""
    values = np.clip(data.astype(np.int16), 0, 100)
    grey = (FREE_LEVEL - (FREE_LEVEL - OCCUPIED_LEVEL) * values // 100).astype(np.uint8)
    # Only -1 is unknown; other negative values (raw mode) are obstacles to costmap_2d.
    grey[data == -1] = UNKNOWN_LEVEL
    grey[data < -1] = OCCUPIED_LEVEL
    return grey


def map_image(
    data: np.ndarray, rows: slice, cols: slice, cells_per_pixel: float
) -> tuple[np.ndarray, int]:
    """Grey levels of ``data[rows, cols]``, ``factor`` x ``factor`` cells per pixel.

    Returns the image and ``factor`` (1 when the map is no finer than the picture).
    Each block takes its darkest cell, so a one-cell wall survives the reduction.
    """
    crop = data[rows, cols]
    factor = max(1, int(cells_per_pixel))
    if factor == 1:
        return occupancy_levels(crop), 1
    height = -(-crop.shape[0] // factor) * factor
    width = -(-crop.shape[1] // factor) * factor
    # Pad with free cells (255 after levels), so partial blocks at the edge stay right.
    levels = np.full((height, width), FREE_LEVEL, dtype=np.uint8)
    levels[: crop.shape[0], : crop.shape[1]] = occupancy_levels(crop)
    blocks = levels.reshape(height // factor, factor, width // factor, factor)
    return blocks.min(axis=(1, 3)), factor
