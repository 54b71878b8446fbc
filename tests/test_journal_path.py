"""The journal keeps the driven path as a thinned polyline that stays near every pose."""

from __future__ import annotations

import itertools
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.executor.events import WaypointProgress
from navseq.journal.path import HEARTBEAT, PATH_TOLERANCE, ProgressThinner


def pose(t: float, x: float, y: float) -> WaypointProgress:
    return WaypointProgress(t, 0, x, y, 0.0, None, 0.0)


def thinned(poses: list[WaypointProgress]) -> list[WaypointProgress]:
    thinner = ProgressThinner()
    kept = [kept for p in poses for kept in thinner.offer(p)]
    last = thinner.flush()
    return kept + ([last] if last is not None else [])


def distance_to_segment(p: WaypointProgress, a: WaypointProgress, b: WaypointProgress) -> float:
    dx, dy = b.x - a.x, b.y - a.y
    length = dx * dx + dy * dy
    along = (
        0.0 if length == 0 else min(1.0, max(0.0, ((p.x - a.x) * dx + (p.y - a.y) * dy) / length))
    )
    return math.hypot(p.x - a.x - along * dx, p.y - a.y - along * dy)


# A robot's walk: each step turns a little (or a lot) and moves up to 5 cm in 0.1 s,
# or stands still.
steps = st.lists(
    st.tuples(st.floats(-math.pi, math.pi), st.floats(0.0, 0.05)), min_size=1, max_size=400
)


@settings(max_examples=200, deadline=None)
@given(steps=steps, turniness=st.floats(0.0, 1.0))
def test_every_pose_lies_near_the_journaled_path_and_no_gap_exceeds_the_heartbeat(
    steps: list[tuple[float, float]], turniness: float
) -> None:
    poses, heading, x, y = [], 0.0, 0.0, 0.0
    for number, (turn, length) in enumerate(steps):
        heading += turn * turniness
        x, y = x + length * math.cos(heading), y + length * math.sin(heading)
        poses.append(pose(number * 0.1, x, y))
    kept = thinned(poses)
    assert kept[0] is poses[0] and kept[-1] is poses[-1]
    positions = [poses.index(k) for k in kept]
    assert positions == sorted(positions)  # a subsequence, in order
    for (i, a), (j, b) in itertools.pairwise(zip(positions, kept, strict=True)):
        assert b.t - a.t <= HEARTBEAT + 0.1 + 1e-9
        for between in poses[i:j]:
            assert distance_to_segment(between, a, b) <= PATH_TOLERANCE * math.sqrt(2) + 1e-9


def test_a_lap_of_a_square_costs_its_corners() -> None:
    corners = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0), (0.0, 0.0)]
    poses = []
    for (ax, ay), (bx, by) in itertools.pairwise(corners):
        for k in range(100):  # 10 s a side: no heartbeat
            fraction = k / 100
            poses.append(
                pose(len(poses) * 0.1, ax + (bx - ax) * fraction, ay + (by - ay) * fraction)
            )
    poses.append(pose(len(poses) * 0.1, 0.0, 0.0))
    kept = thinned(poses)
    assert len(kept) == len(corners)  # 401 poses, one line per corner
    for (x, y), k in zip(corners, kept, strict=True):
        assert math.hypot(k.x - x, k.y - y) <= PATH_TOLERANCE


def test_coming_back_along_the_same_line_keeps_the_turning_point() -> None:
    out_and_back = [pose(i * 0.1, 0.02 * i, 0.0) for i in range(100)]
    out_and_back += [pose(10 + i * 0.1, 2.0 - 0.02 * i, 0.0) for i in range(100)]
    kept = thinned(out_and_back)
    # A straight line from 0 back to 0 would lose the far end.
    assert max(k.x for k in kept) >= 2.0 - PATH_TOLERANCE
