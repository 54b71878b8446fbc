"""Seeded synthetic maps for benchmarks and tests: offices, warehouses, saved as map_server.

- :func:`office_map`: rooms on both sides of a corridor, each with a door of its own
  width, some doors and passages between rooms narrower than a robot's turning circle,
  a few pieces of furniture;
- :func:`warehouse_map`: long shelf rows with aisles of mixed widths, some aisles
  blocked halfway so that the way round is long;
- :func:`save_map`: an :class:`OccupancyGrid` as a map_server YAML + PGM pair.

The same seed gives the same map. Coordinates: metres, origin at the map's lower-left
corner; walls are ``WALL`` metres thick.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from navseq.geometry import Pose2D
from navseq.sim.occupancy import OCCUPIED, UNKNOWN, OccupancyGrid

RESOLUTION = 0.05
WALL = 0.1


class _Canvas:
    """An occupancy array drawn on in metres (x right, y up; row 0 is y = 0)."""

    def __init__(self, width: float, height: float) -> None:
        self.data = np.zeros((round(height / RESOLUTION), round(width / RESOLUTION)), np.int8)

    def _cells(self, x0: float, y0: float, x1: float, y1: float) -> tuple[slice, slice]:
        rows = slice(max(round(min(y0, y1) / RESOLUTION), 0), round(max(y0, y1) / RESOLUTION))
        cols = slice(max(round(min(x0, x1) / RESOLUTION), 0), round(max(x0, x1) / RESOLUTION))
        return rows, cols

    def block(self, x0: float, y0: float, x1: float, y1: float) -> None:
        self.data[self._cells(x0, y0, x1, y1)] = OCCUPIED

    def clear(self, x0: float, y0: float, x1: float, y1: float) -> None:
        self.data[self._cells(x0, y0, x1, y1)] = 0

    def frame(self) -> None:
        height, width = self.data.shape
        w, h = width * RESOLUTION, height * RESOLUTION
        self.block(0, 0, w, WALL)
        self.block(0, h - WALL, w, h)
        self.block(0, 0, WALL, h)
        self.block(w - WALL, 0, w, h)

    def grid(self, source: str) -> OccupancyGrid:
        return OccupancyGrid(self.data.copy(), RESOLUTION, Pose2D(0.0, 0.0, 0.0), source)


def office_map(seed: int) -> OccupancyGrid:
    """About 16 m x 12 m: a corridor across the middle, rooms above and below it.

    Door widths are drawn from 0.25 .. 1.0 m (one in four narrower than a TurtleBot3
    burger's turning circle, 0.3 m), so some rooms are out of reach; passages
    between neighbouring rooms are 0.2 .. 0.6 m wide.
    """
    rng = np.random.default_rng(seed)
    width, height = 16.0, 12.0
    canvas = _Canvas(width, height)
    canvas.frame()
    corridor = float(rng.uniform(1.0, 1.8))
    low = height / 2 - corridor / 2
    high = low + corridor
    canvas.block(0, low - WALL, width, low)
    canvas.block(0, high, width, high + WALL)
    for y_wall, y_far, facing in ((low - WALL, 0.0, -1), (high, height, 1)):
        x = 0.0
        walls = []
        while x < width - 2.5:
            room = float(rng.uniform(2.5, 4.5))
            room = min(room, width - x)
            walls.append(x + room)
            door = float(rng.choice([0.25, 0.3, 0.45, 0.6, 0.7, 0.8, 0.9, 1.0]))
            door_at = x + float(rng.uniform(0.4, max(room - door - 0.4, 0.5)))
            canvas.clear(door_at, y_wall, door_at + door, y_wall + WALL)
            # Furniture: a desk somewhere in the room, away from the door.
            if rng.random() < 0.7:
                desk_w, desk_d = float(rng.uniform(0.6, 1.4)), float(rng.uniform(0.5, 0.8))
                dx = x + float(rng.uniform(0.3, max(room - desk_w - 0.3, 0.4)))
                depth = abs(y_far - (y_wall if facing < 0 else y_wall + WALL))
                dy_from_wall = float(rng.uniform(1.2, max(depth - desk_d - 0.2, 1.3)))
                dy = y_wall - dy_from_wall if facing < 0 else y_wall + WALL + dy_from_wall
                canvas.block(dx, dy, dx + desk_w, dy + facing * desk_d)
            x += room
        y0, y1 = (0.0, low - WALL) if facing < 0 else (high + WALL, height)
        for wall_x in walls[:-1]:
            canvas.block(wall_x - WALL / 2, y0, wall_x + WALL / 2, y1)
            if rng.random() < 0.5:  # a passage to the next room, often too narrow
                gap = float(rng.uniform(0.2, 0.6))
                gap_at = float(rng.uniform(y0 + 0.5, y1 - gap - 0.5))
                canvas.clear(wall_x - WALL / 2, gap_at, wall_x + WALL / 2, gap_at + gap)
    return canvas.grid(f"office-{seed}")


def warehouse_map(seed: int) -> OccupancyGrid:
    """About 30 m x 20 m: rows of shelves 0.8 m deep with aisles 0.9 .. 1.6 m wide.

    Cross aisles run along both ends; some aisles are blocked halfway by a pallet, so a
    goal beyond it needs a long detour.
    """
    rng = np.random.default_rng(seed)
    width, height = 30.0, 20.0
    canvas = _Canvas(width, height)
    canvas.frame()
    y = 2.0
    while y < height - 3.0:
        shelf_start = float(rng.uniform(2.0, 3.0))
        shelf_end = width - float(rng.uniform(2.0, 3.0))
        canvas.block(shelf_start, y, shelf_end, y + 0.8)
        aisle = float(rng.uniform(0.9, 1.6))
        if rng.random() < 0.35:  # a pallet blocking this aisle halfway
            at = float(rng.uniform(shelf_start + 4.0, shelf_end - 4.0))
            canvas.block(at, y + 0.8, at + 1.0, y + 0.8 + aisle)
        y += 0.8 + aisle
    return canvas.grid(f"warehouse-{seed}")


def save_map(grid: OccupancyGrid, yaml_path: Path) -> Path:
    """Write ``grid`` as map_server files: ``yaml_path`` and a PGM beside it (trinary)."""
    yaml_path = Path(yaml_path)
    image_path = yaml_path.with_suffix(".pgm")
    pixels = np.full(grid.data.shape, 254, np.uint8)
    pixels[grid.data >= OCCUPIED] = 0
    pixels[grid.data == UNKNOWN] = 205
    Image.fromarray(np.flipud(pixels)).save(image_path)
    origin = grid.origin
    yaml_path.write_text(
        f"image: {image_path.name}\nresolution: {grid.resolution}\n"
        f"origin: [{origin.x}, {origin.y}, {origin.yaw}]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return yaml_path


__all__ = ["office_map", "save_map", "warehouse_map"]
