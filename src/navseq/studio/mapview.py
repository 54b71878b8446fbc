"""The map as the page draws it: a PNG in world axes, the costmap and the mission's
keepout and speed zones (Nav2 costmap filters) as overlays.

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
    from PIL import Image

    from navseq.mission.costmap_filters import CostmapFilter
    from navseq.mission.robot import RobotProfile
    from navseq.sim.costmap import Costmap
    from navseq.sim.occupancy import OccupancyGrid

# map_server's colours: free 254, occupied 0, unknown 205.
_FREE_GREY, _UNKNOWN_GREY = 254, 205


def _png(image: Image.Image, yaw: float, fill: int | tuple[int, ...]) -> bytes:
    from PIL import Image

    if yaw:
        image = image.rotate(
            math.degrees(yaw), expand=True, resample=Image.Resampling.NEAREST, fillcolor=fill
        )
    out = io.BytesIO()
    # Speed over size (it stays local): level 1 writes a 2000 x 2000 map in ~15 ms.
    image.save(out, format="PNG", compress_level=1)
    return out.getvalue()


def map_png(grid: OccupancyGrid) -> bytes:
    """The occupancy grid in map_server's greys (darker = more occupied).

    One grey byte per cell (PNG mode L), not four: a tenth of the time and a third of
    the bytes of RGBA on a 2000 x 2000 map, which is what the page's first paint waits
    for. A turned map needs transparent corners, so it gets an alpha channel (LA).
    """
    from PIL import Image

    data = grid.data.astype(np.int16)
    grey = np.where(
        data < 0,
        _UNKNOWN_GREY,
        np.clip(_FREE_GREY - (np.clip(data, 0, 100) * _FREE_GREY) // 100, 0, 255),
    ).astype(np.uint8)
    image = Image.fromarray(np.ascontiguousarray(grey[::-1]), "L")  # row 0 is the bottom
    if not grid.origin.yaw:
        return _png(image, 0.0, 0)
    return _png(image.convert("LA"), grid.origin.yaw, (0, 0))


# The costmap overlay's palette: index 0 clear, 1..252 the inflation's cost (blue, more
# opaque with the cost), _NO_CENTRE where the robot's centre may not be (red).
_NO_CENTRE = 255


def _costmap_palette() -> tuple[list[int], bytes]:
    colours = [0, 0, 0] * 256
    alpha = bytearray(256)
    for index in range(1, 253):
        colours[3 * index : 3 * index + 3] = (40, 90, 220)
        alpha[index] = 30 + index * 110 // 252
    colours[3 * _NO_CENTRE : 3 * _NO_CENTRE + 3] = (220, 40, 40)
    alpha[_NO_CENTRE] = 150
    return colours, bytes(alpha)


def costmap_png(costmap: Costmap) -> bytes:
    """Where the robot's centre may not be (red) and the inflation's cost (blue shades).

    Obstacles and unknown cells stay clear: the map under it shows them. A palette
    image (one byte per cell, its transparency in the palette) rather than RGBA.
    """
    from PIL import Image

    from navseq.sim.costmap import INSCRIBED, LETHAL

    cost = costmap.cost
    index = np.where((cost > 0) & (cost < INSCRIBED), cost, 0).astype(np.uint8)
    index[(costmap.planning_cost >= INSCRIBED) & (cost < LETHAL)] = _NO_CENTRE
    image = Image.fromarray(np.ascontiguousarray(index[::-1]), "P")  # row 0 is the bottom
    colours, alpha = _costmap_palette()
    image.putpalette(colours)
    image.info["transparency"] = alpha
    return _png(image, costmap.grid.origin.yaw, 0)


# The zones overlay's colours, as the picture's (navseq.sinks.picture.zones).
_KEEPOUT_RGBA = (214, 39, 40, 140)
_SPEED_RGB = (245, 158, 10)
_MAX_SPEED_ALPHA = 130


def zones_png(grid: OccupancyGrid) -> bytes:
    """Keepout zones (red) and speed zones (amber, more opaque where slower) of
    ``grid.filters``; all clear without filters."""
    from PIL import Image

    rgba = np.zeros((grid.height, grid.width, 4), dtype=np.uint8)
    zones = grid.filters
    if zones is not None and zones.speed_limit is not None:
        limit = zones.speed_limit
        if zones.speed_absolute:
            top = float(np.nanmax(limit)) if np.isfinite(limit).any() else 1.0
            slowed = 1.0 - limit / max(top, 1e-9)
        else:
            slowed = 1.0 - limit / 100.0
        slowed = np.where(np.isnan(slowed), 0.0, np.clip(slowed, 0.1, 1.0))
        rgba[..., :3] = _SPEED_RGB
        rgba[..., 3] = (slowed * _MAX_SPEED_ALPHA).astype(np.uint8)
    if zones is not None and zones.keepout is not None:
        rgba[zones.keepout] = _KEEPOUT_RGBA
    image = Image.fromarray(np.ascontiguousarray(rgba[::-1]), "RGBA")  # row 0 is the bottom
    return _png(image, grid.origin.yaw, (0, 0, 0, 0))


@dataclass
class MapView:
    """One map file, loaded once, with its images and costmaps made on first use.

    Each image and each costmap has its own lock: the map's PNG (what the page's first
    paint waits for) is never held up by a costmap being inflated beside it (about a
    second on a 2000 x 2000 map), and two requests for the same thing make it once.
    """

    path: Path
    grid: OccupancyGrid
    _images: dict[str, bytes] = field(default_factory=dict)
    _costmaps: dict[Any, Costmap] = field(default_factory=dict)
    _locks: dict[Any, threading.Lock] = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock)  # guards _locks only

    @classmethod
    def load(cls, path: Path) -> MapView:
        from navseq.sim.occupancy import load_map

        return cls(path, load_map(path))

    def _lock_of(self, key: Any) -> threading.Lock:
        with self._lock:
            return self._locks.setdefault(key, threading.Lock())

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

        with self._lock_of(("costmap", robot)):
            made = self._costmaps.get(robot)
            if made is None:
                made = costmap_for_robot(self.grid, robot)
                self._costmaps[robot] = made
            return made

    def zones_image(self, filters: tuple[CostmapFilter, ...]) -> bytes:
        """The zones of ``filters`` over this map (made once per set of filters)."""
        from navseq.sim.filters import with_filters

        key = ("zones", filters)
        with self._lock_of(("image", key)):
            png = self._images.get(str(key))
            if png is None:
                png = zones_png(with_filters(self.grid, filters))
                self._images[str(key)] = png
            return png

    def image(self, kind: str, robot: RobotProfile) -> bytes:
        key = kind if kind == "map" else f"{kind}:{robot.name}:{hash(robot)}"
        with self._lock_of(("image", key)):
            png = self._images.get(key)
            if png is None:
                png = map_png(self.grid) if kind == "map" else costmap_png(self.costmap(robot))
                self._images[key] = png
            return png
