"""The map's costmap filters in the picture: keepout zones hatched red, speed zones
tinted amber (the slower, the deeper), over the map and under the paths."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.transforms import Transform

    from navseq.sim.occupancy import OccupancyGrid
    from navseq.sinks.picture.view import Layout

KEEPOUT_COLOUR = "#d62728"
SPEED_COLOUR = (0.96, 0.62, 0.04)  # amber
MAX_SPEED_TINT = 0.45  # alpha of a zone that stops the robot; none at full speed


def draw_zones(ax: Axes, grid: OccupancyGrid, layout: Layout) -> list[Any]:
    """Keepout and speed zones of ``grid.filters`` (nothing without filters); the legend
    handles of those drawn."""
    from matplotlib.patches import Patch

    handles: list[Any] = []
    zones = grid.filters
    if zones is None:
        return handles
    rows, cols = _view_cells(grid, layout)
    transform = _grid_transform(ax, grid)
    x0 = grid.origin.x + cols.start * grid.resolution
    y0 = grid.origin.y + rows.start * grid.resolution
    height, width = rows.stop - rows.start, cols.stop - cols.start
    if height <= 0 or width <= 0:
        return handles
    extent = (x0, x0 + width * grid.resolution, y0, y0 + height * grid.resolution)
    if zones.speed_limit is not None:
        limit = zones.speed_limit[rows, cols]
        # The fraction of top speed taken away: absolute limits against the fastest
        # limit in view, as the picture does not know the robot's top speed.
        if zones.speed_absolute:
            top = np.nanmax(limit) if np.isfinite(limit).any() else 1.0
            slowed = 1.0 - limit / max(float(top), 1e-9)
        else:
            slowed = 1.0 - limit / 100.0
        slowed = np.where(np.isnan(slowed), 0.0, np.clip(slowed, 0.05, 1.0))
        if slowed.any():
            tint = np.zeros((*slowed.shape, 4))
            tint[..., :3] = SPEED_COLOUR
            tint[..., 3] = slowed * MAX_SPEED_TINT
            artist = ax.imshow(
                tint,
                origin="lower",
                extent=extent,
                interpolation="nearest",
                zorder=0.6,
            )
            artist.set_gid("speed-zones")
            artist.set_transform(transform)
            handles.append(
                Patch(facecolor=(*SPEED_COLOUR, MAX_SPEED_TINT * 0.6), label="speed zone")
            )
    if zones.keepout is not None:
        keepout = zones.keepout[rows, cols]
        if keepout.any():
            xs = x0 + (np.arange(width) + 0.5) * grid.resolution
            ys = y0 + (np.arange(height) + 0.5) * grid.resolution
            contours = ax.contourf(
                xs,
                ys,
                keepout.astype(float),
                levels=[0.5, 1.5],
                colors=[KEEPOUT_COLOUR],
                alpha=0.3,
                hatches=["////"],
                zorder=0.7,
                transform=transform,
            )
            contours.set_gid("keepout-zones")
            handles.append(
                Patch(facecolor=KEEPOUT_COLOUR, alpha=0.3, hatch="////", label="keepout zone")
            )
    return handles


def _view_cells(grid: OccupancyGrid, layout: Layout) -> tuple[slice, slice]:
    """The grid's rows and columns in view (all of them on a rotated map)."""
    if grid.origin.yaw:
        return slice(0, grid.height), slice(0, grid.width)
    view = layout.view
    c0 = max(0, math.floor((view.xmin - grid.origin.x) / grid.resolution) - 1)
    c1 = min(grid.width, math.ceil((view.xmax - grid.origin.x) / grid.resolution) + 1)
    r0 = max(0, math.floor((view.ymin - grid.origin.y) / grid.resolution) - 1)
    r1 = min(grid.height, math.ceil((view.ymax - grid.origin.y) / grid.resolution) + 1)
    return slice(r0, max(r0, r1)), slice(c0, max(c0, c1))


def _grid_transform(ax: Axes, grid: OccupancyGrid) -> Transform:
    from matplotlib.transforms import Affine2D

    if not grid.origin.yaw:
        return ax.transData
    rotation = Affine2D().rotate_around(grid.origin.x, grid.origin.y, grid.origin.yaw)
    return rotation + ax.transData


__all__ = ["draw_zones"]
