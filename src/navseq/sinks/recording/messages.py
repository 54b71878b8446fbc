"""The ROS messages of a recording, as plain nested dicts with ROS 2's field names.

Times are the run's clock (the navigator's: simulated time for the simulator, ROS time
for a real stack), in seconds; poses are 2-D (x, y, yaw) as navseq knows them. The
encoder (:mod:`navseq.sinks.recording.encoding`) turns a dict into ROS 2 or ROS 1 bytes.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from navseq.geometry import Pose2D, yaw_to_quaternion
from navseq.sim.occupancy import OccupancyGrid
from navseq.sinks.mission_status import MarkerKind, MarkerSpec

Message = dict[str, Any]
#: visualization_msgs/Marker's type constants for navseq's two marker kinds.
MARKER_TYPES = {MarkerKind.ARROW: 0, MarkerKind.LABEL: 9}  # ARROW, TEXT_VIEW_FACING
MARKER_ADD = 0


def nanoseconds(t: float) -> int:
    """A clock time in seconds as a recording's log time (ns, never negative)."""
    return max(0, round(t * 1e9))


def stamp(t: float) -> Message:
    ns = nanoseconds(t)
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def header(t: float, frame: str) -> Message:
    return {"stamp": stamp(t), "frame_id": frame}


def pose(x: float, y: float, yaw: float, z: float = 0.0) -> Message:
    qx, qy, qz, qw = yaw_to_quaternion(yaw)
    return {
        "position": {"x": float(x), "y": float(y), "z": float(z)},
        "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
    }


def pose_stamped(t: float, frame: str, where: Pose2D, z: float = 0.0) -> Message:
    """``geometry_msgs/PoseStamped``."""
    return {"header": header(t, frame), "pose": pose(where.x, where.y, where.yaw, z)}


def occupancy_grid(t: float, frame: str, grid: OccupancyGrid) -> Message:
    """``nav_msgs/OccupancyGrid``: the map as the run reads it (row 0 at the bottom)."""
    origin = grid.origin
    return {
        "header": header(t, frame),
        "info": {
            "map_load_time": stamp(t),
            "resolution": float(grid.resolution),
            "width": grid.width,
            "height": grid.height,
            "origin": pose(origin.x, origin.y, origin.yaw),
        },
        "data": np.asarray(grid.data, dtype=np.int8).ravel().tolist(),
    }


def path(t: float, frame: str, points: Sequence[tuple[float, float]]) -> Message:
    """``nav_msgs/Path``: each point heading for the next, the last as the one before."""
    poses = []
    yaw = 0.0
    for i, (x, y) in enumerate(points):
        if i + 1 < len(points):
            nx, ny = points[i + 1]
            if (nx, ny) != (x, y):
                yaw = math.atan2(ny - y, nx - x)
        poses.append(pose_stamped(t, frame, Pose2D(x, y, yaw)))
    return {"header": header(t, frame), "poses": poses}


def transform(t: float, parent: str, child: str, where: Pose2D) -> Message:
    """``geometry_msgs/TransformStamped`` of ``child`` in ``parent``."""
    qx, qy, qz, qw = yaw_to_quaternion(where.yaw)
    return {
        "header": header(t, parent),
        "child_frame_id": child,
        "transform": {
            "translation": {"x": float(where.x), "y": float(where.y), "z": 0.0},
            "rotation": {"x": qx, "y": qy, "z": qz, "w": qw},
        },
    }


def tf_message(transforms: Iterable[Message]) -> Message:
    """``tf2_msgs/TFMessage``."""
    return {"transforms": list(transforms)}


def odometry(
    t: float, frame: str, child: str, where: Pose2D, speed: float, turn_rate: float
) -> Message:
    """``nav_msgs/Odometry``: pose in ``frame``, velocity (m/s, rad/s) in ``child``.

    navseq knows no covariance: the matrices stay zero ("unknown" by convention).
    """
    return {
        "header": header(t, frame),
        "child_frame_id": child,
        "pose": {"pose": pose(where.x, where.y, where.yaw)},
        "twist": {
            "twist": {
                "linear": {"x": float(speed), "y": 0.0, "z": 0.0},
                "angular": {"x": 0.0, "y": 0.0, "z": float(turn_rate)},
            }
        },
    }


def marker_array(t: float, specs: Iterable[MarkerSpec]) -> Message:
    """``visualization_msgs/MarkerArray`` of navseq's waypoint markers."""
    markers = []
    for spec in specs:
        r, g, b, a = spec.colour
        markers.append(
            {
                "header": header(t, spec.frame),
                "ns": spec.namespace,
                "id": spec.id,
                "type": MARKER_TYPES[spec.kind],
                "action": MARKER_ADD,
                "pose": pose(spec.x, spec.y, spec.yaw, spec.z),
                "scale": dict(zip("xyz", (float(v) for v in spec.scale), strict=True)),
                "color": {"r": r, "g": g, "b": b, "a": a},
                "text": spec.text,
            }
        )
    return {"markers": markers}


__all__ = [
    "Message",
    "marker_array",
    "nanoseconds",
    "occupancy_grid",
    "odometry",
    "path",
    "pose_stamped",
    "stamp",
    "tf_message",
    "transform",
]
