"""The stack's own map, without ROS: the ``nav_msgs/OccupancyGrid`` fields -> grid
conversion both ROS packages use, which topic is taken, and pre-flight on it.

The ROS runs (a waypoint in a pillar refused on the map the simulator publishes) are in
``test_cli_ros1.py`` and ``test_ros2_navigator.py``.
"""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from PIL import Image

from navseq.errors import MissionErrors, NavseqError
from navseq.geometry import Pose2D, yaw_to_quaternion
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.navigators.registry import NavigatorDraft
from navseq.navigators.stack_map import (
    MapCatch,
    StackMap,
    map_topics,
    map_wait_setting,
    preflight_on_stack_map,
    stack_map_from_message,
)
from navseq.sim.occupancy import OccupancyGrid, grid_from_cells, load_map

REPO_MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"

# A 3 x 2 grid, every cell different, as a message carries it: row-major from the
# origin's cell, so the bottom row (y nearest the origin) comes first.
#   top row    (row 1):  -1 100   0
#   bottom row (row 0):   0  -1 100
CELLS = [0, -1, 100, -1, 100, 0]
ORIGIN = Pose2D(0.0, 0.0, 0.0)


def map_message(
    width: int,
    height: int,
    data: Any,
    *,
    resolution: float = 0.5,
    origin: Pose2D = ORIGIN,
    frame: str = "map",
) -> SimpleNamespace:
    """A ``nav_msgs/OccupancyGrid``-like object: the fields ROS 1 and ROS 2 share."""
    x, y, z, w = yaw_to_quaternion(origin.yaw)
    pose = SimpleNamespace(
        position=SimpleNamespace(x=origin.x, y=origin.y, z=0.0),
        orientation=SimpleNamespace(x=x, y=y, z=z, w=w),
    )
    info = SimpleNamespace(width=width, height=height, resolution=resolution, origin=pose)
    return SimpleNamespace(header=SimpleNamespace(frame_id=frame), info=info, data=data)


# -- the conversion ---------------------------------------------------------------------------


def test_cells_keep_the_messages_order_row_zero_at_the_origin_nothing_flipped() -> None:
    grid = grid_from_cells(3, 2, 0.5, Pose2D(-1.0, 2.0, 0.0), CELLS, source="topic /map")
    assert (grid.width, grid.height) == (3, 2)
    assert grid.data.dtype == np.int8
    assert grid.data.tolist() == [[0, -1, 100], [-1, 100, 0]]
    # World lookups: the origin offset is the lower-left corner of cell (0, 0).
    assert grid.world_to_cell(-0.9, 2.1) == (0, 0)  # bottom left: 0
    assert grid.data[grid.world_to_cell(0.1, 2.1)] == 100  # bottom right
    assert grid.data[grid.world_to_cell(-0.9, 2.9)] == -1  # top left: unknown
    assert grid.data[grid.world_to_cell(-0.4, 2.9)] == 100  # top middle
    assert not grid.contains(-1.1, 2.1) and not grid.contains(-0.9, 3.1)
    assert grid.unknown_mask().tolist() == [[False, True, False], [True, False, False]]
    assert grid.source == "topic /map"


def test_a_message_means_what_map_server_made_it_from_its_image(tmp_path: Path) -> None:
    """map_server fills the message from the image bottom row up (image row j goes to
    message row height - 1 - j): the message, converted, is the image, loaded."""
    # An asymmetric 4 x 3 image: black (occupied) top left, grey (unknown) bottom right.
    pixels = np.full((3, 4), 255, dtype=np.uint8)
    pixels[0, 0] = 0
    pixels[0, 1] = 0
    pixels[2, 3] = 205
    Image.fromarray(pixels).save(tmp_path / "m.pgm")
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.25\norigin: [1.5, -2.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    meaning = {0: 100, 255: 0, 205: -1}
    height, width = pixels.shape
    data = [0] * (width * height)
    for j in range(height):  # map_server's loop: image rows from the top
        for i in range(width):
            data[(height - 1 - j) * width + i] = meaning[int(pixels[j, i])]
    message = map_message(width, height, data, resolution=0.25, origin=Pose2D(1.5, -2.0, 0.0))
    from_message = stack_map_from_message(message, "/map").grid
    from_file = load_map(tmp_path / "m.yaml")
    assert np.array_equal(from_message.data, from_file.data)
    assert from_message.origin == from_file.origin
    # The top-left pixel is the top-left of the world too.
    assert from_message.data[from_message.world_to_cell(1.6, -1.3)] == 100
    assert from_message.data[from_message.world_to_cell(2.4, -1.9)] == -1


def test_the_turtlebot3_map_survives_the_trip_through_a_message() -> None:
    grid = load_map(REPO_MAP)
    message = map_message(
        grid.width,
        grid.height,
        tuple(int(v) for v in grid.data.ravel()),  # rospy's int8[]: a tuple of ints
        resolution=grid.resolution,
        origin=grid.origin,
    )
    stack = stack_map_from_message(message, "/map")
    assert np.array_equal(stack.grid.data, grid.data)
    assert stack.description == "the map on /map: 384 x 384 cells at 0.050 m"


def test_the_origin_yaw_comes_from_the_quaternion_and_rclpy_arrays_are_read() -> None:
    import array

    data = array.array("b", CELLS)  # what rclpy gives for int8[]
    message = map_message(3, 2, data, origin=Pose2D(1.0, 1.0, math.pi / 2), frame="/map")
    stack = stack_map_from_message(message, "/robot1/map")
    assert stack.frame == "map"  # ROS 1's leading slash dropped
    assert stack.grid.origin.yaw == pytest.approx(math.pi / 2)
    # Rotated a quarter turn: the grid's +x runs along the world's +y.
    assert stack.grid.data[stack.grid.world_to_cell(0.9, 2.1)] == 100  # row 0, col 2


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"data": CELLS[:-1]}, "3 x 2 cells but carries 5 values"),
        ({"width": 0, "height": 0, "data": []}, "0 x 0 cells: empty"),
        ({"resolution": 0.0}, "resolution must be from"),
        ({"resolution": math.nan}, "resolution must be from"),
        ({"origin": Pose2D(math.inf, 0.0, 0.0)}, "origin must be within"),
        ({"data": [0, 1, 2, 3, 4, 300]}, "integers from -128 to 127"),
    ],
)
def test_a_message_that_is_no_map_is_one_error_naming_the_topic(
    fields: dict[str, Any], message: str
) -> None:
    values: dict[str, Any] = {"width": 3, "height": 2, "data": CELLS, **fields}
    settings = {k: values[k] for k in ("resolution", "origin") if k in values}
    with pytest.raises(NavseqError, match=message) as raised:
        stack_map_from_message(
            map_message(values["width"], values["height"], values["data"], **settings), "/map"
        )
    assert raised.value.source == "topic /map"


def test_a_map_above_the_pixel_limit_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("NAVSEQ_MAX_MAP_PIXELS", "5")
    with pytest.raises(NavseqError, match="NAVSEQ_MAX_MAP_PIXELS"):
        grid_from_cells(3, 2, 0.5, Pose2D(0.0, 0.0), CELLS, source="topic /map")


# -- which topic ------------------------------------------------------------------------------


def test_the_namespaced_map_first_then_the_global_one() -> None:
    assert map_topics("/robot1/map") == ("/robot1/map", "/map")
    assert map_topics("/map") == ("/map",)


def test_the_namespaced_map_is_taken_at_once() -> None:
    catch = MapCatch(("/robot1/map", "/map"))
    catch.offer("/map", "global")
    catch.offer("/robot1/map", "own")
    assert catch.wait(5.0, lambda topic: True) == ("/robot1/map", "own")


def test_the_global_map_is_taken_when_nobody_publishes_the_namespaced_one() -> None:
    catch = MapCatch(("/robot1/map", "/map"))
    catch.offer("/map", "global")
    began = time.monotonic()
    assert catch.wait(5.0, lambda topic: topic == "/map") == ("/map", "global")
    assert time.monotonic() - began < 4.0  # not the 5 s timeout: nobody was waited for


def test_a_published_namespaced_map_is_waited_for_then_the_global_one_is_taken() -> None:
    catch = MapCatch(("/robot1/map", "/map"))
    catch.offer("/map", "global")
    threading.Timer(0.2, catch.offer, ("/robot1/map", "own")).start()
    assert catch.wait(5.0, lambda topic: True) == ("/robot1/map", "own")
    late = MapCatch(("/robot1/map", "/map"))
    late.offer("/map", "global")
    assert late.wait(0.3, lambda topic: True) == ("/map", "global")  # at the deadline


def test_no_map_within_the_wait_is_none_and_the_first_message_on_a_topic_stays() -> None:
    catch = MapCatch(("/map",))
    began = time.monotonic()
    assert catch.wait(0.2, lambda topic: False) is None
    assert time.monotonic() - began >= 0.2
    catch.offer("/map", "first")
    catch.offer("/map", "second")
    assert catch.wait(0.0, lambda topic: True) == ("/map", "first")


@pytest.mark.parametrize("value", ["-1", "nan", "inf", "soon"])
def test_a_bad_map_wait_is_one_error(value: str) -> None:
    with pytest.raises(NavseqError, match="--map-wait: must be >= 0 seconds"):
        map_wait_setting(value)
    assert map_wait_setting("0") == 0.0


# -- pre-flight on it -------------------------------------------------------------------------


def draft(*points: tuple[str, float, float], preflight: bool = True) -> NavigatorDraft:
    mission = Mission(
        waypoints=tuple(Waypoint(x, y, yaw_deg=0.0, name=name) for name, x, y in points),
        source="m.yaml",
    )
    return NavigatorDraft(mission, None, None, None, DEFAULT_PROFILE, preflight=preflight)


def turtlebot3_map(topic: str = "/map", frame: str = "map") -> StackMap:
    grid = load_map(REPO_MAP)
    return StackMap(topic, frame, OccupancyGrid(grid.data, grid.resolution, grid.origin, topic))


PILLAR = ("pillar", 1.0, 0.0)  # the edge of the east pillar: inside an obstacle
WEST = ("west", -1.6, -0.5)


def reader(found: StackMap | None, asked: list[Any] | None = None) -> Any:
    def read(topics: Any, wait: float) -> StackMap | None:
        if asked is not None:
            asked.append((tuple(topics), wait))
        return found

    return read


def test_a_waypoint_in_a_pillar_of_the_stacks_map_is_refused_naming_that_map() -> None:
    with pytest.raises(MissionErrors) as raised:
        preflight_on_stack_map(draft(WEST, PILLAR), reader(turtlebot3_map()), ("/map",), "map")
    text = str(raised.value)
    assert text.startswith(
        "1 problem found (pre-flight on the map on /map: 384 x 384 cells at 0.050 m):"
    ), text
    assert "waypoint 2 'pillar'" in text and "inside an obstacle" in text


def test_a_good_mission_is_checked_and_the_map_kept_for_the_picture() -> None:
    asked: list[Any] = []
    used = preflight_on_stack_map(
        draft(WEST), reader(turtlebot3_map(), asked), ("/robot1/map", "/map"), "map", 1.5
    )
    assert asked == [(("/robot1/map", "/map"), 1.5)]
    assert used.grid is not None and used.grid.width == 384
    assert used.note == "pre-flight on the map on /map: 384 x 384 cells at 0.050 m"
    assert used.source == "the map on /map: 384 x 384 cells at 0.050 m"


def test_no_preflight_keeps_the_map_for_the_picture_and_checks_nothing() -> None:
    used = preflight_on_stack_map(
        draft(PILLAR, preflight=False), reader(turtlebot3_map()), ("/map",), "map"
    )
    assert used.grid is not None
    assert used.note.endswith("(no pre-flight (--no-preflight))")


def test_no_map_is_said_and_the_run_goes_on() -> None:
    used = preflight_on_stack_map(draft(PILLAR), reader(None), ("/robot1/map", "/map"), "map", 2)
    assert used.grid is None
    assert used.note == (
        "no map on /robot1/map or /map within 2 s: pre-flight skipped "
        "(give --map to check the waypoints)"
    )
    assert used.source == "no map on /robot1/map or /map within 2 s"


def test_a_map_in_another_frame_than_the_goals_is_not_used() -> None:
    used = preflight_on_stack_map(
        draft(PILLAR), reader(turtlebot3_map(frame="odom")), ("/map",), "map"
    )
    assert used.grid is None
    assert "is in frame 'odom', the goals in 'map': not used: pre-flight skipped" in used.note


def test_an_unusable_map_or_a_wait_of_zero_skips_pre_flight_with_a_note() -> None:
    def broken(topics: Any, wait: float) -> StackMap | None:
        raise NavseqError("the map is 3 x 2 cells but carries 5 values", source="topic /map")

    used = preflight_on_stack_map(draft(PILLAR), broken, ("/map",), "map")
    assert used.grid is None
    assert used.note == (
        "the stack's map cannot be used: topic /map: the map is 3 x 2 cells but carries 5 "
        "values: pre-flight skipped"
    )
    asked: list[Any] = []
    used = preflight_on_stack_map(draft(PILLAR), reader(None, asked), ("/map",), "map", 0.0)
    assert asked == [] and used.grid is None
    assert used.note == "--map-wait 0: the stack's map was not read: pre-flight skipped"
