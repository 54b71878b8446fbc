"""A route graph in Nav2's GeoJSON format, and the shortest route on it, without ROS.

Nav2's route server (``nav2_route``, Jazzy) plans on a graph of nodes and directed edges
read by its ``GeoJsonGraphFileLoader``; ``navseq sim --ros2 --route-graph FILE`` reads
the same files (navigation2's ``nav2_route/graphs/*.geojson``) with the same rules:

- a ``FeatureCollection`` whose ``Point`` features are the nodes (``properties.id``, the
  coordinates x, y in metres; an optional ``properties.frame``, which must be ``map``
  here: the simulator knows no other fixed frame) and whose ``LineString`` /
  ``MultiLineString`` features are the edges (``properties.id``, ``startid``,
  ``endid``). An edge goes one way, from ``startid`` to ``endid``: a two-way road is two
  edges. Its optional ``cost`` and ``overridable`` (default true) are Nav2's: an edge
  that is not overridable costs its ``cost``, which must be positive;
- a graph without nodes or edges, or an edge naming a node the file lacks, is refused
  (Nav2's loader fails the route server's configure then). Ids go out in ``uint16``
  message fields, so they are 0..65535 here, and each is given once.

:func:`shortest_route` is Nav2's ``RoutePlanner``: Dijkstra over the directed edges,
each overridable edge scored by nav2_bringup's first edge scorer, ``DistanceScorer``
(the edge's length divided by its ``metadata.speed_limit``, 1 when absent). The second
scorer of nav2_bringup, ``CostmapScorer``, is not modelled (docs/ros2.md says so).
Every problem of a file names it and the feature (index in ``features``) or the line.
"""

from __future__ import annotations

import heapq
import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.reading import read_mission_text
from navseq.text import printable

ROUTE_FRAME = "map"
MAX_ID = 65535  # nav2_msgs' RouteNode.nodeid / RouteEdge.edgeid are uint16
MAX_GRAPH_BYTES = 64 * 1024 * 1024
SPEED_TAG = "speed_limit"  # DistanceScorer's speed_tag default


@dataclass(frozen=True)
class RouteNode:
    """A node of the graph: its id and where it is in the map frame."""

    id: int
    x: float
    y: float

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(self.x - x, self.y - y)


@dataclass(frozen=True)
class RouteEdge:
    """A one-way edge from ``start`` to ``end`` (node ids)."""

    id: int
    start: int
    end: int
    cost: float = 0.0  # the file's cost; used when not overridable
    overridable: bool = True
    speed_limit: float = 1.0  # metadata.speed_limit: DistanceScorer divides by it


@dataclass
class RouteGraph:
    """Nodes by id, edges in file order, and each node's outgoing edges."""

    nodes: dict[int, RouteNode]
    edges: list[RouteEdge]
    source: str = ""
    outgoing: dict[int, list[RouteEdge]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.outgoing = {node_id: [] for node_id in self.nodes}
        for edge in self.edges:
            self.outgoing[edge.start].append(edge)

    def length(self, edge: RouteEdge) -> float:
        start, end = self.nodes[edge.start], self.nodes[edge.end]
        return start.distance_to(end.x, end.y)

    def nearest_node(self, x: float, y: float) -> RouteNode:
        """The node closest to (x, y), the lowest id on a tie (Nav2: its kd-tree's
        nearest; the graph is never empty)."""
        return min(self.nodes.values(), key=lambda node: (node.distance_to(x, y), node.id))


class EdgeCostError(Exception):
    """An edge that cannot be scored (Nav2's ``NoValidGraph`` while routing)."""


def edge_cost(graph: RouteGraph, edge: RouteEdge) -> float:
    """What the route planner pays for ``edge`` (see the module docstring)."""
    if not edge.overridable:
        if edge.cost <= 0.0:
            raise EdgeCostError(
                f"Edge {edge.id} doesn't contain and cannot compute a valid edge cost!"
            )
        return edge.cost
    return graph.length(edge) / edge.speed_limit


def shortest_route(
    graph: RouteGraph, start: int, goal: int, blocked: Iterable[int] = ()
) -> tuple[list[RouteEdge], float] | None:
    """The cheapest edges from node ``start`` to node ``goal`` and their cost, None when
    no route exists. ``blocked``: edge or node ids not to enter (a reroute's). Raises
    EdgeCostError for an edge that cannot be scored."""
    closed = set(blocked)
    best: dict[int, float] = {start: 0.0}
    parent: dict[int, RouteEdge] = {}
    queue: list[tuple[float, int]] = [(0.0, start)]
    while queue:
        cost, node = heapq.heappop(queue)
        if cost != best.get(node):
            continue  # a stale entry: the node was reached more cheaply since
        if node == goal:
            break
        for edge in graph.outgoing[node]:
            if edge.id in closed or edge.end in closed:
                continue
            reached = cost + edge_cost(graph, edge)
            if reached < best.get(edge.end, math.inf):
                best[edge.end] = reached
                parent[edge.end] = edge
                heapq.heappush(queue, (reached, edge.end))
    if goal not in parent:
        return None
    edges: list[RouteEdge] = []
    node = goal
    while node != start:
        edge = parent[node]
        edges.append(edge)
        node = edge.start
    edges.reverse()
    return edges, best[goal]


# -- reading ---------------------------------------------------------------------------


def read_route_graph(path: Path) -> RouteGraph:
    """The graph of a Nav2 GeoJSON route graph file; a NavseqError naming the file and
    the feature for anything wrong (every problem at once)."""
    source = printable(str(path))
    text = read_mission_text(path, max_bytes=MAX_GRAPH_BYTES, what="route graph file")
    try:
        document = json.loads(text)
    except json.JSONDecodeError as error:
        raise NavseqError(
            f"not valid JSON: {error.msg}", source=f"{source}:{error.lineno}"
        ) from None
    features = document.get("features") if isinstance(document, dict) else None
    if not isinstance(features, list):
        raise NavseqError(
            "is not a GeoJSON FeatureCollection with a features list (Nav2's route graph "
            "format: Point features for nodes, LineString features for edges)",
            source=source,
        )
    problems: list[str] = []
    points: list[tuple[int, Mapping[str, Any]]] = []
    lines: list[tuple[int, Mapping[str, Any]]] = []
    for index, feature in enumerate(features):
        kind = _geometry_type(feature)
        if kind == "Point":
            points.append((index, feature))
        elif kind in ("LineString", "MultiLineString"):
            lines.append((index, feature))
    nodes: dict[int, RouteNode] = {}
    for index, feature in points:
        node = _node(index, feature, problems)
        if node is None:
            continue
        if node.id in nodes:
            problems.append(f"feature {index}: node id {node.id} is given twice")
            continue
        nodes[node.id] = node
    edges: list[RouteEdge] = []
    edge_ids: set[int] = set()
    for index, feature in lines:
        edge = _edge(index, feature, nodes, problems)
        if edge is None:
            continue
        if edge.id in edge_ids:
            problems.append(f"feature {index}: edge id {edge.id} is given twice")
            continue
        edge_ids.add(edge.id)
        edges.append(edge)
    if not points or not lines:
        problems.append(
            "the graph is malformed: it does not contain nodes (Point features) and edges "
            "(LineString or MultiLineString features)"
        )
    if problems:
        raise NavseqError(
            f"{len(problems)} problem{'s' if len(problems) > 1 else ''} in the route graph:\n"
            + "\n".join(f"  - {problem}" for problem in problems),
            source=source,
        )
    return RouteGraph(nodes, edges, source=source)


def _geometry_type(feature: Any) -> str:
    geometry = feature.get("geometry") if isinstance(feature, dict) else None
    kind = geometry.get("type") if isinstance(geometry, dict) else None
    return kind if isinstance(kind, str) else ""


def _properties(index: int, feature: Mapping[str, Any], problems: list[str]) -> dict[str, Any]:
    properties = feature.get("properties")
    if not isinstance(properties, dict):
        problems.append(f"feature {index}: has no properties (an id is needed)")
        return {}
    return properties


def _id(index: int, properties: Mapping[str, Any], key: str, problems: list[str]) -> int | None:
    value = properties.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_ID:
        shown = "missing" if value is None else printable(repr(value))
        problems.append(f"feature {index}: {key} must be a whole number 0..{MAX_ID}, {shown}")
        return None
    return value


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def _node(index: int, feature: Mapping[str, Any], problems: list[str]) -> RouteNode | None:
    properties = _properties(index, feature, problems)
    node_id = _id(index, properties, "id", problems)
    frame = properties.get("frame", ROUTE_FRAME)
    if frame != ROUTE_FRAME:
        problems.append(
            f"feature {index}: frame {printable(repr(frame))}: the simulator's route graph "
            f"is in the {ROUTE_FRAME!r} frame"
        )
        return None
    coordinates = feature["geometry"].get("coordinates")
    xy = (
        [_number(value) for value in coordinates[:2]]
        if isinstance(coordinates, list) and len(coordinates) >= 2
        else []
    )
    if len(xy) != 2 or xy[0] is None or xy[1] is None:
        problems.append(f"feature {index}: a Point needs coordinates [x, y] in metres")
        return None
    if node_id is None:
        return None
    return RouteNode(node_id, xy[0], xy[1])


def _edge(
    index: int, feature: Mapping[str, Any], nodes: Mapping[int, RouteNode], problems: list[str]
) -> RouteEdge | None:
    properties = _properties(index, feature, problems)
    ids = [_id(index, properties, key, problems) for key in ("id", "startid", "endid")]
    edge_id, start, end = ids
    if edge_id is None or start is None or end is None:
        return None
    for key, node_id in (("startid", start), ("endid", end)):
        if node_id not in nodes:
            problems.append(f"feature {index}: edge {edge_id}'s {key} {node_id} is not a node")
            return None
    cost = properties.get("cost", 0.0)
    overridable = properties.get("overridable", True)
    metadata = properties.get("metadata", {})
    speed = metadata.get(SPEED_TAG, 1.0) if isinstance(metadata, dict) else 1.0
    if _number(cost) is None or not isinstance(overridable, bool):
        problems.append(f"feature {index}: cost must be a number and overridable true or false")
        return None
    speed_limit = _number(speed)
    if speed_limit is None or speed_limit <= 0.0:
        problems.append(f"feature {index}: metadata.{SPEED_TAG} must be a number > 0")
        return None
    return RouteEdge(edge_id, start, end, float(cost), overridable, speed_limit)


__all__ = [
    "ROUTE_FRAME",
    "EdgeCostError",
    "RouteEdge",
    "RouteGraph",
    "RouteNode",
    "edge_cost",
    "read_route_graph",
    "shortest_route",
]
