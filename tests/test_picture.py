"""The mission picture: map orientation, outcome colours, cropping, the PNG file."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult, WaypointResult
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Policy, Waypoint
from navseq.sim.occupancy import OccupancyGrid
from navseq.sinks.picture import (
    OUTCOME_COLOURS,
    draw_mission_picture,
    mission_figure,
    waypoint_outcomes,
)

RES = 0.05
ORIGIN = Pose2D(-1.0, -2.0, 0.0)


def make_grid(origin: Pose2D = ORIGIN) -> OccupancyGrid:
    """5 m x 4 m: an obstacle block in the bottom-left metre, unknown top-right metre."""
    data = np.zeros((80, 100), dtype=np.int8)
    data[0:20, 0:20] = 100  # row 0 is the bottom of the map
    data[60:80, 80:100] = -1
    return OccupancyGrid(data=data, resolution=RES, origin=origin, source="test.yaml")


WAYPOINTS = (
    Waypoint(1.0, -1.0, yaw_rad=0.0, name="a"),
    Waypoint(2.0, 0.0, yaw_rad=0.0),
    Waypoint(1.0, 1.0, yaw_rad=0.0, name="c"),
)
MISSION = Mission(WAYPOINTS, defaults=Policy(pass_through_m=0.3), source="demo.yaml")


def result_of(*outcomes: WaypointOutcome) -> MissionResult:
    visits = [
        WaypointResult(i % 3, i // 3, None, WAYPOINTS[i % 3].x, WAYPOINTS[i % 3].y, 0.0, outcome=o)
        for i, o in enumerate(outcomes)
    ]
    return MissionResult(
        success=False,
        reason="stopped: waypoint 2 failed",
        visits=visits,
        duration=42.0,
        distance_driven=3.2,
    )


def pixel(fig, x: float, y: float, dx: float = 0.0) -> np.ndarray:
    """RGB (0..1) of the rendered figure at world point (x, y), dx pixels to the right."""
    fig.canvas.draw()
    buffer = np.asarray(fig.canvas.buffer_rgba())
    px, py = fig.axes[0].transData.transform((x, y))
    return buffer[round(float(buffer.shape[0] - py)), round(float(px + dx)), :3] / 255.0


def hex_rgb(colour: str) -> np.ndarray:
    return np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)]) / 255.0


def test_map_is_drawn_in_metres_with_row_zero_at_the_bottom():
    fig = mission_figure(MISSION, result_of(), grid=make_grid())
    # Points off the 0.5 m grid lines.
    occupied = pixel(fig, -0.6, -1.4)  # bottom-left block
    above_it = pixel(fig, -0.6, 1.4)  # same column, top of the map: free
    unknown = pixel(fig, 3.6, 1.4)  # top-right block
    assert occupied.max() < 0.2
    assert above_it.min() > 0.95
    assert np.allclose(unknown, 205 / 255, atol=0.02)


def test_map_origin_yaw_rotates_the_map_about_its_origin():
    # Rotated by +90°, the map's x axis points along world +y: the obstacle block at
    # map (0..1, 0..1) m lies at world x in (-2, -1), y in (-2, -1) from origin (-1, -2).
    grid = make_grid(Pose2D(-1.0, -2.0, math.pi / 2))
    mission = Mission(
        (Waypoint(-3.0, 0.0, yaw_rad=0.0), Waypoint(-1.5, 2.5, yaw_rad=0.0)), source="r.yaml"
    )
    fig = mission_figure(mission, MissionResult(False, "x"), grid=grid)
    assert pixel(fig, -1.4, -1.4).max() < 0.2
    # Where the block would be if the yaw were ignored, there is no map at all (white).
    assert pixel(fig, -0.4, -1.6).min() > 0.95


def test_waypoints_are_coloured_by_their_worst_visit():
    outcomes = result_of(
        WaypointOutcome.REACHED,
        WaypointOutcome.FAILED,
        WaypointOutcome.NOT_RUN,
    )
    fig = mission_figure(MISSION, outcomes, grid=make_grid())
    # Left of the centre: away from the white number and the heading arrow (yaw 0).
    for waypoint, outcome in zip(
        WAYPOINTS,
        (WaypointOutcome.REACHED, WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN),
        strict=True,
    ):
        colour = pixel(fig, waypoint.x, waypoint.y, dx=-9)
        assert np.allclose(colour, hex_rgb(OUTCOME_COLOURS[outcome]), atol=0.06), outcome


def test_a_patrol_waypoint_shows_its_worst_visit():
    r = result_of(
        WaypointOutcome.REACHED,
        WaypointOutcome.REACHED,
        WaypointOutcome.REACHED,
        WaypointOutcome.REACHED,
        WaypointOutcome.SKIPPED,
        WaypointOutcome.NOT_RUN,
    )
    assert waypoint_outcomes(r, 3) == [
        WaypointOutcome.REACHED,
        WaypointOutcome.SKIPPED,
        WaypointOutcome.REACHED,
    ]


def test_view_is_cropped_to_the_mission_on_a_big_map():
    big = OccupancyGrid(
        np.zeros((2000, 2000), dtype=np.int8), 0.05, Pose2D(-50.0, -50.0), source="big.yaml"
    )
    fig = mission_figure(MISSION, result_of(), grid=big)
    xmin, xmax = fig.axes[0].get_xlim()
    ymin, ymax = fig.axes[0].get_ylim()
    assert xmin <= 1.0 and xmax >= 2.0 and ymin <= -1.0 and ymax >= 1.0
    assert xmax - xmin < 5.0 and ymax - ymin < 5.0


def test_a_small_mapped_arena_is_shown_whole():
    fig = mission_figure(MISSION, result_of(), grid=make_grid())
    xmin, xmax = fig.axes[0].get_xlim()
    ymin, ymax = fig.axes[0].get_ylim()
    assert xmin <= -1.0 + RES and xmax >= 4.0 - RES
    assert ymin <= -2.0 + RES and ymax >= 2.0 - RES


def test_png_has_title_legend_and_is_written_atomically(tmp_path):
    trajectory = [(0.1 * i, -0.5 + 0.02 * i, -1.0 + 0.01 * i) for i in range(100)]
    plans = [((-0.5, -1.0), (1.0, -1.0)), ((1.0, -1.0), (2.0, 0.0))]
    path = tmp_path / "out" / "mission.png"
    draw_mission_picture(
        path,
        MISSION,
        result_of(WaypointOutcome.REACHED),
        grid=make_grid(),
        start=Pose2D(-0.5, -1.0, 0.0),
        plans=plans,
        trajectory=trajectory,
    )
    with Image.open(path) as image:
        assert image.format == "PNG"
        assert image.width >= 800 and image.height >= 500
    assert [p.name for p in path.parent.iterdir()] == ["mission.png"]

    fig = mission_figure(
        MISSION,
        result_of(WaypointOutcome.REACHED),
        grid=make_grid(),
        start=Pose2D(-0.5, -1.0, 0.0),
        plans=plans,
        trajectory=trajectory,
        interrupted="SIGINT",
    )
    ax = fig.axes[0]
    assert "demo" in ax.get_title(loc="left") and "interrupted (SIGINT)" in ax.get_title("left")
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"reached", "start", "planned path", "driven path"} <= set(labels)
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    assert ax.get_aspect() == 1.0
    # The time colour bar is there because a trajectory was drawn.
    assert any("mission time" in a.get_ylabel() for a in fig.axes[1:])


def test_picture_without_a_map_still_shows_the_mission(tmp_path):
    path = tmp_path / "m.png"
    draw_mission_picture(path, MISSION, result_of(WaypointOutcome.REACHED))
    assert path.stat().st_size > 10_000


@pytest.mark.parametrize("count", [1, 2])
def test_degenerate_missions_do_not_break_the_picture(tmp_path, count):
    mission = Mission((Waypoint(0.0, 0.0, yaw_rad=0.0),) * count, source="one.yaml")
    draw_mission_picture(tmp_path / "one.png", mission, MissionResult(True, "completed"))
    assert (tmp_path / "one.png").exists()


def test_a_nan_row_breaks_the_driven_path_between_resumed_segments():
    from matplotlib.collections import LineCollection

    nan = math.nan
    # Before the crash the robot got to (1, 0); the resumed run started again at (0, 0).
    trajectory = [
        (0.0, 0.0, 0.0),
        (1.0, 1.0, 0.0),
        (nan, nan, nan),
        (2.0, 0.0, 0.0),
        (3.0, 0.0, 1.0),
    ]
    fig = mission_figure(MISSION, result_of(WaypointOutcome.REACHED), trajectory=trajectory)
    (driven,) = [c for c in fig.axes[0].collections if isinstance(c, LineCollection)]
    segments = [tuple(map(tuple, s)) for s in driven.get_segments()]
    assert segments == [((0.0, 0.0), (1.0, 0.0)), ((0.0, 0.0), (0.0, 1.0))]
    assert list(driven.get_array()) == [0.0, 2.0]  # one mission clock across the break


def test_the_robot_outline_is_drawn_to_scale_at_the_start() -> None:
    from matplotlib.patches import Polygon

    from navseq.mission.robot import TURTLEBOT3_WAFFLE
    from navseq.sinks.picture import mission_figure

    start = Pose2D(1.0, 2.0, math.pi / 2)
    fig = mission_figure(
        MISSION, result_of(WaypointOutcome.REACHED), start=start, robot=TURTLEBOT3_WAFFLE
    )
    outlines = [p for p in fig.axes[0].patches if type(p) is Polygon]  # not the arrows
    assert len(outlines) == 1
    corners = outlines[0].get_xy()[:4]
    # The waffle's rear-left corner (-0.205, 0.155), turned to face +y.
    assert np.allclose(corners[1], (1.0 - 0.155, 2.0 - 0.205))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert "turtlebot3_waffle outline" in labels
