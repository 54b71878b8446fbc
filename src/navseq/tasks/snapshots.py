"""What a ``snapshot`` task writes, and where: alike on both ROS.

A snapshot goes into the run folder's ``snapshots/``, named after its waypoint and task
(``snapshots/dock-task2.png``, ``snapshots/wp3-task1.yaml``), never over a file that is
there already: a resumed run that takes the same snapshot again writes ``...-2.png``.
Each file is written atomically (:func:`navseq.files.write_atomically`).

What the file holds depends on the message type, as Nav2's PhotoAtWaypoint does:

- ``sensor_msgs/Image``: its pixels as PNG (rgb8, bgr8, rgba8, bgra8, mono8, mono16
  and the OpenCV names 8UC1, 8UC3, 8UC4, 16UC1; other encodings: the message's YAML);
- ``sensor_msgs/CompressedImage``: its bytes as they are, JPEG or PNG;
- any other message: its YAML (``rostopic echo`` / ``ros2 topic echo``).
"""

from __future__ import annotations

import io
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from navseq.files import write_atomically

SNAPSHOT_FOLDER = "snapshots"
#: Tries for a free name before giving up (a folder with thousands of copies is wrong).
MAX_NAME_ATTEMPTS = 1000
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")

IMAGE_TYPE = "sensor_msgs/Image"
COMPRESSED_TYPE = "sensor_msgs/CompressedImage"

# Each encoding: Pillow's mode of the PNG, the raw mode of the message's bytes (little-
# and big-endian), bytes per pixel.
_ENCODINGS: dict[str, tuple[str, str, str, int]] = {
    "rgb8": ("RGB", "RGB", "RGB", 3),
    "bgr8": ("RGB", "BGR", "BGR", 3),
    "8UC3": ("RGB", "BGR", "BGR", 3),  # OpenCV's order
    "rgba8": ("RGBA", "RGBA", "RGBA", 4),
    "bgra8": ("RGBA", "BGRA", "BGRA", 4),
    "8UC4": ("RGBA", "BGRA", "BGRA", 4),
    "mono8": ("L", "L", "L", 1),
    "8UC1": ("L", "L", "L", 1),
    "mono16": ("I;16", "I;16", "I;16B", 2),
    "16UC1": ("I;16", "I;16", "I;16B", 2),
}


class SnapshotError(ValueError):
    """The message cannot be saved as asked (its fields do not make an image)."""


@dataclass(frozen=True)
class Snapshot:
    """A file's content and the suffix its name gets."""

    data: bytes
    suffix: str
    what: str  # "PNG 640x480 rgb8", for the report's detail


def snapshot_of(type_name: str, message: Any, to_yaml: Callable[[Any], str]) -> Snapshot:
    """The file a message of ``type_name`` (``pkg/Type``) becomes."""
    if type_name == IMAGE_TYPE and str(message.encoding) in _ENCODINGS:
        return image_png(message)
    if type_name == COMPRESSED_TYPE:
        return compressed_image(message)
    return Snapshot(to_yaml(message).encode("utf-8"), ".yaml", "YAML")


def image_png(message: Any) -> Snapshot:
    """A ``sensor_msgs/Image`` as PNG; SnapshotError when its fields disagree."""
    from PIL import Image

    encoding = str(message.encoding)
    width, height, step = int(message.width), int(message.height), int(message.step)
    mode, little, big, size = _ENCODINGS[encoding]
    data = bytes(message.data)
    if width <= 0 or height <= 0:
        raise SnapshotError(f"the image is {width}x{height}")
    if step < width * size or len(data) < step * height:
        raise SnapshotError(
            f"{len(data)} bytes do not hold {height} rows of {step} bytes "
            f"({width} {encoding} pixels)"
        )
    raw = big if bool(message.is_bigendian) else little
    picture = Image.frombuffer(mode, (width, height), data, "raw", raw, step, 1)
    out = io.BytesIO()
    picture.save(out, format="PNG")
    return Snapshot(out.getvalue(), ".png", f"PNG {width}x{height} {encoding}")


def compressed_image(message: Any) -> Snapshot:
    """A ``sensor_msgs/CompressedImage``'s bytes, named by what they are."""
    data = bytes(message.data)
    if data.startswith(b"\xff\xd8"):
        return Snapshot(data, ".jpg", "JPEG")
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return Snapshot(data, ".png", "PNG")
    written = str(message.format).lower()
    suffix = ".jpg" if "jpeg" in written or "jpg" in written else ".bin"
    return Snapshot(data, suffix, f"compressed ({message.format})")


def snapshot_stem(waypoint: str | None, index: int, number: int) -> str:
    """``dock-task2``: the waypoint's name (made safe for a file name), else ``wp3``."""
    label = _UNSAFE.sub("_", waypoint).strip("._") if waypoint else ""
    return f"{label or f'wp{index + 1}'}-task{number}"


def save_snapshot(folder: Path, stem: str, snapshot: Snapshot) -> Path:
    """Write ``snapshot`` to ``folder/snapshots/stem<suffix>`` or the first free
    ``stem-N<suffix>``; the path written. OSError when the disk refuses."""
    target = folder / SNAPSHOT_FOLDER
    target.mkdir(parents=True, exist_ok=True)
    for number in range(1, MAX_NAME_ATTEMPTS + 1):
        name = stem if number == 1 else f"{stem}-{number}"
        path = target / f"{name}{snapshot.suffix}"
        if path.exists():
            continue
        try:
            write_atomically(path, snapshot.data, replace=False)
        except FileExistsError:
            continue  # appeared meanwhile: the next name
        return path
    raise OSError(f"no free name for {stem}{snapshot.suffix} in {target}")


__all__ = [
    "COMPRESSED_TYPE",
    "IMAGE_TYPE",
    "SNAPSHOT_FOLDER",
    "Snapshot",
    "SnapshotError",
    "compressed_image",
    "image_png",
    "save_snapshot",
    "snapshot_of",
    "snapshot_stem",
]
