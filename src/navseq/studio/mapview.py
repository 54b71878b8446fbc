"""The map as the page draws it: a PNG in world axes, and the costmap as an overlay.

The grid comes from :func:`navseq.sim.occupancy.load_map` (every map mode, negate and
threshold as the loader reads them), so the page shows what the planner and pre-flight
see. Images are drawn in the map's own pixels, north up; a map whose origin is turned
(``origin: [x, y, yaw]``) is turned here too and given its axis-aligned bounds, so the
page only places an image between two corners in metres.
"""

from __future__ import annotations

import io
import math
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from navseq.mission.robot import RobotProfile
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid

# map_server's colours: free 254, occupied 0, unknown 205.
_FREE_GREY, _UNKNOWN_GREY = 254, 205


def _png(rgba: np.ndarray, yaw: float) -> bytes:
    from PIL import Image

    image = Image.fromarray(np.ascontiguousarray(rgba[::-1]), "RGBA")  # row 0 is the bottom
    if yaw:
        image = image.rotate(
            math.degrees(yaw), expand=True, resample=Image.Resampling.NEAREST, fillcolor=(0,) * 4
        )
    out = io.BytesIO()
    image.save(out, format="PNG", compress_level=1)  # speed over size: it stays local
    return out.getvalue()


def map_png(grid: OccupancyGrid) -> bytes:
    """The occupancy grid in map_server's greys (darker = more occupied)."""
    data = grid.data.astype(np.int16)
    grey = np.where(
        data < 0,
        _UNKNOWN_GREY,
        np.clip(_FREE_GREY - (np.clip(data, 0, 100) * _FREE_GREY) // 100, 0, 255),
    ).astype(np.uint8)
    alpha = np.full(grey.shape, 255, dtype=np.uint8)
    return _png(np.dstack((grey, grey, grey, alpha)), grid.origin.yaw)


def costmap_png(costmap: Costmap) -> bytes:
    """Where the robot's centre may not be (red) and the inflation's cost (blue shades).

    Obstacles and unknown cells stay clear: the map under it shows them.
    """
    from navseq.sim.costmap import INSCRIBED, LETHAL

    cost = costmap.cost
    planning = costmap.planning_cost
    rgba = np.zeros((*cost.shape, 4), dtype=np.uint8)
    inflated = (cost > 0) & (cost < INSCRIBED)
    rgba[inflated] = (40, 90, 220, 0)
    rgba[..., 3][inflated] = (30 + cost[inflated].astype(np.uint16) * 110 // 252).astype(np.uint8)
    no_centre = (planning >= INSCRIBED) & (cost < LETHAL)
    rgba[no_centre] = (220, 40, 40, 150)
    return _png(rgba, costmap.grid.origin.yaw)


@dataclass
class MapView:
    """One map file, loaded once, with its images made on first use."""

    path: Path
    grid: OccupancyGrid
    _images: dict[str, bytes] = field(default_factory=dict)
    _costmaps: dict[Any, Costmap] = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock)

    @classmethod
    def load(cls, path: Path) -> MapView:
        from navseq.sim.occupancy import load_map

        return cls(path, load_map(path))

    def info(self) -> dict[str, Any]:
        grid = self.grid
        xmin, ymin, xmax, ymax = grid.bounds
        return {
            "width_cells": grid.width,
            "height_cells": grid.height,
            "resolution_m": grid.resolution,
            "origin": {
                "x_m": grid.origin.x,
                "y_m": grid.origin.y,
                "yaw_deg": math.degrees(grid.origin.yaw),
            },
            "bounds_m": {"xmin": xmin, "ymin": ymin, "xmax": xmax, "ymax": ymax},
        }

    def costmap(self, robot: RobotProfile) -> Costmap:
        """The grid inflated for ``robot`` (navseq's own rule, made once per robot)."""
        from navseq.commands.common import costmap_for_robot

        with self._lock:
            made = self._costmaps.get(robot)
            if made is None:
                made = costmap_for_robot(self.grid, robot)
                self._costmaps[robot] = made
            return made

    def image(self, kind: str, robot: RobotProfile) -> bytes:
        key = kind if kind == "map" else f"{kind}:{robot.name}:{hash(robot)}"
        with self._lock:
            cached = self._images.get(key)
        if cached is not None:
            return cached
        png = map_png(self.grid) if kind == "map" else costmap_png(self.costmap(robot))
        with self._lock:
            self._images[key] = png
        return png
