"""Routes between many places on a big map: exact near each place, coarse in between.

One exact search per place (:func:`navseq.sim.planner.reach_routes`) expands most of
the map when the places are spread over it: 100 places on Nav2's warehouse map
(1.7 M cells) took 24 s. Here each search expands a small disc around its place and a
graph of the map about a hundred times smaller than the grid:

- **The coarse graph** (made once per map and robot, kept beside the distances): the
  grid cut into square blocks; a node per connected piece of free space within a block
  (8-connected, as the planner steps), placed at the piece's cell nearest the block's
  centre; an edge between two pieces of neighbouring blocks that touch. A piece of
  free space joined to another only through a doorway one cell wide is joined in the
  graph too, and pieces that do not touch are not: two places are connected in the graph
  exactly when the planner finds a path between them.
- **Near each place**, an exact search up to a few blocks away
  (``_astar.local``): the cost, length and heading of the cheapest route to every other
  place and every node within reach. Two places within each other's reach take that
  route, exactly the planner's.
- **Further**, the cheapest of: the exact way from the first place to a node near it,
  the graph from there to a node near the second place, the exact way from that node to
  the second place; a route that comes out short this way is planned exactly. Lengths
  come out within a few per cent of the planner's but for near ties (the bounds:
  docs/performance.md, held by tests/test_route_coarse.py); the headings a route
  leaves and arrives with come from the exact searches, so the turns at both ends are
  counted as before.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from navseq.sim.costmap import Costmap

Place = tuple[float, float]
#: The coarse graph is made with about this many blocks at most (its searches cost what
#: its nodes are: 3.5 ms for 32 000 nodes, 25 000 blocks, on the 2000 x 2000 map; half
#: as many blocks halved them, and the lengths came out as close to the planner's:
#: median 0.45 % off instead of 1.0 % there, 0.30 % instead of 0.16 % on a warehouse).
TARGET_BLOCKS = 12_000
#: Exact search to this many blocks around each place (and at least one lookahead and a
#: block further): pairs nearer than that are measured exactly, and the graph's ends get
#: exact ways to a ring of nodes around each place.
NEAR_BLOCKS = 4.0
#: Cells looked at along each edge of the graph for its cost.
SAMPLES_PER_EDGE = 5
#: Pairs whose route (found the coarse way) is shorter than this (m) get an exact plan.
PLAN_WITHIN_M = 3.0
#: Coarse routes are taken when one exact search per place would expand more cells than
#: this in all (about three seconds on two cores).
EXACT_CELLS_AT_MOST = 20_000_000


@dataclass(frozen=True)
class CoarseGraph:
    """A map's free space as pieces of blocks (see the module doc), in compressed rows."""

    block: int
    node_cell: np.ndarray  # flat cell of each node's representative
    indptr: np.ndarray
    indices: np.ndarray
    edge_cost: np.ndarray  # the planner's cost between the nodes' cells, straight
    edge_length: np.ndarray  # cells between the nodes' cells, straight


def block_for(free_cells: int) -> int:
    """The block side (cells) that cuts ``free_cells`` into about :data:`TARGET_BLOCKS`."""
    return max(2, math.ceil(math.sqrt(free_cells / TARGET_BLOCKS)))


def build_graph(cost: np.ndarray, lut: np.ndarray, block: int) -> CoarseGraph:
    """The coarse graph of a planning costmap (uint8 costs, ``lut`` their traversal costs,
    ``inf`` impassable) with blocks of ``block`` x ``block`` cells."""
    from scipy import ndimage

    height, width = cost.shape
    traversal = lut[cost]
    free = np.isfinite(traversal)
    rows_b, cols_b = -(-height // block), -(-width // block)
    padded = np.zeros((rows_b * block, cols_b * block), bool)
    padded[:height, :width] = free
    # A blocked line between blocks keeps each piece of free space inside its block.
    spaced = np.zeros((rows_b, block + 1, cols_b, block + 1), bool)
    spaced[:, :block, :, :block] = padded.reshape(rows_b, block, cols_b, block)
    labels, count = ndimage.label(
        spaced.reshape(rows_b * (block + 1), cols_b * (block + 1)), np.ones((3, 3), bool)
    )
    label = labels.reshape(rows_b, block + 1, cols_b, block + 1)[:, :block, :, :block]
    label = label.reshape(rows_b * block, cols_b * block)[:height, :width]
    # Each node at one of its piece's cheapest cells (the middle of an aisle, where
    # routes run), the one nearest the block's centre: open floor gives a regular
    # lattice, whose 8-connected steps measure as the planner's do. One integer key per
    # cell, smallest wins: cheapness, then distance from the centre, then the cell.
    flat = np.flatnonzero(label)
    node = label.ravel()[flat].astype(np.int64) - 1
    rows, cols = np.divmod(flat, width)
    twice_off = (2 * (rows % block) - (block - 1)) ** 2 + (2 * (cols % block) - (block - 1)) ** 2
    cheap = np.floor((traversal.ravel()[flat] - 1.0) * 4.0).astype(np.int64)
    key = (cheap * (2 * block * block + 1) + twice_off) * cost.size + flat
    best = np.full(count, np.iinfo(np.int64).max)
    np.minimum.at(best, node, key)
    node_cell = best % cost.size
    # Pieces of neighbouring blocks that touch (8-connected) are joined: only steps
    # across a block's edge can join two.
    pairs = []
    for d_row, d_col in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = label[: height - d_row, max(0, -d_col) : width - max(0, d_col)]
        b = label[d_row:, max(0, d_col) : width - max(0, -d_col)]
        a_rows = np.arange(a.shape[0])
        a_cols = np.arange(a.shape[1]) + max(0, -d_col)
        b_cols = a_cols + d_col
        crossing_rows = (a_rows // block != (a_rows + d_row) // block) if d_row else None
        crossing_cols = (a_cols // block != b_cols // block) if d_col else None
        for axis, crossing in enumerate((crossing_rows, crossing_cols)):
            if crossing is None:
                continue
            left, right = a.compress(crossing, axis), b.compress(crossing, axis)
            touch = (left > 0) & (right > 0)
            tails = left[touch].astype(np.int64) - 1
            heads = right[touch].astype(np.int64) - 1
            pairs += [tails * count + heads, heads * count + tails]  # both ways
    tail, head = np.divmod(np.unique(np.concatenate(pairs)), count)
    tail_rc = np.stack(np.divmod(node_cell[tail], width), axis=1)
    head_rc = np.stack(np.divmod(node_cell[head], width), axis=1)
    length = np.hypot(*(head_rc - tail_rc).T.astype(float))
    # An edge costs its length times the traversal cost of cells along it (sampled;
    # the cells where it cuts a corner through a wall counted at the dearest cost).
    samples = np.linspace(0.0, 1.0, SAMPLES_PER_EDGE)[:, None]
    sample_rows = np.rint(tail_rc[:, 0] + samples * (head_rc[:, 0] - tail_rc[:, 0])).astype(
        np.int64
    )
    sample_cols = np.rint(tail_rc[:, 1] + samples * (head_rc[:, 1] - tail_rc[:, 1])).astype(
        np.int64
    )
    along = traversal[sample_rows, sample_cols]
    dearest = float(lut[np.isfinite(lut)].max())
    edge_cost = length * np.where(np.isfinite(along), along, dearest).mean(axis=0)
    indptr = np.zeros(count + 1, np.int64)
    np.cumsum(np.bincount(tail, minlength=count), out=indptr[1:])
    return CoarseGraph(
        block,
        node_cell,
        indptr,
        head.astype(np.int64),
        np.ascontiguousarray(edge_cost, dtype=np.float64),
        np.ascontiguousarray(length, dtype=np.float64),
    )


_GRAPHS: OrderedDict[tuple[Any, ...], CoarseGraph] = OrderedDict()
_LOCK = threading.Lock()


def graph_for(costmap: Costmap, block: int | None = None) -> CoarseGraph:
    """The coarse graph of ``costmap`` (kept per map and robot, as the distances are)."""
    from navseq.route import distances
    from navseq.sim.planner import _TRAVERSAL_LUT

    cost = np.ascontiguousarray(costmap.planning_cost, dtype=np.uint8)
    if block is None:
        block = block_for(int(np.count_nonzero(np.isfinite(_TRAVERSAL_LUT[cost]))))
    key = (*distances.costmap_key(costmap), block)
    with _LOCK:
        graph = _GRAPHS.get(key)
        if graph is not None:
            _GRAPHS.move_to_end(key)
            return graph
    graph = build_graph(cost, _TRAVERSAL_LUT, block)
    with _LOCK:
        _GRAPHS[key] = graph
        while len(_GRAPHS) > distances.COSTMAPS_KEPT:
            _GRAPHS.popitem(last=False)
    return graph


def worth_it(costmap: Costmap, searches: int) -> bool:
    """Whether the coarse way pays: exact searches would expand more than
    :data:`EXACT_CELLS_AT_MOST` cells in all."""
    from navseq.sim.costmap import INSCRIBED

    free = int(np.count_nonzero(costmap.planning_cost < INSCRIBED))
    return free * searches > EXACT_CELLS_AT_MOST and block_for(free) >= 2


@dataclass(frozen=True)
class _Near:
    """One place's exact search: the other places and the graph's nodes it reached."""

    cell: int
    place_ids: np.ndarray  # the places reached (int64), their lengths (cells) and
    place_length: np.ndarray  # departure anchor cells
    place_anchor: np.ndarray
    nodes: np.ndarray  # nodes reached (int64)
    node_rows: np.ndarray  # (len(nodes), 3) length, cost, departure anchor cell
    seed_cost: np.ndarray  # node_rows' costs and lengths, contiguous (for the C search)
    seed_length: np.ndarray


@dataclass(frozen=True)
class _Index:
    """Every prepared place's search in flat arrays, so that :meth:`CoarseRoutes.reach`
    looks up a thousand places at once rather than one by one (the loop over them
    in Python took as long as the graph search on 2000 places)."""

    prepared: np.ndarray  # per place: searched around
    node_start: np.ndarray  # per place: where its nodes begin in `nodes`
    node_count: np.ndarray
    nodes: np.ndarray
    node_rows: np.ndarray
    pair_keys: np.ndarray  # sorted `from * places + to` of the pairs searched exactly
    pair_length: np.ndarray
    pair_anchor: np.ndarray


class CoarseRoutes:
    """Routes between ``places`` on ``costmap``, as :func:`navseq.sim.planner.reach_routes`
    gives them, by the coarse way of the module doc. :meth:`prepare` the places a
    search starts or ends at first (each on any thread), then :meth:`reach`."""

    def __init__(
        self, costmap: Costmap, places: Sequence[Place], anchor_m: float, block: int | None = None
    ) -> None:
        from navseq.sim.costmap import INSCRIBED
        from navseq.sim.planner import _TRAVERSAL_LUT

        self.costmap = costmap
        self.graph = graph_for(costmap, block)
        self._cost = np.ascontiguousarray(costmap.planning_cost, dtype=np.uint8)
        self._lut = np.ascontiguousarray(_TRAVERSAL_LUT, dtype=np.float64)
        grid = costmap.grid
        self._width = self._cost.shape[1]
        self._anchor_cells = anchor_m / grid.resolution
        self._bound = max(NEAR_BLOCKS * self.graph.block, 4 * self._anchor_cells + self.graph.block)
        # Pairs with a route this short that are not within each other's exact search
        # (around walls, where each step costs more) get a plan of their own: a few
        # centimetres off is a large part of a short way.
        self._plan_within = max(PLAN_WITHIN_M / grid.resolution, 1.5 * self._bound)
        cells = np.full(len(places), -1, np.int64)
        for index, place in enumerate(places):
            row, col = grid.world_to_cell(*place)
            if grid.in_bounds(row, col) and self._cost[row, col] < INSCRIBED:
                cells[index] = row * self._width + col
        self.cells = cells
        self._queries = np.ascontiguousarray(
            np.concatenate((np.where(cells >= 0, cells, 0), self.graph.node_cell))
        )
        self._near: dict[int, _Near] = {}
        self._index: _Index | None = None
        self._index_lock = threading.Lock()
        self._rows, self._cols = np.divmod(cells, self._width)

    def prepare(self, index: int) -> None:
        """The exact search around place ``index`` (nothing for a place off the free space)."""
        from navseq.sim import _astar  # type: ignore[attr-defined]

        start = int(self.cells[index])
        if start < 0:
            return
        count = len(self.cells)
        bound = self._bound
        while True:
            raw = _astar.local(
                self._cost,
                self._width,
                self._lut,
                start,
                bound,
                self._queries,
                self._anchor_cells,
            )
            found = np.frombuffer(raw, dtype=np.float64).reshape(-1, 3)
            reached = np.flatnonzero(np.isfinite(found[count:, 0]))
            # A place in a winding pocket may reach no node within the bound: further.
            if reached.size or math.isinf(bound):
                break
            bound = bound * 4 if bound < 1e6 else math.inf
        # Only the places reached are kept (2000 places: a full row each is 100 MB).
        near_ids = np.flatnonzero(np.isfinite(found[:count, 0]) & (self.cells >= 0))
        nodes = found[count:][reached]
        # Routes further away leave through the nodes a lookahead away or more (where
        # their heading is measured), when there are any.
        beyond = nodes[:, 0] >= self._anchor_cells
        if beyond.any():
            reached, nodes = reached[beyond], nodes[beyond]
        near = _Near(
            start,
            near_ids.astype(np.int64),
            found[near_ids, 0].copy(),
            found[near_ids, 2].astype(np.int64),
            reached.astype(np.int64),
            nodes.copy(),
            np.ascontiguousarray(nodes[:, 1]),
            np.ascontiguousarray(nodes[:, 0]),
        )
        with self._index_lock:
            self._near[index] = near
            self._index = None

    def _flat(self) -> _Index:
        """The prepared searches as :class:`_Index` (made at the first :meth:`reach`)."""
        with self._index_lock:
            if self._index is not None:
                return self._index
            count = len(self.cells)
            prepared = np.zeros(count, bool)
            node_count = np.zeros(count, np.int64)
            for index, near in self._near.items():
                prepared[index] = True
                node_count[index] = len(near.nodes)
            node_start = np.concatenate(([0], np.cumsum(node_count)[:-1])).astype(np.int64)
            ids = [int(i) for i in np.flatnonzero(prepared)]
            searched = [self._near[i] for i in ids]
            keys = [i * count + near.place_ids for i, near in zip(ids, searched, strict=True)]

            def joined(parts: list[np.ndarray], dtype: Any, shape: tuple[int, ...]) -> np.ndarray:
                return np.concatenate(parts).astype(dtype) if parts else np.zeros(shape, dtype)

            pair_keys = joined(keys, np.int64, (0,))
            order = np.argsort(pair_keys, kind="stable")
            self._index = _Index(
                prepared,
                node_start,
                node_count,
                joined([near.nodes for near in searched], np.int64, (0,)),
                joined([near.node_rows for near in searched], np.float64, (0, 3)),
                pair_keys[order],
                joined([near.place_length for near in searched], np.float64, (0,))[order],
                joined([near.place_anchor for near in searched], np.int64, (0,))[order],
            )
            return self._index

    def _pairs(self, flat: _Index, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which of ``keys`` (``from * places + to``) were searched exactly, and where."""
        at = np.minimum(np.searchsorted(flat.pair_keys, keys), max(len(flat.pair_keys) - 1, 0))
        if not len(flat.pair_keys):
            return np.zeros(len(keys), bool), at
        return flat.pair_keys[at] == keys, at

    def reach(self, index: int, others: np.ndarray) -> np.ndarray:
        """Per place of ``others`` (indices): metres, the heading leaving place ``index``
        and the heading arriving there (``inf``, NaN, NaN: no route), as
        :func:`navseq.sim.planner.reach_routes` gives them."""
        from navseq.sim import _astar  # type: ignore[attr-defined]

        others = np.asarray(others, dtype=np.int64)
        rows = np.full((len(others), 3), np.nan)
        rows[:, 0] = np.inf
        near = self._near.get(index)
        if near is None or len(others) == 0:
            return rows
        graph = self.graph
        flat = self._flat()
        count = len(self.cells)
        length = np.full(len(others), np.inf)
        depart = np.full(len(others), -1, np.int64)
        arrive = np.full(len(others), -1, np.int64)
        there = flat.prepared[others]
        out, out_at = self._pairs(flat, index * count + others)
        back, back_at = self._pairs(flat, others * count + index)
        both = there & out & back
        length[both] = flat.pair_length[out_at[both]]
        depart[both] = flat.pair_anchor[out_at[both]]
        arrive[both] = flat.pair_anchor[back_at[both]]
        rest = there & ~both
        straight = np.hypot(self._rows[others] - near.cell // self._width,
                            self._cols[others] - near.cell % self._width)  # fmt: skip
        far = np.flatnonzero(rest & (flat.node_count[others] > 0))
        planned = rest & (straight <= self._plan_within) & (flat.node_count[others] == 0)
        if far.size:
            # The far places' nodes, one segment per place, gathered from the flat arrays.
            sizes = flat.node_count[others[far]]
            starts = np.concatenate(([0], np.cumsum(sizes)[:-1]))
            gather = np.repeat(flat.node_start[others[far]] - starts, sizes) + np.arange(
                int(sizes.sum())
            )
            end_nodes = np.ascontiguousarray(flat.nodes[gather])
            end_rows = flat.node_rows[gather]
            raw = _astar.graph(
                graph.indptr,
                graph.indices,
                graph.edge_cost,
                graph.edge_length,
                near.nodes,
                near.seed_cost,
                near.seed_length,
                end_nodes,
            )
            over = np.frombuffer(raw, dtype=np.float64).reshape(-1, 3)
            # Per far place, its cheapest node of all: the segments of the concatenation.
            total = over[end_nodes, 0] + end_rows[:, 1]
            cheapest = np.minimum.reduceat(total, starts)
            at_min = np.flatnonzero(total == np.repeat(cheapest, sizes))
            best = at_min[np.searchsorted(at_min, starts)]
            reached = np.isfinite(cheapest)
            best, ks = best[reached], far[reached]
            nodes = end_nodes[best]
            length[ks] = over[nodes, 1] + end_rows[best, 0]
            depart[ks] = near.node_rows[over[nodes, 2].astype(np.int64), 2].astype(np.int64)
            arrive[ks] = end_rows[best, 2].astype(np.int64)
            # Only the routes that come out short are planned: a few cells off is much of
            # a short way, little of a long one. (Planning every pair near in a straight
            # line planned those around a long shelf too: most of the time on a big map.)
            planned[ks[length[ks] <= self._plan_within]] = True
        for k in np.flatnonzero(planned):
            length[k], depart[k], arrive[k] = self._plan(near.cell, int(self.cells[others[k]]))
        rows[:, 0] = length * self.costmap.grid.resolution
        found = np.flatnonzero(np.isfinite(length))
        ends_cells = self.cells[others[found]]
        rows[found, 1] = self._headings(np.full(len(found), near.cell), depart[found])
        rows[found, 2] = self._headings(arrive[found], ends_cells)
        return rows

    def _plan(self, start: int, goal: int) -> tuple[float, int, int]:
        """One A* plan (the planner's): its length in cells and its two anchor cells."""
        from navseq.sim.planner import search_cells

        found = search_cells(self._cost, divmod(start, self._width), divmod(goal, self._width))
        if found is None:
            return math.inf, -1, -1
        cells = found[0]
        along = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(cells, axis=0).T))))
        leave = int(np.searchsorted(along, self._anchor_cells, side="right")) - 1
        come = max(int(np.searchsorted(along, along[-1] - self._anchor_cells, side="right")) - 1, 0)
        flat = cells[:, 0] * self._width + cells[:, 1]
        return float(along[-1]), int(flat[leave]), int(flat[come])

    def _headings(self, tails: np.ndarray, heads: np.ndarray) -> np.ndarray:
        """Direction (rad) from each tail cell to its head cell (NaN: the same cell)."""
        tail_rc = np.divmod(np.asarray(tails, np.int64), self._width)
        head_rc = np.divmod(np.asarray(heads, np.int64), self._width)
        grid = self.costmap.grid
        tail_xy = grid.cells_to_world(*tail_rc)
        head_xy = grid.cells_to_world(*head_rc)
        delta = head_xy - tail_xy
        moved = np.hypot(delta[:, 0], delta[:, 1]) > 0
        return np.where(moved, np.arctan2(delta[:, 1], delta[:, 0]), np.nan)


__all__ = ["CoarseGraph", "CoarseRoutes", "build_graph", "graph_for", "worth_it"]
