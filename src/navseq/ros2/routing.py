"""What Nav2's route server (``nav2_route``, Jazzy) does with a goal, without ROS.

The ROS 2 simulator node serves ``compute_route`` and ``compute_and_track_route``
(:mod:`navseq.ros2.route_server`); the rules live here, after navigation2's
``route_server.cpp``, ``goal_intent_extractor.cpp``, ``route_planner.cpp``,
``path_converter.cpp`` and ``route_tracker.cpp`` (jazzy branch), with nav2_bringup's
parameters:

- **start and goal** (:func:`plan_route`): with ``use_poses`` false, the goal's
  ``start_id`` and ``goal_id`` (an id not in the graph: ``UNKNOWN``, as Nav2's
  ``std::out_of_range`` ends). With ``use_poses``, the ``start`` pose (``use_start``) or
  the robot's, and the ``goal`` pose, each to its nearest node (Nav2 then searches the
  costmap when the nearest node is not in line of sight: not modelled);
- **the route**: :func:`navseq.sim.route_graph.shortest_route`; none:
  ``NO_VALID_ROUTE``. Start and goal on one node: a route of that node alone;
- **pruning** (with poses, or when rerouting): the first node is dropped when the start
  is already past it along the first edge (more than ``min_prune_dist_from_start``
  0.10 m from it, within ``max_prune_dist_from_edge`` 8 m of the edge), the last when
  the goal lies before it on the last edge (``min_prune_dist_from_goal`` 0.15 m;
  ``prune_goal`` true); the route cost loses that edge's;
- **the path** (:func:`densify`): the edges' points every ``path_density`` (0.05 m),
  each pose facing the next, the last facing along the last edge. nav2_bringup smooths
  corners (``smooth_corners``): not modelled, the path keeps its corners;
- **tracking** (:class:`RouteTracker`): Nav2's route tracker follows the robot along the
  route and *does not drive it* — a client sends the feedback's path to ``follow_path``
  (navigation2's ``example_route.py``) or its nodes to the waypoint follower. A node is
  achieved when the robot, having come within ``radius_to_achieve_node`` (2.0 m;
  ``boundary_radius_to_achieve_node`` 1.0 m for the first and last), passes the line
  bisecting the edges in and out of it, or leaves the radius again (the first and last
  node: when within the radius). Feedback is sent at the start (``rerouted`` true) and
  at each node; the last node achieved completes the goal. A reroute request
  (``route_server/ReroutingService/reroute``) plans again from the last node achieved.
  Nav2's route operations (``AdjustSpeedLimit``, ``CollisionMonitor``) are not modelled:
  ``operations_triggered`` stays empty.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

from navseq.geometry import Pose2D
from navseq.sim.route_graph import (
    EdgeCostError,
    RouteEdge,
    RouteGraph,
    RouteNode,
    edge_cost,
    shortest_route,
)

PATH_DENSITY = 0.05  # m: path_density
RADIUS_TO_ACHIEVE_NODE = 2.0  # m: nav2_bringup's radius_to_achieve_node
BOUNDARY_RADIUS_TO_ACHIEVE_NODE = 1.0  # m: nav2_bringup's boundary_radius_to_achieve_node
MIN_PRUNE_DIST_FROM_START = 0.10  # m
MIN_PRUNE_DIST_FROM_GOAL = 0.15  # m
MAX_PRUNE_DIST_FROM_EDGE = 8.0  # m
EPSILON = 1e-6


class RouteErrorCode(enum.IntEnum):
    """``ComputeRoute`` / ``ComputeAndTrackRoute`` result codes (nav2_msgs, Jazzy)."""

    NONE = 0
    UNKNOWN = 400
    TF_ERROR = 401
    NO_VALID_GRAPH = 402
    INDETERMINANT_NODES_ON_GRAPH = 403
    TIMEOUT = 404
    NO_VALID_ROUTE = 405
    OPERATION_FAILED = 406
    INVALID_EDGE_SCORER_USE = 407


class RouteFailure(Exception):
    """A goal the route server ends ABORTED with ``code``."""

    def __init__(self, code: RouteErrorCode, text: str) -> None:
        super().__init__(text)
        self.code = code


@dataclass(frozen=True)
class RouteGoal:
    """The fields of a ``ComputeRoute`` / ``ComputeAndTrackRoute`` goal, in the map frame."""

    start_id: int
    goal_id: int
    start: Pose2D | None  # the goal's start pose (None: not in the map frame / unused)
    goal: Pose2D | None
    use_start: bool
    use_poses: bool


@dataclass
class Route:
    """A node-edge sequence: ``start`` then each edge's end node."""

    start: RouteNode
    edges: list[RouteEdge]
    cost: float

    def node_ids(self) -> list[int]:
        return [self.start.id, *(edge.end for edge in self.edges)]


@dataclass
class Rerouting:
    """What a reroute keeps: the node to plan from, the robot pose then, and the edges
    and nodes to avoid (Nav2's ``ReroutingState``)."""

    start_id: int | None = None
    start_pose: Pose2D | None = None
    blocked: list[int] = field(default_factory=list)
    first_time: bool = True


def plan_route(graph: RouteGraph, goal: RouteGoal, robot: Pose2D, rerouting: Rerouting) -> Route:
    """The route for ``goal`` from the robot at ``robot`` (see the module docstring);
    RouteFailure with Nav2's code when there is none."""
    if goal.use_poses:
        if goal.goal is None or (goal.use_start and goal.start is None):
            raise RouteFailure(RouteErrorCode.TF_ERROR, "Failed to transform pose to: map")
        start_pose = goal.start if goal.use_start and goal.start is not None else robot
        goal_pose = goal.goal
        start = graph.nearest_node(start_pose.x, start_pose.y)
        end = graph.nearest_node(goal_pose.x, goal_pose.y)
    else:
        if goal.start_id not in graph.nodes or goal.goal_id not in graph.nodes:
            missing = goal.start_id if goal.start_id not in graph.nodes else goal.goal_id
            raise RouteFailure(RouteErrorCode.UNKNOWN, f"node id {missing} is not in the graph")
        start, end = graph.nodes[goal.start_id], graph.nodes[goal.goal_id]
        start_pose = Pose2D(start.x, start.y, 0.0)
        goal_pose = Pose2D(end.x, end.y, 0.0)
    if rerouting.start_id is not None and rerouting.start_pose is not None:
        start = graph.nodes[rerouting.start_id]
        start_pose = rerouting.start_pose
    if start.id == end.id:
        route = Route(start, [], 0.0)
    else:
        try:
            found = shortest_route(graph, start.id, end.id, rerouting.blocked)
        except EdgeCostError as error:
            raise RouteFailure(RouteErrorCode.NO_VALID_GRAPH, str(error)) from None
        if found is None:
            raise RouteFailure(
                RouteErrorCode.NO_VALID_ROUTE, "Could not find a route to the requested goal!"
            )
        route = Route(start, *found)
    first_time = rerouting.first_time
    rerouting.first_time = False
    if not route.edges or (not goal.use_poses and first_time):
        return route
    return _prune(graph, route, start_pose, goal_pose, prune_goal=goal.use_poses)


def _prune(
    graph: RouteGraph, route: Route, start: Pose2D, goal: Pose2D, *, prune_goal: bool
) -> Route:
    """Drop a first node the start is past, a last node the goal is short of."""
    edges = list(route.edges)
    cost = route.cost
    first = route.start
    following = graph.nodes[edges[0].end]
    if _passed(first, following, start, MIN_PRUNE_DIST_FROM_START, forward=True):
        cost -= _edge_score(graph, edges[0])
        first = following
        edges.pop(0)
    if prune_goal and edges:
        before, last = graph.nodes[edges[-1].start], graph.nodes[edges[-1].end]
        if _passed(last, before, goal, MIN_PRUNE_DIST_FROM_GOAL, forward=False):
            cost -= _edge_score(graph, edges[-1])
            edges.pop()
    return Route(first, edges, cost)


def _edge_score(graph: RouteGraph, edge: RouteEdge) -> float:
    return edge_cost(graph, edge)


def _passed(
    node: RouteNode, other: RouteNode, pose: Pose2D, min_distance: float, *, forward: bool
) -> bool:
    """Whether ``pose`` lies beyond ``node`` toward ``other`` (``forward``: along the edge
    node -> other; else the goal case, before ``node`` on the edge other -> node)."""
    if forward:
        vx, vy = other.x - node.x, other.y - node.y
    else:
        vx, vy = node.x - other.x, node.y - other.y
    px, py = pose.x - node.x, pose.y - node.y
    dot = _normalized_dot(vx, vy, px, py)
    projects = dot > EPSILON if forward else dot < -EPSILON
    a, b = (node, other) if forward else (other, node)
    return (
        projects
        and math.hypot(px, py) > min_distance
        and _distance_to_segment(pose, a, b) <= MAX_PRUNE_DIST_FROM_EDGE
    )


def _normalized_dot(ax: float, ay: float, bx: float, by: float) -> float:
    first, second = math.hypot(ax, ay), math.hypot(bx, by)
    if first < 1e-6 or second < 1e-6:
        return 0.0
    return (ax * bx + ay * by) / (first * second)


def _distance_to_segment(pose: Pose2D, a: RouteNode, b: RouteNode) -> float:
    vx, vy = b.x - a.x, b.y - a.y
    length2 = vx * vx + vy * vy
    if length2 < 1e-6:
        return a.distance_to(pose.x, pose.y)
    t = max(0.0, min(1.0, ((pose.x - a.x) * vx + (pose.y - a.y) * vy) / length2))
    return math.hypot(a.x + t * vx - pose.x, a.y + t * vy - pose.y)


def densify(graph: RouteGraph, route: Route, density: float = PATH_DENSITY) -> list[Pose2D]:
    """The route as a dense path (see the module docstring)."""
    points: list[tuple[float, float]] = []
    for edge in route.edges:
        start, end = graph.nodes[edge.start], graph.nodes[edge.end]
        length = math.hypot(end.x - start.x, end.y - start.y)
        count = math.ceil(length / density)
        for index in range(count):  # the end is the next edge's start, or added below
            share = index / count
            points.append(
                (start.x + (end.x - start.x) * share, start.y + (end.y - start.y) * share)
            )
    last = graph.nodes[route.edges[-1].end] if route.edges else route.start
    points.append((last.x, last.y))
    poses: list[Pose2D] = []
    for index, (x, y) in enumerate(points):
        if index + 1 < len(points):
            after = points[index + 1]
            yaw = math.atan2(after[1] - y, after[0] - x)
        elif route.edges:
            start = graph.nodes[route.edges[-1].start]
            yaw = math.atan2(last.y - start.y, last.x - start.x)
        else:
            yaw = 0.0
        poses.append(Pose2D(x, y, yaw))
    return poses


@dataclass(frozen=True)
class TrackerFeedback:
    """One ``ComputeAndTrackRoute`` feedback message's ids."""

    rerouted: bool
    next_node_id: int
    last_node_id: int
    current_edge_id: int


class RouteTracker:
    """Nav2's route tracker on one route; :meth:`update` with each robot pose."""

    def __init__(
        self,
        graph: RouteGraph,
        route: Route,
        *,
        radius: float = RADIUS_TO_ACHIEVE_NODE,
        boundary_radius: float = BOUNDARY_RADIUS_TO_ACHIEVE_NODE,
    ) -> None:
        self.graph = graph
        self.route = route
        self.radius = radius
        self.boundary_radius = boundary_radius
        self.edge_index = -1  # the route edge being driven (-1: heading to the start node)
        self.next_node: RouteNode | None = route.start
        self.last_node: RouteNode | None = None
        self.current_edge: RouteEdge | None = None
        self.within_radius = False
        self.completed = False

    def start(self) -> TrackerFeedback:
        """The feedback sent when tracking (re)starts."""
        return TrackerFeedback(True, self.route.start.id, 0, 0)

    def update(self, pose: Pose2D) -> TrackerFeedback | None:
        """Feedback when the robot at ``pose`` achieved a node, else None; the last node
        achieved sets :attr:`completed`."""
        if self.completed or not self._achieved(pose):
            return None
        self.within_radius = False
        self.last_node = self.next_node
        self.edge_index += 1
        assert self.last_node is not None
        if self.edge_index < len(self.route.edges):
            self.current_edge = self.route.edges[self.edge_index]
            self.next_node = self.graph.nodes[self.current_edge.end]
            return TrackerFeedback(
                False, self.next_node.id, self.last_node.id, self.current_edge.id
            )
        self.current_edge = None
        self.next_node = None
        self.completed = True
        return TrackerFeedback(False, 0, self.last_node.id, 0)

    def _achieved(self, pose: Pose2D) -> bool:
        node = self.next_node
        assert node is not None
        dx, dy = node.x - pose.x, node.y - pose.y
        distance = math.hypot(dx, dy)
        boundary = self.edge_index == len(self.route.edges) - 1 or (
            self.edge_index == -1 and self.current_edge is None
        )
        in_radius = distance <= (self.boundary_radius if boundary else self.radius)
        if distance < 1e-4 or (not in_radius and self.within_radius):
            return True
        self.within_radius = in_radius
        if boundary:
            return self.within_radius
        if not self.within_radius or self.current_edge is None:
            return False
        last = self.graph.nodes[self.current_edge.start]
        future = self.graph.nodes[self.route.edges[self.edge_index + 1].end]
        nx, ny = node.x - last.x, node.y - last.y
        mx, my = future.x - node.x, future.y - node.y
        n_mag, m_mag = math.hypot(nx, ny), math.hypot(mx, my)
        if n_mag < 1e-6 or m_mag < 1e-6:
            return True
        # The bisector of the edges in and out; past its orthogonal line: achieved.
        bx, by = nx * m_mag + mx * n_mag, ny * m_mag + my * n_mag
        return _normalized_dot(bx, by, dx, dy) <= 0.0


__all__ = [
    "Rerouting",
    "Route",
    "RouteErrorCode",
    "RouteFailure",
    "RouteGoal",
    "RouteTracker",
    "TrackerFeedback",
    "densify",
    "plan_route",
]
