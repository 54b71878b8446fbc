"""Path smoothing (Nav2's SimpleSmoother rules, navseq.sim.smoother)."""

from __future__ import annotations

import numpy as np

from navseq.sim.smoother import SmootherParams, headings, smooth_path


def _turning(points: np.ndarray) -> float:
    """Sum of the heading changes along ``points`` (radians): how much a robot turns."""
    yaws = np.arctan2(*np.diff(points, axis=0).T[::-1])
    return float(np.abs(np.angle(np.exp(1j * np.diff(yaws)))).sum())


def test_a_staircase_path_is_smoothed_its_ends_kept_and_its_points_near() -> None:
    stairs = np.array([(i * 0.05 + (i % 2) * 0.05, (i // 2) * 0.05) for i in range(40)])
    smoothed = smooth_path(stairs)
    assert smoothed.completed
    assert np.array_equal(smoothed.points[[0, -1]], stairs[[0, -1]])
    assert _turning(smoothed.points) < 0.5 * _turning(stairs)
    assert np.hypot(*(smoothed.points - stairs).T).max() < 0.05  # still the same route


def test_a_straight_path_stays_as_it_is() -> None:
    line = np.column_stack((np.linspace(0, 2, 41), np.zeros(41)))
    assert np.allclose(smooth_path(line).points, line)


def test_a_path_that_does_not_settle_comes_back_unchanged() -> None:
    stairs = np.array([(i * 0.05 + (i % 2) * 0.05, (i // 2) * 0.05) for i in range(40)])
    smoothed = smooth_path(stairs, SmootherParams(max_iterations=3))
    assert not smoothed.completed
    assert np.array_equal(smoothed.points, stairs)


def test_short_paths_have_nothing_to_smooth() -> None:
    two = np.array([(0.0, 0.0), (1.0, 0.0)])
    assert np.array_equal(smooth_path(two).points, two)


def test_headings_face_the_next_point_and_end_with_the_goals() -> None:
    points = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)])
    assert np.allclose(headings(points, 3.0), [0.0, np.pi / 2, 3.0])
