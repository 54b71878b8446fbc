"""The picture the task peers publish on ``/camera/image``: 3 x 2 rgb8 pixels, each row
padded to 12 bytes (``step``), as some cameras do. Plain data: no ROS import."""

from __future__ import annotations

WIDTH, HEIGHT, STEP = 3, 2, 12
#: Each row's pixels, left to right, as (r, g, b).
PIXELS = (
    ((255, 0, 0), (0, 255, 0), (0, 0, 255)),
    ((10, 20, 30), (40, 50, 60), (255, 255, 255)),
)
PADDING = bytes(STEP - 3 * WIDTH)
DATA = b"".join(bytes(value for pixel in row for value in pixel) + PADDING for row in PIXELS)

#: The fields of a ``sensor_msgs/Image`` on both ROS (no header: its defaults).
IMAGE_FIELDS = {
    "width": WIDTH,
    "height": HEIGHT,
    "encoding": "rgb8",
    "is_bigendian": 0,
    "step": STEP,
    "data": DATA,
}
