"""Path smoothing as Nav2's ``SimpleSmoother`` does it (nav2_bringup's ``smoother_server``).

Each interior point is pulled toward its place on the original path (``w_data``) and
toward the middle of its neighbours (``w_smooth``); the end points stay. The pulls are
repeated until the points move less than ``tolerance`` in one pass, at most
``max_iterations`` passes; a path that did not settle by then is given back unchanged,
as Nav2 does. ``refinements`` more rounds start again from the smoothed path. Nav2
updates one point at a time (Gauss-Seidel); here every point moves at once (Jacobi, in
numpy), which settles on the same path a little more slowly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt


@dataclass(frozen=True)
class SmootherParams:
    """nav2_bringup's ``simple_smoother`` parameters (Jazzy)."""

    tolerance: float = 1.0e-10
    max_iterations: int = 1000
    w_data: float = 0.2
    w_smooth: float = 0.3
    refinements: int = 2  # do_refinement: true, refinement_num: 2


@dataclass(frozen=True)
class Smoothed:
    """The smoothed points and whether every round settled (Nav2's ``was_completed``)."""

    points: npt.NDArray[np.float64]
    completed: bool


def smooth_path(points: npt.ArrayLike, params: SmootherParams | None = None) -> Smoothed:
    """``points`` (N, 2) smoothed; see the module docstring."""
    params = params or SmootherParams()
    original = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(original) < 3:
        return Smoothed(original.copy(), True)
    current = original
    for _ in range(1 + params.refinements):
        smoothed = _smooth_once(current, params)
        if smoothed is None:
            return Smoothed(current, False)
        current = smoothed
    return Smoothed(current, True)


def _smooth_once(
    original: npt.NDArray[np.float64], params: SmootherParams
) -> npt.NDArray[np.float64] | None:
    path = original.copy()
    for _ in range(params.max_iterations):
        inner = path[1:-1]
        pull = params.w_data * (original[1:-1] - inner) + params.w_smooth * (
            path[:-2] + path[2:] - 2.0 * inner
        )
        path[1:-1] = inner + pull
        if float(np.abs(pull).sum()) < params.tolerance:
            return path
    return None


def headings(points: npt.NDArray[np.float64], last_yaw: float) -> npt.NDArray[np.float64]:
    """Each point's yaw along the path (toward the next point); the last one ``last_yaw``."""
    steps = np.diff(points, axis=0)
    yaws = np.arctan2(steps[:, 1], steps[:, 0])
    return np.append(yaws, last_yaw)


__all__ = ["Smoothed", "SmootherParams", "headings", "smooth_path"]
