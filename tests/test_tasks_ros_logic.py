"""What the ROS tasks decide without ROS, the same for ROS 1 and ROS 2: a field by its
path, the wait_for condition, an image message as PNG, and snapshot file names that never
replace a file. Messages here are plain objects shaped as genpy's (fields in
``__slots__``); the real ROS runs are tests/test_tasks_ros.py."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import pytest
from PIL import Image

from navseq.tasks.ros_fields import FieldMissing, condition_met, field_value
from navseq.tasks.snapshots import (
    Snapshot,
    SnapshotError,
    save_snapshot,
    snapshot_of,
    snapshot_stem,
)


def message(**values: Any) -> Any:
    """A message as genpy makes them: a class whose ``__slots__`` are its fields."""
    kind = type("Msg", (), {"__slots__": tuple(values)})
    made = kind()
    for name, value in values.items():
        setattr(made, name, value)
    return made


def test_field_paths_reach_nested_fields_and_list_items() -> None:
    odom = message(pose=message(position=message(x=1.5, y=-2.0)), ranges=[0.3, 0.7])
    assert field_value(odom, "pose.position.x") == 1.5
    assert field_value(odom, "ranges[1]") == 0.7
    with pytest.raises(FieldMissing, match="has no field 'z'"):
        field_value(odom, "pose.position.z")
    with pytest.raises(FieldMissing, match=r"ranges has no item \[5\]"):
        field_value(odom, "ranges[5]")


@pytest.mark.parametrize(
    ("value", "relation", "expected", "met"),
    [
        (True, "equals", True, True),
        (False, "equals", True, False),
        (1, "equals", True, True),  # a uint8 flag
        (3, "equals", 3, True),
        (3.0000000001, "equals", 3, True),
        ("DOCKED", "equals", "DOCKED", True),
        ("docked", "equals", "DOCKED", False),
        (0.4, "above", 0.5, False),
        (0.6, "above", 0.5, True),
        (0.4, "below", 0.5, True),
        ("text", "above", 0.5, False),  # not a number: never above anything
    ],
)
def test_the_condition(value: Any, relation: str, expected: Any, met: bool) -> None:
    assert condition_met(value, relation, expected) is met


def image(encoding: str, width: int, height: int, step: int, data: bytes, big: int = 0) -> Any:
    return message(
        width=width, height=height, encoding=encoding, step=step, data=data, is_bigendian=big
    )


def png_pixels(snapshot: Snapshot) -> tuple[str, list[Any]]:
    assert snapshot.suffix == ".png"
    with Image.open(io.BytesIO(snapshot.data)) as picture:
        width, height = picture.size
        return picture.mode, [picture.getpixel((x, y)) for y in range(height) for x in range(width)]


def no_yaml(_message: Any) -> str:
    raise AssertionError("an image is no YAML")


@pytest.mark.parametrize(
    ("encoding", "data", "mode", "pixels"),
    [
        ("rgb8", bytes([1, 2, 3, 4, 5, 6]), "RGB", [(1, 2, 3), (4, 5, 6)]),
        ("bgr8", bytes([1, 2, 3, 4, 5, 6]), "RGB", [(3, 2, 1), (6, 5, 4)]),
        ("rgba8", bytes([1, 2, 3, 4, 5, 6, 7, 8]), "RGBA", [(1, 2, 3, 4), (5, 6, 7, 8)]),
        ("bgra8", bytes([1, 2, 3, 4, 5, 6, 7, 8]), "RGBA", [(3, 2, 1, 4), (7, 6, 5, 8)]),
        ("mono8", bytes([0, 200]), "L", [0, 200]),
        (
            "mono16",
            (1000).to_bytes(2, "little") + (65535).to_bytes(2, "little"),
            None,
            [1000, 65535],
        ),
    ],
)
def test_image_encodings_become_png_pixels(
    encoding: str, data: bytes, mode: str | None, pixels: list[Any]
) -> None:
    got_mode, got = png_pixels(
        snapshot_of("sensor_msgs/Image", image(encoding, 2, 1, len(data), data), no_yaml)
    )
    assert got == pixels
    if mode is not None:
        assert got_mode == mode


def test_a_big_endian_mono16_and_padded_rows() -> None:
    data = (513).to_bytes(2, "big") + b"\0\0" + (7).to_bytes(2, "big") + b"\0\0"
    snapshot = snapshot_of("sensor_msgs/Image", image("mono16", 1, 2, 4, data, big=1), no_yaml)
    assert png_pixels(snapshot)[1] == [513, 7]


def test_an_image_whose_fields_disagree_is_refused_and_other_encodings_are_yaml() -> None:
    with pytest.raises(SnapshotError, match="do not hold 2 rows of 6 bytes"):
        snapshot_of("sensor_msgs/Image", image("rgb8", 2, 2, 6, bytes(6)), no_yaml)
    odd = image("yuv422", 2, 1, 4, bytes(4))
    snapshot = snapshot_of("sensor_msgs/Image", odd, lambda _m: "encoding: yuv422\n")
    assert (snapshot.suffix, snapshot.data) == (".yaml", b"encoding: yuv422\n")


def test_compressed_images_keep_their_bytes() -> None:
    jpeg = message(format="jpeg", data=b"\xff\xd8\xff\xe0rest")
    assert snapshot_of("sensor_msgs/CompressedImage", jpeg, no_yaml).suffix == ".jpg"
    png = message(format="rgb8; png compressed", data=b"\x89PNG\r\n\x1a\nrest")
    snapshot = snapshot_of("sensor_msgs/CompressedImage", png, no_yaml)
    assert (snapshot.suffix, snapshot.data) == (".png", png.data)


def test_snapshots_never_replace_a_file(tmp_path: Path) -> None:
    assert snapshot_stem("dock / bay 2", 0, 1) == "dock_bay_2-task1"
    assert snapshot_stem(None, 2, 3) == "wp3-task3"
    first = save_snapshot(tmp_path, "wp1-task1", Snapshot(b"one", ".yaml", "YAML"))
    again = save_snapshot(tmp_path, "wp1-task1", Snapshot(b"two", ".yaml", "YAML"))
    assert [first.name, again.name] == ["wp1-task1.yaml", "wp1-task1-2.yaml"]
    assert first.read_bytes() == b"one" and again.read_bytes() == b"two"
    assert sorted(p.name for p in (tmp_path / "snapshots").iterdir()) == [
        "wp1-task1-2.yaml",
        "wp1-task1.yaml",
    ]
