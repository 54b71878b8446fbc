"""The waypoints in the mission picture: markers, numbers, labels.

- :func:`group_markers` puts waypoints that would hide one another under one marker
  with a count, and chooses numbered discs (few, spread out) or dots (crowded);
- :func:`draw_markers` draws them by outcome, the most alarming on top, waypoints
  beyond the view as triangles on its border, and a ring where a run was cut short;
- :func:`place_labels` labels all of them when they fit, else the first, the last,
  the failures and a spread-out sample, never two labels on top of each other
  (:mod:`navseq.sinks.picture.labels`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from navseq.mission.model import Mission
from navseq.sinks.picture.labels import LabelPlacer, spread_order
from navseq.sinks.picture.style import (
    ALARMING,
    COINCIDENT,
    DISC,
    DISC_MIN,
    DOT_LABELS,
    DOT_RANGE,
    DOTS_DRAWN,
    DRAW_ORDER,
    LABEL_FONT,
    LABEL_PAD,
    NUMBERED_MAX,
    OFF_VIEW_DRAWN,
    STATUS_COLOURS,
    STATUSES,
    Status,
    WaypointOutcomes,
)
from navseq.sinks.picture.thin import Groups, coincident_groups
from navseq.sinks.picture.view import Layout, pose_arrows
from navseq.text import printable

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def _numbers(members: np.ndarray, most: int = 5) -> str:
    shown = ", ".join(str(int(i) + 1) for i in members[:most])
    return shown + (", …" if len(members) > most else "")


@dataclass
class Markers:
    """The waypoint markers as drawn: one per group, in the view or on its border."""

    groups: Groups
    points: np.ndarray  # (G, 2) world position of each marker
    pixels: np.ndarray  # (G, 2) display pixels
    status: np.ndarray  # (G,) worst status code of the members
    inside: np.ndarray  # (G,) True: in the view; False: on the border
    numbered: bool
    size: float  # marker diameter, points
    spacing: float  # median distance between neighbouring markers, points


def _group_status(outcomes: WaypointOutcomes, groups: Groups) -> np.ndarray:
    """A group's status: its most alarming member's (the draw order's last)."""
    rank = np.array([DRAW_ORDER.index(s) for s in STATUSES])[outcomes.status]
    worst = np.zeros(len(groups), dtype=np.int64)
    np.maximum.at(worst, groups.of, rank)
    return np.array([STATUSES.index(DRAW_ORDER[r]) for r in range(len(DRAW_ORDER))])[worst]


def group_markers(
    positions: np.ndarray, outcomes: WaypointOutcomes, layout: Layout, dpi: float
) -> Markers:
    """Group the waypoints into markers and choose numbered discs or dots.

    Numbered discs while there are at most a few hundred and most are a disc apart;
    discs that would overlap by more than half are one marker with a count. Else dots,
    sized to the typical spacing, grouped only when they fall on the same pixels.
    """
    from scipy.spatial import cKDTree

    view = layout.view
    inset = 0.5 * DISC / 72.0 * dpi / layout.scale  # metres: a marker's radius
    inside_each = view.contains(positions)
    # A waypoint beyond the view is drawn on its border, just inside.
    border = np.column_stack(
        (
            np.clip(positions[:, 0], view.xmin + inset, view.xmax - inset),
            np.clip(positions[:, 1], view.ymin + inset, view.ymax - inset),
        )
    )
    clipped = np.where(inside_each[:, None], positions, border)
    pixel = 72.0 / dpi  # points per pixel
    metres_per_point = 1.0 / (layout.scale * pixel)
    fine = coincident_groups(clipped, 2.0 / layout.scale)
    spacing = np.inf
    if len(fine) > 1:
        reps = layout.to_pixels(clipped[fine.first])
        # The median over a sample is as good as over all, and bounded in time.
        sample = reps[:: max(1, len(reps) // 5000)]
        distances, _ = cKDTree(reps).query(sample, k=2)
        spacing = float(np.median(distances[:, 1])) * pixel  # points
    numbered = len(fine) <= NUMBERED_MAX and spacing >= DISC_MIN * 1.3
    if numbered:
        size = DISC if spacing >= DISC * 1.3 else DISC_MIN
        groups = coincident_groups(clipped, 0.5 * size * metres_per_point)
    else:
        size = float(np.clip(0.5 * spacing, *DOT_RANGE))
        # Only waypoints really at one spot (a route through one point twice) count as
        # coincident here; dots a few centimetres apart simply overlap.
        groups = coincident_groups(clipped, min(2.0 / layout.scale, COINCIDENT))
    points = clipped[groups.first]
    inside = np.zeros(len(groups), dtype=bool)
    np.logical_or.at(inside, groups.of, inside_each)
    return Markers(
        groups=groups,
        points=points,
        pixels=layout.to_pixels(points),
        status=_group_status(outcomes, groups),
        inside=inside,
        numbered=numbered,
        size=size,
        spacing=spacing,
    )


def draw_markers(
    ax: Axes,
    markers: Markers,
    outcomes: WaypointOutcomes,
    positions: np.ndarray,
    layout: Layout,
) -> None:
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Polygon

    inside = markers.inside
    drawn = _thinned_dots(markers, layout) if not markers.numbered else inside
    # Dots packed tighter than their size lose their edges, or the crowd turns black.
    dense = not markers.numbered and markers.spacing < 2.0 * markers.size
    edge = 0.8 if markers.numbered else (0.0 if dense else 0.4)
    # Sparse dots get a white rim that sets them apart from the paths under them.
    rim = "black" if markers.numbered else "white"
    for status in DRAW_ORDER:
        chosen = drawn & (markers.status == STATUSES.index(status))
        if not chosen.any():
            continue
        # Dots that need attention are drawn larger than the crowd of reached ones.
        size, line = markers.size, edge
        if not markers.numbered and status in ALARMING:
            size, line = max(2.0 * markers.size, 6.0), 0.8
        elif not markers.numbered and status is Status.SKIPPED and not dense:
            size = 1.3 * markers.size
        ax.scatter(
            markers.points[chosen, 0],
            markers.points[chosen, 1],
            s=size**2,
            c=STATUS_COLOURS[status],
            edgecolors="black" if status in ALARMING else rim,
            linewidths=line,
            zorder=6 + 0.01 * DRAW_ORDER.index(status),
        )
    # Groups get a thick black ring: several waypoints under one marker (thinned as the
    # dots are: one ring per dot-sized cell says as much as thirty thousand).
    several = inside & (markers.groups.sizes > 1)
    if several.any() and not markers.numbered:
        several = _one_per_cell(markers, layout, several, by_status=False)
        ax.scatter(
            markers.points[several, 0],
            markers.points[several, 1],
            s=(markers.size + 3) ** 2,
            facecolors="none",
            edgecolors="black",
            linewidths=1.2,
            zorder=6.1,
        )
    # "Interrupted here": the waypoint being driven to when the run was cut short.
    ring = np.zeros(len(markers.groups), dtype=bool)
    np.logical_or.at(ring, markers.groups.of, outcomes.interrupted)
    if ring.any():
        ax.scatter(
            markers.points[ring, 0],
            markers.points[ring, 1],
            s=(markers.size + 7) ** 2,
            facecolors="none",
            edgecolors=STATUS_COLOURS[Status.INTERRUPTED],
            linewidths=2.2,
            zorder=5.9,
        )
    # Off the view: a triangle on the border, pointing at the waypoint.
    outside = np.flatnonzero(~inside)
    if len(outside) > OFF_VIEW_DRAWN:
        # Thousands beyond the view: one triangle per disc-sized stretch of the border.
        cells = np.floor(markers.pixels[outside] / (DISC / 72.0 * layout.dpi)).astype(np.int64)
        _, first = np.unique(cells, axis=0, return_index=True)
        outside = outside[np.sort(first)]
    if len(outside):
        metres = DISC / 72.0 * layout.dpi / layout.scale  # a disc's diameter
        triangles = []
        colours = []
        for group in outside:
            member = markers.groups.first[group]
            tip = markers.points[group]
            dx, dy = positions[member] - tip
            angle = math.atan2(dy, dx)
            c, s = math.cos(angle), math.sin(angle)
            # Tip on the border (the marker sits a radius inside it), base inwards.
            shape = np.array([(0.5, 0.0), (-0.5, 0.5), (-0.5, -0.5)]) * metres
            triangles.append(Polygon(tip + shape @ np.array([[c, s], [-s, c]]), closed=True))
            colours.append(STATUS_COLOURS[STATUSES[int(markers.status[group])]])
        ax.add_collection(
            PatchCollection(
                triangles, facecolors=colours, edgecolors="black", linewidths=0.8, zorder=6.5
            )
        )


def _thinned_dots(markers: Markers, layout: Layout) -> np.ndarray:
    """Which dots to draw: one per status in each dot-sized cell, when there are very many.

    Dots that would cover one another to the pixel add nothing to the picture but
    drawing time; the most alarming status of a cell is drawn last, on top.
    """
    return _one_per_cell(markers, layout, markers.inside, by_status=True)


def _one_per_cell(
    markers: Markers, layout: Layout, candidates: np.ndarray, *, by_status: bool
) -> np.ndarray:
    """Of the ``candidates`` markers, the first in each dot-sized cell (of each status
    with ``by_status``); all of them when there are no more than :data:`DOTS_DRAWN`."""
    if np.count_nonzero(candidates) <= DOTS_DRAWN:
        return candidates
    cell = markers.size / 72.0 * layout.dpi
    cells = np.floor(markers.pixels / cell).astype(np.int64)
    cells -= cells.min(axis=0)
    span = int(cells.max()) + 1
    keys = cells[:, 0] * span + cells[:, 1]
    if by_status:
        keys = keys * len(STATUSES) + markers.status
    keys = np.where(candidates, keys, -1)
    _, first = np.unique(keys, return_index=True)
    drawn = np.zeros(len(candidates), dtype=bool)
    drawn[first] = True
    return drawn & candidates


def draw_numbered_details(
    ax: Axes,
    mission: Mission,
    markers: Markers,
    waypoints: np.ndarray,
    yaws: np.ndarray,
    layout: Layout,
) -> bool:
    """Numbers in the discs, yaw arrows and pass-through radii; True if a radius was drawn."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    groups = markers.groups
    shown = np.flatnonzero(markers.inside)
    colours = [STATUS_COLOURS[STATUSES[int(markers.status[g])]] for g in shown]
    length = 1.8 * markers.size / 72.0 * layout.dpi / layout.scale
    members = groups.first[shown]
    pose_arrows(ax, waypoints[members], yaws[members], colours, length, 5.0)
    circles, circle_colours = [], []
    last = len(mission.waypoints) - 1
    for group, colour in zip(shown, colours, strict=True):
        first = int(groups.first[group])
        size = int(groups.sizes[group])
        text = str(first + 1) if size == 1 else f"×{size}"
        digits = len(text)
        x, y = markers.points[group]
        ax.text(
            x,
            y,
            text,
            ha="center",
            va="center",
            fontsize=(7.5 if digits <= 2 else 6.0) * markers.size / DISC,
            fontweight="bold",
            color="white",
            zorder=7,
        )
        policy = mission.policy_for(first)
        if policy.pass_through_m and first != last and policy.dwell_s == 0:
            circles.append(Circle(tuple(waypoints[first]), policy.pass_through_m))
            circle_colours.append(colour)
    if circles:
        ax.add_collection(
            PatchCollection(
                circles,
                facecolors="none",
                edgecolors=circle_colours,
                linestyles=[(0, (2, 2))],
                linewidths=1.0,
                zorder=4,
            )
        )
    return bool(circles)


def _label_text(
    mission: Mission, markers: Markers, group: int, positions: np.ndarray
) -> str | None:
    """What a marker's label says, or None when a numbered disc says it all already."""
    groups = markers.groups
    first = int(groups.first[group])
    name = mission.waypoints[first].name
    name_text = printable(name)[:28] if name else ""
    if groups.sizes[group] > 1:
        numbers = _numbers(groups.members(group))
        text = f"{numbers}" if markers.numbered else f"×{groups.sizes[group]}: {numbers}"
    elif markers.numbered:
        text = name_text
    else:
        text = f"{first + 1} {name_text}".strip()
    if not markers.inside[group]:
        # A triangle has no number inside: the label says which waypoint, and where.
        x, y = positions[first]
        if groups.sizes[group] == 1:
            text = f"{first + 1} {name_text}".strip()
        text = f"{text} at ({x:.1f}, {y:.1f})"
    return text or None


def place_labels(
    ax: Axes,
    fig: Figure,
    mission: Mission,
    markers: Markers,
    outcomes: WaypointOutcomes,
    positions: np.ndarray,
    layout: Layout,
    obstacles: np.ndarray,
    yaws: np.ndarray,
) -> int:
    """Place and draw the labels (see the module doc); returns how many were drawn."""
    from matplotlib.font_manager import FontProperties

    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    font = FontProperties(size=LABEL_FONT)
    pad = 2 * LABEL_PAD * LABEL_FONT / 72.0 * layout.dpi

    def measure(text: str) -> tuple[float, float]:
        width, height, _ = renderer.get_text_width_height_descent(text, font, ismath=False)
        # The drawn box is a line's height (ascent and descent of the font), not the
        # text's: measured with a tall glyph and a deep one, plus a pixel of air.
        _, line, _ = renderer.get_text_width_height_descent("Ág", font, ismath=False)
        return width + pad + 2.0, max(height, line) + pad + 2.0

    count = len(markers.groups)
    placer = LabelPlacer(
        area=layout.axes_pixels, measure=measure, limit=count if markers.numbered else DOT_LABELS
    )
    radius_px = 0.5 * markers.size / 72.0 * layout.dpi + 1.5
    if markers.numbered:
        placer.block(square(markers.pixels, radius_px))
        # And the heads of the yaw arrows (they start under the disc, so only the head
        # sticks out far enough to be hidden by a label).
        heads = markers.pixels + 1.5 * radius_px * np.column_stack(
            (np.cos(yaws[markers.groups.first]), np.sin(yaws[markers.groups.first]))
        )
        placer.block(square(heads[markers.inside], 0.4 * radius_px))
    placer.block(obstacles)
    group_status = markers.status
    code = {status: STATUSES.index(status) for status in Status}
    ring = np.zeros(count, dtype=bool)
    np.logical_or.at(ring, markers.groups.of, outcomes.interrupted)
    everyone = np.arange(count)
    tiers = [
        everyone[:1],
        everyone[markers.groups.of[-1:]] if len(positions) else everyone[:0],
        everyone[group_status == code[Status.FAILED]],
        everyone[(group_status == code[Status.INTERRUPTED]) | ring],
        everyone[~markers.inside],
        everyone[group_status == code[Status.SKIPPED]],
        everyone[markers.groups.sizes > 1],
        everyone[[bool(mission.waypoints[int(f)].name) for f in markers.groups.first]]
        if markers.numbered or count <= 5000
        else everyone[:0],
        everyone,
    ]
    done = np.zeros(count, dtype=bool)
    for tier in tiers:
        todo = tier[~done[tier]]
        if not len(todo):
            continue
        room = placer.limit - len(placer.placed)
        if room <= 0:
            break
        taken = np.array([(p.x, p.y) for p in placer.placed]).reshape(-1, 2)
        order = (
            todo.tolist()
            if markers.numbered
            else spread_order(markers.pixels, todo.tolist(), taken, 4 * room)
        )
        for group in order:
            done[group] = True
            text = _label_text(mission, markers, group, positions)
            if text is None:
                continue
            x, y = markers.pixels[group]
            if placer.place(group, text, x, y, radius_px) and not markers.numbered:
                placer.block(square(markers.pixels[group : group + 1], radius_px))
    leaders = [
        (layout.to_world(*label.anchor), layout.to_world(*_nearest_on_box(label)))
        for label in placer.placed
        if label.far
    ]
    if leaders:
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(leaders, colors="#444444", linewidths=0.6, zorder=7.5))
    for label in placer.placed:
        ax.text(
            *layout.to_world(label.x, label.y),
            label.text,
            ha="center",
            va="center",
            fontsize=LABEL_FONT,
            color="#222222",
            zorder=8,
            bbox={
                "boxstyle": f"round,pad={LABEL_PAD}",
                "facecolor": "white",
                "edgecolor": "none",
                "alpha": 0.8,
            },
            gid="waypoint-label",
        )
    return len(placer.placed)


def _nearest_on_box(label: Any) -> tuple[float, float]:
    """The point of a label's box nearest its marker: where its leader line ends."""
    xmin, ymin, xmax, ymax = label.box
    x, y = label.anchor
    return min(max(x, xmin), xmax), min(max(y, ymin), ymax)


def square(pixels: np.ndarray, radius: float) -> np.ndarray:
    return np.column_stack(
        (pixels[:, 0] - radius, pixels[:, 1] - radius, pixels[:, 0] + radius, pixels[:, 1] + radius)
    )
