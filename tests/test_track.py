"""What a run keeps of its paths stays true to them and bounded however long it runs."""

from __future__ import annotations

import itertools
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.track import Track, kept_indices, simplify_path

coordinates = st.floats(-50.0, 50.0, allow_nan=False)
polylines = st.lists(st.tuples(coordinates, coordinates), min_size=0, max_size=200)


def distance_to_segment(p, a, b) -> float:
    ex, ey = b[0] - a[0], b[1] - a[1]
    length_squared = ex * ex + ey * ey
    t = 0.0
    if length_squared > 0.0:
        t = max(0.0, min(1.0, ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / length_squared))
    return math.hypot(p[0] - a[0] - t * ex, p[1] - a[1] - t * ey)


@settings(max_examples=300, deadline=None)
@given(polylines, st.sampled_from([0.005, 0.01, 0.1, 1.0]))
def test_a_simplified_path_keeps_its_ends_and_stays_within_the_tolerance(points, tolerance):
    kept = kept_indices(points, tolerance)
    assert simplify_path(points, tolerance) == tuple(points[i] for i in kept)
    if not points:
        return
    assert kept[0] == 0 and kept[-1] == len(points) - 1 and kept == sorted(set(kept))
    # Every dropped point lies near the segment between the kept points around it.
    for first, last in itertools.pairwise(kept):
        for point in points[first + 1 : last]:
            assert distance_to_segment(point, points[first], points[last]) <= tolerance + 1e-9


def test_a_corridor_plan_becomes_its_corners() -> None:
    plan = [(0.05 * i, 0.0) for i in range(200)] + [(9.95, 0.05 * i) for i in range(1, 200)]
    corners = simplify_path(plan, 0.01)
    assert [(round(x, 6), round(y, 6)) for x, y in corners] == [(0, 0), (9.95, 0), (9.95, 9.95)]


@settings(max_examples=50, deadline=None)
@given(st.integers(1, 20_000), st.integers(4, 500))
def test_a_track_stays_bounded_and_in_order(steps, max_points) -> None:
    track = Track(min_step=0.01, min_interval=10.0, max_points=max_points)
    for i in range(steps):
        track.append((0.1 * i, 0.02 * i, 0.0))
        if i == steps // 2:
            track.append((math.nan, math.nan, math.nan))
    rows = track.rows()
    assert len(rows) < max_points + 2  # the newest point and a break may ride along
    times = [row[0] for row in rows if not math.isnan(row[1])]
    assert times == sorted(times) and times[0] == 0.0
    assert sum(math.isnan(row[1]) for row in rows) == 1  # breaks are never thinned away


def test_a_track_records_a_stop_as_time_spent_in_place() -> None:
    track = Track(min_step=0.05, min_interval=0.5)
    for i in range(40):
        track.append((0.1 * i, 0.0, 0.0))  # standing still for 4 s
    assert len(track) == 8  # one row per half second
