"""Which waypoint labels the mission picture shows, and where, so that none collide.

Labels are placed greedily in priority order (the caller's: first, last, failures,
...), each at the first of eight spots around its marker where its box overlaps no
label already placed, no obstacle (markers that must stay visible) and does not
leave the axes. A label that fits nowhere is left out: a picture with 60 readable
labels says more than one with 5000 unreadable ones. Boxes are in display pixels.

:func:`spread_order` orders candidates so that the labels chosen are spread over the
picture (farthest-point sampling) instead of crowding its first corner.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

# Where a label goes around its marker, tried in this order: (dx, dy) unit directions.
_SPOTS = (
    (1.0, -0.6),
    (1.0, 0.6),
    (-1.0, -0.6),
    (-1.0, 0.6),
    (0.0, -1.0),
    (0.0, 1.0),
    (1.0, 0.0),
    (-1.0, 0.0),
)


@dataclass(frozen=True)
class PlacedLabel:
    """A label to draw: ``text`` centred at display pixel ``(x, y)``; ``item`` is the caller's."""

    item: int
    text: str
    x: float
    y: float
    box: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax in pixels
    anchor: tuple[float, float]  # the marker it names (pixels)
    far: bool = False  # not right beside its marker: worth a leader line


@dataclass
class LabelPlacer:
    """Greedy collision-free placement inside ``area`` (xmin, ymin, xmax, ymax pixels).

    ``measure(text)`` gives a text's (width, height) in pixels, padding included.
    """

    area: tuple[float, float, float, float]
    measure: Callable[[str], tuple[float, float]]
    limit: int = 10_000

    def __post_init__(self) -> None:
        self._boxes = np.zeros((0, 4))
        self.placed: list[PlacedLabel] = []

    def block(self, boxes: np.ndarray) -> None:
        """Keep labels off these boxes (N, 4): markers that must stay visible."""
        boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
        self._boxes = np.concatenate([self._boxes, boxes])

    def free(self, box: tuple[float, float, float, float]) -> bool:
        xmin, ymin, xmax, ymax = box
        ax0, ay0, ax1, ay1 = self.area
        if xmin < ax0 or ymin < ay0 or xmax > ax1 or ymax > ay1:
            return False
        b = self._boxes
        if len(b) == 0:
            return True
        overlaps = (b[:, 0] < xmax) & (b[:, 2] > xmin) & (b[:, 1] < ymax) & (b[:, 3] > ymin)
        return not bool(overlaps.any())

    def place(self, item: int, text: str, x: float, y: float, clearance: float) -> bool:
        """Put ``text`` beside the marker at pixel (x, y) of radius ``clearance``, if room."""
        if len(self.placed) >= self.limit:
            return False
        width, height = self.measure(text)
        # Right beside the marker first; a little further out if a neighbour is in the way.
        for ring, distance in enumerate(
            (clearance, clearance + 0.6 * height, clearance + 1.5 * height)
        ):
            for dx, dy in _SPOTS:
                cx = x + dx * (distance + width / 2.0)
                cy = y + dy * (distance + height / 2.0)
                box = (cx - width / 2.0, cy - height / 2.0, cx + width / 2.0, cy + height / 2.0)
                if self.free(box):
                    self.placed.append(PlacedLabel(item, text, cx, cy, box, (x, y), ring > 0))
                    self._boxes = np.concatenate([self._boxes, np.array([box])])
                    return True
        return False


def spread_order(
    points: np.ndarray, candidates: Sequence[int], taken: np.ndarray, count: int
) -> list[int]:
    """Up to ``count`` of ``candidates`` (indices into ``points``), each farthest from the rest.

    ``taken`` (K, 2) are points already labelled: the first candidate chosen is the
    one farthest from them (or the first candidate when there are none). Linear in
    the number of candidates per pick.
    """
    index = np.asarray(candidates, dtype=np.int64)
    if len(index) == 0 or count <= 0:
        return []
    xy = np.asarray(points, dtype=float)[index]
    nearest = np.full(len(index), np.inf)
    for tx, ty in np.asarray(taken, dtype=float).reshape(-1, 2):
        nearest = np.minimum(nearest, np.hypot(xy[:, 0] - tx, xy[:, 1] - ty))
    chosen: list[int] = []
    # With nothing labelled yet, start from the first candidate (the caller's order).
    pick = int(np.argmax(nearest)) if len(taken) else 0
    for _ in range(min(count, len(index))):
        chosen.append(int(index[pick]))
        distance = np.hypot(xy[:, 0] - xy[pick, 0], xy[:, 1] - xy[pick, 1])
        nearest = np.minimum(nearest, distance)
        nearest[pick] = -1.0
        pick = int(np.argmax(nearest))
        if nearest[pick] < 0:
            break
    return chosen
