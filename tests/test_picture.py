"""The mission picture: map orientation, outcome colours, cropping, the PNG file, and
readability from 1 to 5000 waypoints (labels, coincident and off-map waypoints,
patrols cut short, thinning).

Set ``NAVSEQ_PICTURES=/some/folder`` to keep the PNGs of the readability cases, to look
at them.
"""

from __future__ import annotations

import itertools
import math
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult, WaypointResult
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Policy, Waypoint
from navseq.sim.mapgen import office_map, warehouse_map
from navseq.sim.occupancy import OccupancyGrid
from navseq.sinks.picture.draw import (
    STATUS_COLOURS,
    Status,
    draw_mission_picture,
    mission_figure,
    waypoint_outcomes,
)
from navseq.sinks.picture.thin import coincident_groups, map_image, thin_segments

RES = 0.05
ORIGIN = Pose2D(-1.0, -2.0, 0.0)
REACHED, SKIPPED, FAILED, NOT_RUN = (
    WaypointOutcome.REACHED,
    WaypointOutcome.SKIPPED,
    WaypointOutcome.FAILED,
    WaypointOutcome.NOT_RUN,
)


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


def visits_result(mission: Mission, outcomes, reason: str = "stopped") -> MissionResult:
    """One visit per waypoint with the given outcomes (WaypointOutcome or (outcome, reason))."""
    visits = []
    for index, (waypoint, outcome) in enumerate(zip(mission.waypoints, outcomes, strict=True)):
        why = ""
        if isinstance(outcome, tuple):
            outcome, why = outcome
        visits.append(
            WaypointResult(
                index, 0, waypoint.name, waypoint.x, waypoint.y, 0.0, outcome, reason=why
            )
        )
    return MissionResult(False, reason, visits, duration=100.0, distance_driven=20.0)


def pixel(fig, x: float, y: float, dx: float = 0.0) -> np.ndarray:
    """RGB (0..1) of the rendered figure at world point (x, y), dx pixels to the right."""
    fig.canvas.draw()
    buffer = np.asarray(fig.canvas.buffer_rgba())
    px, py = fig.axes[0].transData.transform((x, y))
    return buffer[round(float(buffer.shape[0] - py)), round(float(px + dx)), :3] / 255.0


def hex_rgb(colour: str) -> np.ndarray:
    return np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)]) / 255.0


def legend_texts(fig) -> list[str]:
    legends = [a.get_legend() for a in fig.axes if a.get_legend() is not None]
    assert len(legends) == 1
    return [t.get_text() for t in legends[0].get_texts()]


def labels(fig) -> list:
    """The waypoint labels drawn (text artists), after a draw so their extents are known."""
    fig.canvas.draw()
    return [t for t in fig.axes[0].texts if t.get_gid() == "waypoint-label"]


def disc_numbers(fig) -> list[str]:
    return [t.get_text() for t in fig.axes[0].texts if t.get_gid() != "waypoint-label"]


def overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def assert_readable(fig) -> list:
    """No label leaves the map axes, overlaps another label, the legend or the colour bar."""
    drawn = labels(fig)
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_bbox_patch().get_window_extent(renderer) for t in drawn]
    frame = fig.axes[0].get_window_extent(renderer)
    for box in boxes:
        assert frame.x0 - 1 <= box.x0 and box.x1 <= frame.x1 + 1, "label clipped left/right"
        assert frame.y0 - 1 <= box.y0 and box.y1 <= frame.y1 + 1, "label clipped top/bottom"
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not overlap(a.shrunk(0.98, 0.98), b.shrunk(0.98, 0.98)), "labels overlap"
    legend = fig.axes[1].get_legend().get_window_extent(renderer)
    whole = fig.bbox
    assert whole.x0 <= legend.x0 and legend.x1 <= whole.x1, "legend cut by the figure's edge"
    assert whole.y0 <= legend.y0 and legend.y1 <= whole.y1, "legend cut by the figure's edge"
    others = [legend]
    others += [a.get_window_extent(renderer) for a in fig.axes[2:]]  # the colour bar
    for other in others:
        assert not overlap(frame, other), "legend or colour bar over the map"
        assert not any(overlap(box, other) for box in boxes)
    return drawn


def markers_xy(fig) -> np.ndarray:
    """Centres (display pixels) of every waypoint disc or dot drawn in the map axes."""
    from matplotlib.collections import PathCollection

    ax = fig.axes[0]
    points = [
        ax.transData.transform(c.get_offsets())
        for c in ax.collections
        if isinstance(c, PathCollection) and len(c.get_offsets())
    ]
    return np.concatenate(points) if points else np.zeros((0, 2))


def save(fig, name: str, tmp_path: Path) -> Path:
    """Write the PNG (and keep it in $NAVSEQ_PICTURES, to look at)."""
    path = tmp_path / f"{name}.png"
    fig.savefig(path)
    keep = os.environ.get("NAVSEQ_PICTURES")
    if keep:
        Path(keep).mkdir(parents=True, exist_ok=True)
        fig.savefig(Path(keep) / f"{name}.png")
    return path


def random_mission(grid: OccupancyGrid, count: int, seed: int, name: str) -> Mission:
    """``count`` waypoints on free cells, in the order of a sweep (1 m bands, boustrophedon)."""
    rng = np.random.default_rng(seed)
    rows, cols = np.nonzero(grid.data == 0)
    chosen = rng.choice(len(rows), size=count, replace=False)
    xy = grid.cells_to_world(rows[chosen], cols[chosen])
    band = np.floor(xy[:, 1]).astype(int)
    xy = xy[np.lexsort((np.where(band % 2, -xy[:, 0], xy[:, 0]), band))]
    return Mission(
        tuple(
            Waypoint(float(x), float(y), yaw_rad=float(rng.uniform(-3, 3)), name=f"bay-{i + 1}")
            for i, (x, y) in enumerate(xy)
        ),
        source=f"{name}.yaml",
    )


def tour(mission: Mission) -> list[tuple[float, float, float]]:
    """A driven path straight through the waypoints, 20 rows per leg."""
    xy = np.array([(w.x, w.y) for w in mission.waypoints])
    rows = []
    for leg, (a, b) in enumerate(itertools.pairwise(xy)):
        for f in np.linspace(0, 1, 20, endpoint=False):
            x, y = a + f * (b - a)
            rows.append((leg + f, float(x), float(y)))
    return rows


# --------------------------------------------------------------------------- the map


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


def test_a_large_map_is_reduced_to_about_a_cell_per_pixel_keeping_thin_walls():
    data = np.zeros((4000, 4000), dtype=np.int8)
    data[:, 2001] = 100  # a one-cell wall
    image, factor = map_image(data, slice(0, 4000), slice(0, 4000), cells_per_pixel=4.0)
    assert factor == 4 and image.shape == (1000, 1000)
    assert image[:, 500].max() < 40  # the wall survives: darkest cell of each block
    assert image[:, 10].min() == 255


def test_view_is_cropped_to_the_mission_on_a_big_map():
    big = OccupancyGrid(
        np.zeros((2000, 2000), dtype=np.int8), 0.05, Pose2D(-50.0, -50.0), source="big.yaml"
    )
    fig = mission_figure(MISSION, result_of(), grid=big)
    xmin, xmax = fig.axes[0].get_xlim()
    ymin, ymax = fig.axes[0].get_ylim()
    assert xmin <= 1.0 and xmax >= 2.0 and ymin <= -1.0 and ymax >= 1.0
    assert xmax - xmin < 8.0 and ymax - ymin < 8.0
    # Only the part of the map in view is turned into an image.
    (image,) = fig.axes[0].images
    assert image.get_array().size < 200 * 200


def test_a_small_mapped_arena_is_shown_whole():
    fig = mission_figure(MISSION, result_of(), grid=make_grid())
    xmin, xmax = fig.axes[0].get_xlim()
    ymin, ymax = fig.axes[0].get_ylim()
    assert xmin <= -1.0 + RES and xmax >= 4.0 - RES
    assert ymin <= -2.0 + RES and ymax >= 2.0 - RES


# --------------------------------------------------------------------------- outcomes


def test_waypoints_are_coloured_by_their_outcome():
    outcomes = result_of(REACHED, FAILED, NOT_RUN)
    fig = mission_figure(MISSION, outcomes, grid=make_grid())
    # Left of the centre: away from the white number and the heading arrow (yaw 0).
    for waypoint, status in zip(
        WAYPOINTS, (Status.REACHED, Status.FAILED, Status.NOT_RUN), strict=True
    ):
        colour = pixel(fig, waypoint.x, waypoint.y, dx=-9)
        assert np.allclose(colour, hex_rgb(STATUS_COLOURS[status]), atol=0.06), status


def test_a_patrol_waypoint_shows_its_worst_visit_that_ran():
    outcomes = waypoint_outcomes(result_of(REACHED, REACHED, REACHED, REACHED, SKIPPED, NOT_RUN), 3)
    assert [outcomes[i] for i in range(3)] == [Status.REACHED, Status.SKIPPED, Status.REACHED]
    assert list(outcomes.reached) == [2, 1, 1] and list(outcomes.ended) == [2, 2, 1]


def patrol_interrupted(laps: int, cut_at: int) -> MissionResult:
    """``laps`` good laps of MISSION, then Ctrl-C while driving to waypoint ``cut_at``."""
    visits = [
        WaypointResult(i, lap, None, w.x, w.y, 0.0, REACHED)
        for lap in range(laps)
        for i, w in enumerate(WAYPOINTS)
    ]
    w = WAYPOINTS[cut_at]
    visits.append(
        WaypointResult(cut_at, laps, None, w.x, w.y, 0.0, FAILED, reason="interrupted: SIGINT")
    )
    return MissionResult(False, "interrupted: SIGINT", visits, duration=9e4, distance_driven=9e3)


def test_a_patrol_point_interrupted_after_1806_good_laps_is_reached_with_a_ring(tmp_path):
    result = patrol_interrupted(1806, cut_at=1)
    outcomes = waypoint_outcomes(result, 3)
    assert [outcomes[i] for i in range(3)] == [Status.REACHED] * 3
    assert list(outcomes.interrupted) == [False, True, False]
    assert outcomes.reached[1] == 1806

    fig = mission_figure(MISSION, result, grid=make_grid(), interrupted="SIGINT")
    save(fig, "patrol-interrupted", tmp_path)
    green = hex_rgb(STATUS_COLOURS[Status.REACHED])
    assert np.allclose(pixel(fig, 2.0, 0.0, dx=-9), green, atol=0.06)  # not red
    # A ring in the "interrupted" colour around it says where the run was cut short.
    ring = pixel(fig, 2.0, 0.0, dx=-23)
    assert np.allclose(ring, hex_rgb(STATUS_COLOURS[Status.INTERRUPTED]), atol=0.1), ring
    texts = legend_texts(fig)
    assert "interrupted here" in texts and not any(t.startswith("failed") for t in texts)
    assert "5,418/5,419 visits reached" in fig.axes[0].get_title(loc="left")


def test_a_waypoint_the_operator_cancelled_on_is_not_drawn_failed():
    """A Stop or ~cancel cuts the visit short as Ctrl-C does: the robot did not fail it."""
    w = WAYPOINTS[1]
    reason = "cancelled by the operator (~cancel)"
    visits = [
        WaypointResult(0, 0, None, WAYPOINTS[0].x, WAYPOINTS[0].y, 0.0, REACHED),
        WaypointResult(1, 0, None, w.x, w.y, 0.0, FAILED, reason=reason),
    ]
    outcomes = waypoint_outcomes(MissionResult(False, reason, visits, duration=30.0), 3)
    assert outcomes[1] is Status.INTERRUPTED and list(outcomes.interrupted) == [False, True, False]


def test_a_patrol_longer_than_the_report_lists_is_drawn_from_its_totals():
    """The result of a long patrol lists only its last visits; the picture counts all."""
    from navseq.executor.result import VisitLog

    log = VisitLog(MISSION.waypoints, None)
    for visit in patrol_interrupted(1806, cut_at=1).visits:
        log.add(visit)
    result = log.result(
        success=False, reason="interrupted: SIGINT", duration=9e4, loops_completed=1806
    )
    assert result.omitted_visits > 0  # the premise: not every visit is listed
    outcomes = waypoint_outcomes(result, 3)
    assert [outcomes[i] for i in range(3)] == [Status.REACHED] * 3
    assert list(outcomes.interrupted) == [False, True, False]
    assert outcomes.reached[1] == 1806
    fig = mission_figure(MISSION, result, grid=make_grid(), interrupted="SIGINT")
    assert "5,418/5,419 visits reached" in fig.axes[0].get_title(loc="left")


def test_a_waypoint_only_ever_interrupted_is_interrupted_and_a_real_failure_is_failed():
    mission = Mission(WAYPOINTS, source="m.yaml")
    cut = visits_result(mission, [REACHED, (FAILED, "interrupted: SIGTERM"), NOT_RUN])
    stopped = visits_result(mission, [REACHED, (FAILED, "aborted by the server"), NOT_RUN])
    assert waypoint_outcomes(cut, 3)[1] is Status.INTERRUPTED
    assert waypoint_outcomes(stopped, 3)[1] is Status.FAILED
    fig = mission_figure(mission, cut, grid=make_grid())
    colour = pixel(fig, 2.0, 0.0, dx=-9)
    assert np.allclose(colour, hex_rgb(STATUS_COLOURS[Status.INTERRUPTED]), atol=0.06)
    assert any(t.startswith("interrupted") for t in legend_texts(fig))


# --------------------------------------------------------------------------- readable at scale


def test_one_waypoint(tmp_path):
    mission = Mission((Waypoint(1.0, 0.5, yaw_rad=0.5, name="dock"),), source="one.yaml")
    result = visits_result(mission, [REACHED])
    fig = mission_figure(mission, result, grid=make_grid(), start=Pose2D(0.0, 0.0, 0.0))
    save(fig, "size-1", tmp_path)
    drawn = assert_readable(fig)
    assert [t.get_text() for t in drawn] == ["dock"]
    assert disc_numbers(fig) == ["1"]
    assert "1 waypoint ·" in fig.axes[0].get_title(loc="left")


def test_ten_waypoints_are_all_numbered_and_named(tmp_path):
    grid = office_map(3)
    mission = random_mission(grid, 10, seed=1, name="office-10")
    result = visits_result(mission, [REACHED] * 6 + [SKIPPED, REACHED, FAILED, NOT_RUN])
    fig = mission_figure(
        mission, result, grid=grid, trajectory=tour(mission), start=mission.waypoints[0].pose
    )
    save(fig, "size-10", tmp_path)
    drawn = assert_readable(fig)
    assert sorted(t.get_text() for t in drawn) == sorted(f"bay-{i}" for i in range(1, 11))
    assert sorted(disc_numbers(fig), key=int) == [str(i) for i in range(1, 11)]


def test_a_hundred_waypoints_each_have_a_marker_and_labels_do_not_collide(tmp_path):
    grid = office_map(5)
    mission = random_mission(grid, 100, seed=2, name="office-100")
    outcomes = [REACHED] * 80 + [SKIPPED] * 5 + [FAILED] + [NOT_RUN] * 14
    fig = mission_figure(mission, visits_result(mission, outcomes), grid=grid)
    save(fig, "size-100", tmp_path)
    drawn = assert_readable(fig)
    # Every waypoint is within a marker's radius of a marker drawn in the axes.
    from scipy.spatial import cKDTree

    ax = fig.axes[0]
    centres = ax.transData.transform([(w.x, w.y) for w in mission.waypoints])
    distance, _ = cKDTree(markers_xy(fig)).query(centres)
    assert distance.max() <= 16  # pixels: within the disc (or dot) drawn for it
    frame = ax.get_window_extent()
    assert frame.contains(*centres.min(axis=0)) and frame.contains(*centres.max(axis=0))
    # The failed one is labelled, whatever else had to be left out.
    assert any(t.get_text().split()[0] in {"86", "bay-86"} for t in drawn) or "86" in disc_numbers(
        fig
    )


def test_five_thousand_waypoints_label_a_bounded_spread_out_subset(tmp_path):
    grid = warehouse_map(4)
    mission = random_mission(grid, 5000, seed=3, name="warehouse-5000")
    # As in the issue: 1333 ran (a few skipped), one failed and stopped it, 3666 not run.
    outcomes = [SKIPPED if i % 97 == 0 else REACHED for i in range(1333)]
    outcomes += [FAILED] + [NOT_RUN] * 3666
    result = visits_result(mission, outcomes)
    ran = mission.waypoints[:1334]
    trajectory = tour(Mission(ran, source="x"))
    fig = mission_figure(mission, result, grid=grid, trajectory=trajectory, start=ran[0].pose)
    save(fig, "size-5000", tmp_path)
    drawn = assert_readable(fig)
    texts = [t.get_text() for t in drawn]
    assert 10 <= len(texts) <= 60
    numbers = {t.split()[0] for t in texts}
    assert {"1", "5000", "1334"} <= numbers  # first, last, the failure
    # Spread out: labels in every quarter of the map.
    centres = np.array([t.get_position() for t in drawn])
    midx, midy = 15.0, 10.0
    quarters = {(x > midx, y > midy) for x, y in centres}
    assert len(quarters) == 4
    assert any("labelled" in (a.get_legend().get_title().get_text()) for a in fig.axes[1:2])
    # Every waypoint has its dot: the dots drawn cover all of them.
    from scipy.spatial import cKDTree

    centres = fig.axes[0].transData.transform([(w.x, w.y) for w in mission.waypoints])
    distance, _ = cKDTree(markers_xy(fig)).query(centres)
    assert distance.max() <= 3


@pytest.mark.parametrize("count", [1, 2])
def test_degenerate_missions_do_not_break_the_picture(tmp_path, count):
    mission = Mission((Waypoint(0.0, 0.0, yaw_rad=0.0),) * count, source="one.yaml")
    draw_mission_picture(tmp_path / "one.png", mission, MissionResult(True, "completed"))
    assert (tmp_path / "one.png").exists()


def test_coincident_waypoints_are_one_marker_with_a_count_and_their_numbers(tmp_path):
    home = Waypoint(0.0, 0.0, yaw_rad=0.0, name="home")
    mission = Mission(
        (home, Waypoint(2.0, 0.0, yaw_rad=0.0), home, Waypoint(2.0, 1.0, yaw_rad=0.0), home),
        source="loop.yaml",
    )
    fig = mission_figure(mission, visits_result(mission, [REACHED] * 5), grid=make_grid())
    save(fig, "coincident", tmp_path)
    drawn = assert_readable(fig)
    assert sorted(disc_numbers(fig)) == ["2", "4", "×3"]
    assert "1, 3, 5" in [t.get_text() for t in drawn]
    assert "×n: waypoints at one spot" in legend_texts(fig)


def test_coincident_groups_are_linear_and_exact():
    points = np.array([(0.0, 0.0), (5.0, 5.0), (0.0, 0.001), (5.0, 5.0), (9.0, 9.0)])
    groups = coincident_groups(points, 0.05)
    assert list(groups.first) == [0, 1, 4] and list(groups.sizes) == [2, 2, 1]
    assert list(groups.members(1)) == [1, 3]


def test_off_map_waypoints_are_drawn_on_the_border_pointing_at_them(tmp_path):
    from matplotlib.collections import PatchCollection

    mission = Mission(
        (
            Waypoint(1.0, 0.0, yaw_rad=0.0, name="in"),
            Waypoint(5.0, 0.5, yaw_rad=0.0, name="just-off"),  # 1 m beyond the map's edge
            Waypoint(500.0, 0.0, yaw_rad=0.0, name="typo"),  # far away
        ),
        source="off.yaml",
    )
    fig = mission_figure(
        mission, visits_result(mission, [REACHED, NOT_RUN, NOT_RUN]), grid=make_grid()
    )
    save(fig, "off-map", tmp_path)
    ax = fig.axes[0]
    _, xmax = ax.get_xlim()
    assert xmax > 5.2 and xmax < 20  # extended to the near one, not to the typo
    drawn = assert_readable(fig)
    texts = [t.get_text() for t in drawn]
    assert "3 typo at (500.0, 0.0)" in texts and "just-off" in texts
    (triangles,) = [c for c in ax.collections if isinstance(c, PatchCollection) and c.get_paths()]
    (path,) = triangles.get_paths()
    tip = path.vertices[np.argmax(path.vertices[:, 0])]
    assert xmax - 1.0 < tip[0] <= xmax  # on the right border, pointing right
    assert "beyond the view (points to it)" in legend_texts(fig)
    # The map's edge is drawn, so "just-off" is seen to be off the map.
    (border,) = [p for p in ax.patches if p.get_gid() == "map-border"]
    corners = border.get_xy()
    assert corners[:, 0].max() == pytest.approx(4.0) and corners[:, 0].min() == pytest.approx(-1.0)


def test_without_a_map_a_far_outlier_is_marked_on_the_border_not_zoomed_out_to(tmp_path):
    mission = Mission(
        (
            *(Waypoint(float(i % 4), float(i // 4), yaw_rad=0.0) for i in range(12)),
            Waypoint(1e6, 2.0, yaw_rad=0.0),
        ),
        source="outlier.yaml",
    )
    fig = mission_figure(mission, visits_result(mission, [REACHED] * 13))
    save(fig, "outlier-no-map", tmp_path)
    xmin, xmax = fig.axes[0].get_xlim()
    assert xmin < 0.0 and 3.0 < xmax < 100.0
    texts = [t.get_text() for t in assert_readable(fig)]
    assert "13 at (1000000.0, 2.0)" in texts
    assert sorted(disc_numbers(fig), key=int) == [str(i) for i in range(1, 13)]


def test_thousands_of_far_waypoints_are_a_bounded_row_of_triangles():
    from matplotlib.collections import PatchCollection

    near = tuple(Waypoint(float(i % 60), float(i // 60), yaw_rad=0.0) for i in range(3600))
    # 10 km north of it, spread along it: clipped, they line the whole top border.
    far = tuple(Waypoint(0.06 * i, 1e4, yaw_rad=0.0) for i in range(1000))
    mission = Mission(near + far, source="far.yaml")
    fig = mission_figure(mission, visits_result(mission, [REACHED] * len(mission)))
    (triangles,) = [c for c in fig.axes[0].collections if isinstance(c, PatchCollection)]
    assert 1 <= len(triangles.get_paths()) <= 200
    assert_readable(fig)


# --------------------------------------------------------------------------- thinning


def test_a_long_trajectory_is_thinned_to_a_bounded_number_of_segments():
    from matplotlib.collections import LineCollection

    t = np.linspace(0, 1e5, 1_000_000)
    trajectory = np.column_stack((t, 1.5 + np.cos(t / 50), np.sin(t / 50)))
    fig = mission_figure(MISSION, result_of(REACHED), grid=make_grid(), trajectory=trajectory)
    (driven,) = [
        c
        for c in fig.axes[0].collections
        if isinstance(c, LineCollection) and c.get_array() is not None
    ]
    # 318 laps of one circle, a million rows: drawn as a few laps' worth of segments,
    # the latest on top.
    assert 100 < len(driven.get_segments()) <= 5_000
    times = np.asarray(driven.get_array())
    assert (np.diff(times) >= 0).all() and times[-1] > 0.99 * t[-1]


def test_thinning_keeps_breaks_and_a_short_path_unchanged():
    nan = math.nan
    points = np.array([(0, 0), (1, 0), (nan, nan), (0, 0), (0, 1)], dtype=float)
    segments, values = thin_segments(points, np.array([0, 1, nan, 2, 3.0]), 100.0)
    assert [tuple(map(tuple, s)) for s in segments] == [((0, 0), (1, 0)), ((0, 0), (0, 1))]
    assert list(values) == [0.0, 2.0]


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
    fig = mission_figure(MISSION, result_of(REACHED), trajectory=trajectory)
    (driven,) = [
        c
        for c in fig.axes[0].collections
        if isinstance(c, LineCollection) and c.get_array() is not None
    ]
    segments = [tuple(map(tuple, s)) for s in driven.get_segments()]
    assert segments == [((0.0, 0.0), (1.0, 0.0)), ((0.0, 0.0), (0.0, 1.0))]
    assert list(driven.get_array()) == [0.0, 2.0]  # one mission clock across the break


# --------------------------------------------------------------------------- the file


def test_png_has_title_legend_and_is_written_atomically(tmp_path):
    trajectory = [(0.1 * i, -0.5 + 0.02 * i, -1.0 + 0.01 * i) for i in range(100)]
    plans = [((-0.5, -1.0), (1.0, -1.0)), ((1.0, -1.0), (2.0, 0.0))]
    path = tmp_path / "out" / "mission.png"
    draw_mission_picture(
        path,
        MISSION,
        result_of(REACHED),
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
        result_of(REACHED),
        grid=make_grid(),
        start=Pose2D(-0.5, -1.0, 0.0),
        plans=plans,
        trajectory=trajectory,
        interrupted="SIGINT",
    )
    ax = fig.axes[0]
    assert "demo" in ax.get_title(loc="left") and "interrupted (SIGINT)" in ax.get_title("left")
    texts = legend_texts(fig)
    assert {"start", "planned path", "driven path"} <= set(texts)
    assert any(t.startswith("reached") for t in texts)
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    assert ax.get_aspect() == 1.0
    # The time colour bar is there because a trajectory was drawn.
    assert any("mission time" in a.get_ylabel() for a in fig.axes[1:])
    assert_readable(fig)


def test_picture_without_a_map_still_shows_the_mission(tmp_path):
    path = tmp_path / "m.png"
    draw_mission_picture(path, MISSION, result_of(REACHED))
    assert path.stat().st_size > 10_000


def test_an_empty_mission_still_gives_a_picture(tmp_path):
    mission = Mission((), source="none.yaml")
    draw_mission_picture(tmp_path / "none.png", mission, MissionResult(True, "completed"))
    assert (tmp_path / "none.png").stat().st_size > 1000


def test_the_robot_outline_is_drawn_to_scale_at_the_start() -> None:
    from navseq.mission.robot import TURTLEBOT3_WAFFLE

    start = Pose2D(1.0, 2.0, math.pi / 2)
    fig = mission_figure(MISSION, result_of(REACHED), start=start, robot=TURTLEBOT3_WAFFLE)
    outlines = [p for p in fig.axes[0].patches if p.get_gid() == "robot-outline"]
    assert len(outlines) == 1
    corners = outlines[0].get_xy()[:4]
    # The waffle's rear-left corner (-0.205, 0.155), turned to face +y.
    assert np.allclose(corners[1], (1.0 - 0.155, 2.0 - 0.205))
    assert "turtlebot3_waffle outline" in legend_texts(fig)


def test_tens_of_thousands_of_stacked_waypoints_get_no_more_group_rings_than_dots():
    """A recorded patrol in a small room, positions rounded to the centimetre: thousands
    of spots hold several waypoints. Rings are thinned as the dots are, one per
    dot-sized cell; a ring per group drew 28 000 of them, most of a second of a stopped
    run's picture."""
    from matplotlib.collections import PathCollection

    rng = np.random.default_rng(5)
    xy = np.round(rng.uniform(0.5, 2.5, size=(60_000, 2)), 2)
    mission = Mission(
        tuple(Waypoint(float(x), float(y), yaw_rad=0.0) for x, y in xy), source="room.yaml"
    )
    outcomes = [REACHED] * 50 + [FAILED] + [NOT_RUN] * (len(xy) - 51)
    fig = mission_figure(mission, visits_result(mission, outcomes))
    marks = [c for c in fig.axes[0].collections if isinstance(c, PathCollection)]
    rings = sum(len(c.get_offsets()) for c in marks if not len(c.get_facecolor()))
    dots = sum(len(c.get_offsets()) for c in marks if len(c.get_facecolor()))
    spots, counts = np.unique(xy, axis=0, return_counts=True)
    assert np.count_nonzero(counts > 1) > dots  # the premise: more stacks than dots
    assert 0 < rings <= dots
    # Every waypoint still has a dot within a dot's width of it.
    from scipy.spatial import cKDTree

    centres = fig.axes[0].transData.transform(spots[::20])
    distance, _ = cKDTree(markers_xy(fig)).query(centres)
    assert distance.max() <= 6
