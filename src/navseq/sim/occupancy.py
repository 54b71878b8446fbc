"""Occupancy grids in the ROS map_server format (an image plus a YAML description).

A map_server map is a greyscale (or colour) image whose pixels are turned into
occupancy values by a few YAML settings::

    image: turtlebot3_world.pgm   # relative paths are resolved against the YAML's folder
    resolution: 0.05              # metres per cell
    origin: [-10.0, -10.0, 0.0]   # pose (x, y, yaw) of the lower-left corner of the image
    negate: 0                     # 1: white means occupied instead of black
    occupied_thresh: 0.65         # occupancy probability above which a cell is occupied
    free_thresh: 0.196            # ... and below which it is free
    mode: trinary                 # trinary (default) | scale | raw

``load_map`` follows ROS 1 map_server's ``image_loader.cpp`` pixel by pixel, so a map
means the same thing here as on a robot:

- the colour channels are averaged; an alpha channel is averaged in too in trinary
  mode, while in scale and raw mode it is left out and a fully transparent pixel is
  unknown;
- ``negate`` flips the average (``255 - avg``) before anything else, in every mode;
- the occupancy probability is ``p = (255 - avg) / 255``: ``p > occupied_thresh``
  gives 100, ``p < free_thresh`` gives 0, anything between gives -1 (unknown) in
  trinary mode and ``1 + 98 * (p - free) / (occupied - free)`` (truncated) in scale
  mode;
- raw mode stores the (possibly negated) average itself, as map_server does into an
  ``int8`` message, so 255 becomes -1 (unknown) and 128..254 become negative;
- the image's top row is the map's last row: row 0 of ``OccupancyGrid.data`` is the
  bottom of the picture (``nav_msgs/OccupancyGrid`` order).

``image``, ``resolution`` and ``origin`` are required, as map_server requires them (a map
without an origin would put every waypoint somewhere else than the robot's map does).
Where map_server insists on ``occupied_thresh`` and ``free_thresh``, navseq falls back
on the values ``map_saver`` writes (0.65 and 0.196). A setting missing or of the wrong
type is refused naming the map file's line and the key.

A map is input like a mission file and gets the same care: the YAML is read by the
mission files' reader (YAML 1.2 numbers such as ``5e-2``, alias bombs and Python tags
refused, every message with its line), both files must be regular files of bounded
size, and an image may hold at most ``NAVSEQ_MAX_MAP_PIXELS`` pixels, checked from its
header before a byte of it is decoded.

The map a running stack publishes (``nav_msgs/OccupancyGrid`` on ``/map``) becomes a
grid through :func:`grid_from_cells` (its fields as plain numbers) or
:func:`grid_from_map_message` (the message itself, ROS 1 or ROS 2): the one conversion
both ROS packages use, with the same bounds as a map file.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from PIL import Image, UnidentifiedImageError

from navseq.errors import NavseqError
from navseq.files import limit_from_environment, open_input_file
from navseq.geometry import Pose2D, normalize_angle, pose2d_from_pose
from navseq.mission.located import Located, describe
from navseq.mission.problems import Problems
from navseq.mission.reading import read_mission_text
from navseq.mission.yaml_doc import parse_yaml
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.sim.filters import MapFilters

OCCUPIED = 100
FREE = 0
UNKNOWN = -1

DEFAULT_OCCUPIED_THRESH = 0.65
DEFAULT_FREE_THRESH = 0.196
MODES = ("trinary", "scale", "raw")

# What a map can mean: cells from 0.1 mm to 1 km, an origin within 1000 km, a yaw
# within ten turns (then normalised). Beyond these, arithmetic on the map overflows.
MIN_RESOLUTION = 1e-4
MAX_RESOLUTION = 1e3
MAX_ORIGIN = 1e6
MAX_ORIGIN_YAW = 20 * math.pi
# A 4000 x 4000 map (200 m square at 5 cm) takes about 750 MB with its costmap.
MAX_PIXELS_VARIABLE = "NAVSEQ_MAX_MAP_PIXELS"
DEFAULT_MAX_PIXELS = 4000 * 4000
MAX_MAP_YAML_BYTES = 1024 * 1024
# Bytes per pixel of the widest image (16-bit RGBA PGM/PNG, uncompressed).
_MAX_BYTES_PER_PIXEL = 8


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A 2-D occupancy map: -1 unknown, 0 free .. 100 occupied, one value per cell.

    ``data[row, col]`` with row 0 at the bottom (``nav_msgs/OccupancyGrid`` order).
    ``origin`` is the pose of the lower-left corner of cell (0, 0); its yaw rotates the
    whole grid about that corner, as in ``nav_msgs/MapMetaData``. Grids compare (and
    hash) by identity: ``data`` is large and treated as immutable. ``filters``: Nav2
    costmap filters (keepout and speed zones) laid over the cells
    (:func:`navseq.sim.filters.with_filters`), None without any.
    """

    data: np.ndarray
    resolution: float
    origin: Pose2D = field(default_factory=lambda: Pose2D(0.0, 0.0, 0.0))
    source: str = "<memory>"
    filters: MapFilters | None = None

    def __post_init__(self) -> None:
        if self.data.ndim != 2:
            raise ValueError(f"occupancy data must be 2-D, got shape {self.data.shape}")
        if not self.resolution > 0:
            raise ValueError(f"resolution must be positive, got {self.resolution}")

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    def world_to_grid(self, x: float, y: float) -> tuple[float, float]:
        """Continuous grid coordinates (col, row) in cells of a world point.

        Cell (row, col) spans ``[col, col + 1) x [row, row + 1)`` in these units.
        """
        dx, dy = x - self.origin.x, y - self.origin.y
        if self.origin.yaw:
            c, s = math.cos(self.origin.yaw), math.sin(self.origin.yaw)
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        return dx / self.resolution, dy / self.resolution

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """(row, col) of the cell containing a world point; may be out of bounds."""
        gx, gy = self.world_to_grid(x, y)
        return math.floor(gy), math.floor(gx)

    def cell_to_world(self, row: int, col: int) -> tuple[float, float]:
        """World (x, y) of a cell's centre."""
        gx, gy = (col + 0.5) * self.resolution, (row + 0.5) * self.resolution
        if self.origin.yaw:
            c, s = math.cos(self.origin.yaw), math.sin(self.origin.yaw)
            gx, gy = c * gx - s * gy, s * gx + c * gy
        return self.origin.x + gx, self.origin.y + gy

    def world_to_cells(self, xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of the cells containing many world points; may be out of bounds.

        The same arithmetic as :meth:`world_to_cell`, element by element, so each point
        lands in the same cell.
        """
        dx = np.asarray(xs, dtype=float) - self.origin.x
        dy = np.asarray(ys, dtype=float) - self.origin.y
        if self.origin.yaw:
            c, s = math.cos(self.origin.yaw), math.sin(self.origin.yaw)
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        rows = np.floor(dy / self.resolution).astype(np.int64)
        cols = np.floor(dx / self.resolution).astype(np.int64)
        return rows, cols

    def cells_to_world(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """World (x, y) of many cell centres at once, shape (N, 2)."""
        gx = (np.asarray(cols, dtype=float) + 0.5) * self.resolution
        gy = (np.asarray(rows, dtype=float) + 0.5) * self.resolution
        c, s = math.cos(self.origin.yaw), math.sin(self.origin.yaw)
        return np.column_stack((self.origin.x + c * gx - s * gy, self.origin.y + s * gx + c * gy))

    def in_bounds(self, row: int, col: int) -> bool:
        return 0 <= row < self.height and 0 <= col < self.width

    def contains(self, x: float, y: float) -> bool:
        """True if the world point lies on the map."""
        return self.in_bounds(*self.world_to_cell(x, y))

    def occupied_mask(self) -> np.ndarray:
        """Cells that are obstacles.

        That is value 100 (and, as costmap_2d reads a raw-mode map as unsigned bytes,
        any other value it would call lethal: 101..127 and -128..-2).
        """
        return (self.data >= OCCUPIED) | (self.data < UNKNOWN)

    def keepout_mask(self) -> np.ndarray | None:
        """Cells in a keepout zone of the map's filters, None without keepout zones."""
        return None if self.filters is None else self.filters.keepout

    def unknown_mask(self) -> np.ndarray:
        """Cells whose occupancy is unknown (value -1)."""
        return self.data == UNKNOWN

    def blocked_mask(self) -> np.ndarray:
        """Cells a robot must not overlap: occupied or unknown."""
        return blocked_values(self.data)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) in the world of the map's corners."""
        corners = [(0, 0), (self.width, 0), (0, self.height), (self.width, self.height)]
        c, s = math.cos(self.origin.yaw), math.sin(self.origin.yaw)
        xs = [self.origin.x + (c * u - s * v) * self.resolution for u, v in corners]
        ys = [self.origin.y + (s * u + c * v) * self.resolution for u, v in corners]
        return min(xs), min(ys), max(xs), max(ys)


def blocked_values(values: np.ndarray) -> np.ndarray:
    """Occupied or unknown, for any slice of grid values (see ``occupied_mask``)."""
    return (values >= OCCUPIED) | (values < FREE)


def load_map(yaml_path: str | Path) -> OccupancyGrid:
    """Read a map_server map (YAML + PGM/PNG image) into an ``OccupancyGrid``.

    Raises ``NavseqError`` naming the file and the key for anything wrong with it.
    """
    path = Path(yaml_path)
    source = str(path)
    description = _read_yaml(path)
    settings = _MapSettings.from_yaml(description, source)
    image_path = Path(settings.image)
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    pixels = _read_image(image_path, description.where_key("image"))
    data = pixels_to_occupancy(
        pixels,
        mode=settings.mode,
        negate=settings.negate,
        occupied_thresh=settings.occupied_thresh,
        free_thresh=settings.free_thresh,
    )
    return OccupancyGrid(
        data=data, resolution=settings.resolution, origin=settings.origin, source=source
    )


def check_map_description(yaml_path: str | Path) -> None:
    """Read and check a map YAML's settings only (not its image); ``NavseqError`` if
    they are unusable. Nav2's map_server answers a bad YAML and a bad image with
    different codes, so its stand-in asks this before :func:`load_map`."""
    path = Path(yaml_path)
    _MapSettings.from_yaml(_read_yaml(path), str(path))


def pixels_to_occupancy(
    pixels: np.ndarray,
    *,
    mode: str = "trinary",
    negate: bool = False,
    occupied_thresh: float = DEFAULT_OCCUPIED_THRESH,
    free_thresh: float = DEFAULT_FREE_THRESH,
) -> np.ndarray:
    """map_server's pixel rules: image array (top row first) -> int8 grid (bottom row first).

    ``pixels`` is uint8 of shape (H, W) or (H, W, C) with C = 2 (grey + alpha), 3 (RGB)
    or 4 (RGBA).
    """
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}")
    channels = pixels[..., np.newaxis] if pixels.ndim == 2 else pixels
    n_channels = channels.shape[2]
    has_alpha = n_channels in (2, 4)
    # map_server: trinary mode averages the alpha channel in with the colours.
    averaged = n_channels - 1 if has_alpha and mode != "trinary" else n_channels
    colour = channels[..., :averaged].astype(np.float64).mean(axis=2)
    alpha = channels[..., -1] if has_alpha else np.full(colour.shape, 255, dtype=np.uint8)
    if negate:
        colour = 255.0 - colour

    if mode == "raw":
        # map_server assigns the int value to an int8 cell: 255 wraps to -1 (unknown).
        values = colour.astype(np.int64).astype(np.uint8).view(np.int8)
        return np.ascontiguousarray(np.flipud(values))

    occupancy = (255.0 - colour) / 255.0
    values = np.full(colour.shape, UNKNOWN, dtype=np.int8)
    if mode == "scale":
        # Truncation toward zero, as the C++ double -> int conversion does.
        ratio = (occupancy - free_thresh) / (occupied_thresh - free_thresh)
        scaled = (1.0 + 98.0 * ratio).astype(np.int64).clip(-128, 127).astype(np.int8)
        values = np.where(alpha < 1, np.int8(UNKNOWN), scaled).astype(np.int8)
    values[occupancy < free_thresh] = FREE
    values[occupancy > occupied_thresh] = OCCUPIED
    return np.ascontiguousarray(np.flipud(values))


def grid_from_cells(
    width: int,
    height: int,
    resolution: float,
    origin: Pose2D,
    data: Sequence[int] | np.ndarray,
    *,
    source: str,
) -> OccupancyGrid:
    """A grid from the fields of a ``nav_msgs/OccupancyGrid`` (ROS 1 or ROS 2).

    ``data`` is row-major from the origin's cell: its first ``width`` values are the
    bottom row, which is the grid's row 0 too, so nothing is flipped (an image is, see
    :func:`pixels_to_occupancy`: its top row is the map's last). The values are kept as
    they are (-1 unknown, 0..100). The message comes from a running stack, not from the
    user's files, but it is checked with a map file's bounds all the same, and any
    problem is a :class:`NavseqError` naming ``source`` (``topic /map``).
    """

    def fail(message: str) -> NavseqError:
        return NavseqError(message, source=source)

    width, height = int(width), int(height)
    if width <= 0 or height <= 0:
        raise fail(f"the map is {width} x {height} cells: empty")
    limit = max_map_pixels()
    if width * height > limit:
        raise fail(
            f"the map is {width} x {height} = {width * height:,} cells; navseq checks at most "
            f"{limit:,} (the environment variable {MAX_PIXELS_VARIABLE} raises the limit)"
        )
    if len(data) != width * height:
        raise fail(f"the map is {width} x {height} cells but carries {len(data)} values")
    resolution = float(resolution)
    if not MIN_RESOLUTION <= resolution <= MAX_RESOLUTION:
        raise fail(
            f"the resolution must be from {MIN_RESOLUTION:g} to {MAX_RESOLUTION:g} m per "
            f"cell, not {resolution:g}"
        )
    if not (abs(origin.x) <= MAX_ORIGIN and abs(origin.y) <= MAX_ORIGIN):
        raise fail(f"the origin must be within ±{MAX_ORIGIN:g} m, not ({origin.x:g}, {origin.y:g})")
    if not math.isfinite(origin.yaw):
        raise fail(f"the origin's yaw is {origin.yaw}")
    values = np.asarray(data)
    # ROS 1 gives a tuple of ints, ROS 2 an array('b'): int8 values either way, unless forged.
    if values.dtype != np.int8 and (
        values.dtype.kind not in "iu" or values.min() < -128 or values.max() > 127
    ):
        raise fail("the occupancy values must be integers from -128 to 127 (int8)")
    cells = np.array(values, dtype=np.int8).reshape(height, width)
    origin = Pose2D(float(origin.x), float(origin.y), normalize_angle(float(origin.yaw)))
    return OccupancyGrid(data=cells, resolution=resolution, origin=origin, source=source)


def grid_from_map_message(message: Any, source: str) -> OccupancyGrid:
    """A grid from a ``nav_msgs/OccupancyGrid``-like object: ROS 1 and ROS 2 name its
    fields alike, so both read their messages here (see :func:`grid_from_cells`)."""
    info = message.info
    return grid_from_cells(
        info.width,
        info.height,
        info.resolution,
        pose2d_from_pose(info.origin),
        message.data,
        source=source,
    )


@dataclass(frozen=True)
class _MapSettings:
    image: str
    resolution: float
    origin: Pose2D
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str

    @classmethod
    def from_yaml(cls, description: Located, source: str) -> _MapSettings:
        doc = {key: entry.value for key, entry in description.value.items()}

        def fail(key: str, message: str) -> NavseqError:
            return NavseqError(message, source=description.where_key(key), subject=f"key {key}")

        image = doc.get("image")
        if image is None:
            raise fail("image", "the map YAML has no 'image' (the PGM/PNG file to load)")
        if not isinstance(image, str) or not image.strip():
            raise fail("image", f"expected a file name, got {_shown(description, 'image')}")
        if "\0" in image:
            raise fail("image", "a file name cannot contain a NUL character")

        if "resolution" not in doc:
            raise fail("resolution", "the map YAML has no 'resolution' (metres per cell)")
        resolution = _number(doc["resolution"])
        if resolution is None or not MIN_RESOLUTION <= resolution <= MAX_RESOLUTION:
            raise fail(
                "resolution",
                f"expected metres per cell from {MIN_RESOLUTION:g} to "
                f"{MAX_RESOLUTION:g}, got {_shown(description, 'resolution')}",
            )

        if "origin" not in doc:  # map_server refuses such a map too
            raise fail(
                "origin",
                "the map YAML has no 'origin' ([x, y, yaw]: the pose of the image's "
                "lower-left pixel, in metres and radians)",
            )
        origin_value = doc["origin"]
        origin_numbers = (
            [_number(v.value) for v in origin_value] if isinstance(origin_value, list) else []
        )
        if len(origin_numbers) != 3 or any(v is None for v in origin_numbers):
            raise fail("origin", f"expected [x, y, yaw], got {_shown(description, 'origin')}")
        x, y, yaw = (float(v) for v in origin_numbers)  # type: ignore[arg-type]
        if not (abs(x) <= MAX_ORIGIN and abs(y) <= MAX_ORIGIN):
            raise fail(
                "origin",
                f"x and y must be within ±{MAX_ORIGIN:g} m, got {_shown(description, 'origin')}",
            )
        if not abs(yaw) <= MAX_ORIGIN_YAW:
            raise fail(
                "origin",
                f"the yaw (radians) must be within ±{MAX_ORIGIN_YAW:.4g} (ten turns), got {yaw:g}",
            )

        negate_value = doc.get("negate", 0)
        if negate_value not in (0, 1) or isinstance(negate_value, float):
            raise fail("negate", f"expected 0 or 1, got {_shown(description, 'negate')}")

        thresholds = {}
        for key, default in (
            ("occupied_thresh", DEFAULT_OCCUPIED_THRESH),
            ("free_thresh", DEFAULT_FREE_THRESH),
        ):
            value = _number(doc.get(key, default))
            if value is None or not 0.0 <= value <= 1.0:
                raise fail(
                    key, f"expected a probability between 0 and 1, got {_shown(description, key)}"
                )
            thresholds[key] = value
        if thresholds["free_thresh"] >= thresholds["occupied_thresh"]:
            raise fail(
                "free_thresh",
                f"free_thresh ({thresholds['free_thresh']}) must be below occupied_thresh "
                f"({thresholds['occupied_thresh']})",
            )

        mode = doc.get("mode", "trinary")
        if mode not in MODES:
            raise fail(
                "mode", f"expected one of {', '.join(MODES)}, got {_shown(description, 'mode')}"
            )

        return cls(
            image=image,
            resolution=resolution,
            origin=Pose2D(x, y, normalize_angle(yaw)),
            negate=bool(negate_value),
            occupied_thresh=thresholds["occupied_thresh"],
            free_thresh=thresholds["free_thresh"],
            mode=mode,
        )


def _shown(description: Located, key: str) -> str:
    """A value from the map YAML as a message shows it: short, escaped."""
    value = description.value[key].value
    if isinstance(value, list) and len(value) <= 4:
        return printable("[" + ", ".join(_short(item.value) for item in value) + "]")
    return printable(_short(value))


def _short(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else describe(value)


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    try:
        number = float(value)
    except OverflowError:  # an integer with hundreds of digits
        return None
    return number if math.isfinite(number) else None


def _read_yaml(path: Path) -> Located:
    """The map YAML as a located mapping, read with the mission files' care."""
    source = str(path)
    if _is_image(path):
        sibling = path.with_suffix(".yaml")
        hint = f" ({printable(str(sibling))}?)" if sibling.is_file() else ""
        raise NavseqError(
            "is a map image, not a map description: give the map's YAML file, the one that "
            f"names this image and its resolution and origin{hint}",
            source=source,
        )
    try:
        text = read_mission_text(path, max_bytes=MAX_MAP_YAML_BYTES, what="map YAML file")
    except NavseqError as error:
        if error.message == "no such file":
            raise NavseqError("map file not found", source=source) from None
        raise
    problems = Problems()
    try:
        doc = parse_yaml(text, source, problems)
    except RecursionError:
        raise NavseqError("is nested too deeply to be a map YAML", source=source) from None
    problems.raise_if_any()
    if doc is None or not doc.is_mapping:
        raise NavseqError(
            "a map YAML must be a mapping with image, resolution, origin, ...",
            source=source if doc is None else doc.where,
        )
    return doc


def _is_image(path: Path) -> bool:
    """Whether ``path`` is a PGM/PPM/PBM or PNG file (a map's image given for its YAML).

    Only a regular file is opened: a FIFO would block here.
    """
    try:
        if not path.is_file():
            return False
        with path.open("rb") as stream:
            head = stream.read(8)
    except OSError:
        return False
    netpbm = head[:1] == b"P" and head[1:2] in (b"1", b"2", b"3", b"4", b"5", b"6")
    return head.startswith(b"\x89PNG") or (netpbm and head[2:3].isspace())


def max_map_pixels() -> int:
    """The largest map image navseq loads, in pixels (``NAVSEQ_MAX_MAP_PIXELS`` raises it)."""
    return limit_from_environment(MAX_PIXELS_VARIABLE, DEFAULT_MAX_PIXELS)


def _read_image(image_path: Path, source: str) -> np.ndarray:
    """Pixels of a PGM/PNG as uint8 (H, W[, C]), top row first.

    ``source`` is where the YAML names the image (``map.yaml:1``).
    """
    subject = f"image {printable(str(image_path))}"
    limit = max_map_pixels()
    try:
        stream = open_input_file(
            image_path, what="map image", max_bytes=limit * _MAX_BYTES_PER_PIXEL + 2**20
        )
    except NavseqError as error:
        message = (
            "the map image does not exist"
            if error.message == "no such file"
            else f"the map image {error.message}"
        )
        raise NavseqError(message, source=source, subject=subject) from None
    try:
        with stream, _pillow_size_checks_off(), Image.open(stream) as image:
            width, height = image.size
            if width * height > limit:
                raise NavseqError(
                    f"the map image is {width} x {height} = {width * height:,} pixels; navseq "
                    f"loads at most {limit:,} (set the environment variable "
                    f"{MAX_PIXELS_VARIABLE} to raise the limit, if the machine has the memory)",
                    source=source,
                    subject=subject,
                )
            image.load()
            return _to_uint8_channels(image)
    except (
        UnidentifiedImageError,
        OSError,
        SyntaxError,
        ValueError,
        EOFError,
        Image.DecompressionBombError,
    ) as error:
        raise NavseqError(
            f"cannot read the map image (not a valid PGM/PNG?): {printable(str(error))}",
            source=source,
            subject=subject,
        ) from None
    except MemoryError:
        raise NavseqError(
            "there is not enough memory to load the map image; lower "
            f"{MAX_PIXELS_VARIABLE} or use a smaller map",
            source=source,
            subject=subject,
        ) from None


@contextlib.contextmanager
def _pillow_size_checks_off() -> Iterator[None]:
    """navseq checks the pixel count itself: no DecompressionBombWarning on stderr and no
    Pillow limit below the one the user set."""
    saved = Image.MAX_IMAGE_PIXELS
    Image.MAX_IMAGE_PIXELS = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            yield
    finally:
        Image.MAX_IMAGE_PIXELS = saved


def _to_uint8_channels(image: Image.Image) -> np.ndarray:
    if image.mode in ("L", "LA", "RGB", "RGBA"):
        return np.asarray(image, dtype=np.uint8)
    if image.mode == "1":
        return np.asarray(image.convert("L"), dtype=np.uint8)
    if image.mode == "P":
        has_transparency = "transparency" in image.info
        return np.asarray(image.convert("RGBA" if has_transparency else "RGB"), dtype=np.uint8)
    if image.mode.startswith("I"):
        # 16-bit PGM/PNG: keep the top 8 bits, as an 8-bit loader would see it.
        wide = np.asarray(image, dtype=np.int64)
        return (wide >> 8).clip(0, 255).astype(np.uint8)
    return np.asarray(image.convert("RGB"), dtype=np.uint8)
