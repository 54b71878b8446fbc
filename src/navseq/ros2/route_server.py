"""Nav2's route server on the ROS 2 simulator node: ``compute_route`` and
``compute_and_track_route`` (``nav2_msgs/action/ComputeRoute`` /
``ComputeAndTrackRoute``), ``route_server/set_route_graph``
(``nav2_msgs/srv/SetRouteGraph``), the rerouting operation's
``route_server/ReroutingService/reroute`` (``std_srvs/srv/Trigger``), the graph on
``route_graph`` (``visualization_msgs/MarkerArray``, transient local) and each route's
path on ``plan``, as navigation2's ``nav2_route`` (Jazzy) serves them.

The graph is ``--route-graph FILE`` (:mod:`navseq.sim.route_graph`); without one, as in
Nav2 without ``graph_filepath``, every goal ends ABORTED with a default result (code 0)
and "No graph set! Aborting request." in the log. A ``set_route_graph`` that fails
leaves no graph (Jazzy clears it first). The rules are :mod:`navseq.ros2.routing`'s;
``compute_and_track_route`` tracks the robot (its localised pose) along the route and
drives nothing, as Nav2's. A new goal of an action preempts its running one, which ends
ABORTED with an empty result (Nav2's ``SimpleActionServer``); a cancel ends it CANCELED.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from geometry_msgs.msg import Point, PoseStamped
from nav2_msgs.action import ComputeAndTrackRoute, ComputeRoute
from nav2_msgs.msg import Route as RouteMsg
from nav2_msgs.msg import RouteEdge as RouteEdgeMsg
from nav2_msgs.msg import RouteNode as RouteNodeMsg
from nav2_msgs.srv import SetRouteGraph
from nav_msgs.msg import Path as PathMsg
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger
from visualization_msgs.msg import Marker, MarkerArray

from navseq.errors import NavseqError, error_text
from navseq.geometry import Pose2D
from navseq.ros2.lifecycle import Nav2Lifecycle
from navseq.ros2.messages import duration_msg, finish_goal, pose_stamped
from navseq.ros2.routing import (
    Rerouting,
    Route,
    RouteErrorCode,
    RouteFailure,
    RouteGoal,
    RouteTracker,
    TrackerFeedback,
    densify,
    plan_route,
)
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.route_graph import RouteGraph, read_route_graph

TRACK_PERIOD = 0.02  # s of wall time between two tracker updates (tracker_update_rate 50 Hz)
LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)

InMap = Callable[[PoseStamped], Pose2D | str]


class RouteServer:
    """The route server's actions, services and topics on ``node``; see the module doc.

    It registers with the stand-in as a driver that never drives, so that the stand-in's
    ``abort_all`` (the node shutting down) ends a tracking goal too.
    """

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        lifecycle: Nav2Lifecycle,
        *,
        graph: RouteGraph | None,
        in_map: InMap,
        stamp: Callable[[], Any],
        frame: str,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._in_map = in_map
        self._stamp = stamp
        self._frame = frame
        self._log = node.get_logger()
        self.graph = graph
        self._tracking = 0  # generation of the compute_and_track_route goal that runs
        self._reroute = threading.Event()
        self._stopping = threading.Event()
        self._graph_pub = node.create_publisher(MarkerArray, "route_graph", LATCHED)
        self._path_pub = node.create_publisher(PathMsg, "plan", 10)
        self.servers = lifecycle.action_servers(
            node,
            group,
            self._log.info,
            [
                (ComputeRoute, "compute_route", self._execute_compute),
                (ComputeAndTrackRoute, "compute_and_track_route", self._execute_track),
            ],
        )
        node.create_service(
            SetRouteGraph, "route_server/set_route_graph", self._set_graph, callback_group=group
        )
        node.create_service(Trigger, "route_server/ReroutingService/reroute", self._request_reroute)
        standin.drivers.append(self)
        if graph is None:
            self._log.info("route_server: No graph file provided to load yet.")
        else:
            self._log.info(
                f"route_server: graph {graph.source}: {len(graph.nodes)} nodes, "
                f"{len(graph.edges)} edges"
            )
        self._publish_graph()

    # -- the stand-in's driver protocol: never drives, ends with the node ---------------

    def drives(self, _now: float) -> bool:
        return False

    def step(self, _now: float, _pose: Pose2D, _collides: Any) -> tuple[float, float]:
        return (0.0, 0.0)

    def abort_all(self, _now: float, _why: str) -> None:
        self._stopping.set()

    # -- actions -----------------------------------------------------------------------

    def _execute_compute(self, handle: Any) -> Any:
        self._log.info("Computing route to goal.")
        started = time.monotonic()
        result = ComputeRoute.Result()
        found = self._route(handle.request, Rerouting())
        if isinstance(found, RouteFailure):
            return self._fail(handle, result, found)
        if found is None:
            finish_goal(handle, "ABORTED")
            return result
        graph, route, path = found
        result.route = self._route_msg(route, graph)
        result.path = path
        result.planning_time = duration_msg(time.monotonic() - started)
        finish_goal(handle, "SUCCEEDED")
        return result

    def _execute_track(self, handle: Any) -> Any:
        self._log.info("Computing and tracking route to goal.")
        with self._lock:
            self._tracking += 1
            generation = self._tracking
            started = self._standin.time
        self._reroute.clear()
        result = ComputeAndTrackRoute.Result()
        rerouting = Rerouting()
        while True:
            found = self._route(handle.request, rerouting)
            if isinstance(found, RouteFailure):
                return self._fail(handle, result, found)
            if found is None:
                finish_goal(handle, "ABORTED")
                return result
            graph, route, path = found
            ending = self._track(handle, generation, graph, route, path, rerouting)
            if ending == "rerouted":
                continue
            if ending == "SUCCEEDED":
                self._log.info("Routing to goal completed!")
                with self._lock:
                    result.execution_duration = duration_msg(self._standin.time - started)
            elif ending == "CANCELED":
                self._log.info("Goal was canceled. Canceling route planning action.")
            finish_goal(handle, ending)
            return result

    def _track(
        self,
        handle: Any,
        generation: int,
        graph: RouteGraph,
        route: Route,
        path: PathMsg,
        rerouting: Rerouting,
    ) -> str:
        """Follow the robot along ``route`` until it ends: SUCCEEDED, CANCELED, ABORTED
        (preempted, or the node stops) or "rerouted"."""
        route_msg = self._route_msg(route, graph)
        tracker = RouteTracker(graph, route)
        self._feedback(handle, tracker.start(), route_msg, path)
        while True:
            if handle.is_cancel_requested:
                return "CANCELED"
            if self._stopping.is_set() or self._tracking != generation:
                return "ABORTED"
            if self._reroute.is_set():
                self._reroute.clear()
                self._log.info("Rerouting requested by route tracking operations!")
                with self._lock:
                    robot = self._standin.localization.believed_pose
                last = tracker.last_node
                rerouting.start_id = last.id if last is not None else None
                rerouting.start_pose = robot if last is not None else None
                return "rerouted"
            with self._lock:
                robot = self._standin.localization.believed_pose
            update = tracker.update(robot)
            if update is not None:
                self._feedback(handle, update, route_msg, path)
            if tracker.completed:
                return "SUCCEEDED"
            time.sleep(TRACK_PERIOD)

    def _route(
        self, request: Any, rerouting: Rerouting
    ) -> tuple[RouteGraph, Route, PathMsg] | RouteFailure | None:
        """The route for a goal (None: no graph, logged), or why there is none."""
        with self._lock:
            graph = self.graph
            robot = self._standin.localization.believed_pose
            start = self._in_map(request.start) if request.use_start else None
            goal = self._in_map(request.goal) if request.use_poses else None
        if graph is None:
            self._log.info("No graph set! Aborting request.")
            return None
        for pose in (start, goal):
            if isinstance(pose, str):
                return RouteFailure(RouteErrorCode.TF_ERROR, pose)
        wanted = RouteGoal(
            start_id=int(request.start_id),
            goal_id=int(request.goal_id),
            start=start if isinstance(start, Pose2D) else None,
            goal=goal if isinstance(goal, Pose2D) else None,
            use_start=bool(request.use_start),
            use_poses=bool(request.use_poses),
        )
        try:
            route = plan_route(graph, wanted, robot, rerouting)
        except RouteFailure as failure:
            return failure
        self._log.info(
            f"Route found with {len(route.edges) + 1} nodes and {len(route.edges)} edges"
        )
        path = PathMsg()
        path.header.frame_id = self._frame
        path.header.stamp = self._stamp()
        path.poses = [
            pose_stamped(pose, self._frame, path.header.stamp) for pose in densify(graph, route)
        ]
        self._path_pub.publish(path)
        return graph, route, path

    def _fail(self, handle: Any, result: Any, failure: RouteFailure) -> Any:
        request = handle.request
        self._log.warning(
            f"Route server failed on request: Start: [({request.start.pose.position.x:.2f}, "
            f"{request.start.pose.position.y:.2f}) / {request.start_id}] Goal: "
            f"[({request.goal.pose.position.x:.2f}, {request.goal.pose.position.y:.2f}) / "
            f'{request.goal_id}]: "{failure}"'
        )
        result.error_code = int(failure.code)
        finish_goal(handle, "ABORTED")
        return result

    def _feedback(
        self, handle: Any, update: TrackerFeedback, route: RouteMsg, path: PathMsg
    ) -> None:
        feedback = ComputeAndTrackRoute.Feedback()
        feedback.rerouted = update.rerouted
        feedback.next_node_id = update.next_node_id
        feedback.last_node_id = update.last_node_id
        feedback.current_edge_id = update.current_edge_id
        feedback.route = route
        feedback.path = path
        handle.publish_feedback(feedback)

    def _route_msg(self, route: Route, graph: RouteGraph) -> RouteMsg:
        message = RouteMsg()
        message.header.frame_id = self._frame
        message.header.stamp = self._stamp()
        message.route_cost = float(route.cost)
        message.nodes = [
            RouteNodeMsg(nodeid=node_id, position=_point(graph.nodes[node_id]))
            for node_id in route.node_ids()
        ]
        message.edges = [
            RouteEdgeMsg(
                edgeid=edge.id,
                start=_point(graph.nodes[edge.start]),
                end=_point(graph.nodes[edge.end]),
            )
            for edge in route.edges
        ]
        return message

    # -- services and the graph's markers -----------------------------------------------

    def _set_graph(self, request: Any, response: Any) -> Any:
        self._log.info(f"Setting new route graph: {request.graph_filepath}.")
        with self._lock:
            self.graph = None  # Jazzy clears the graph before loading the new one
        try:
            graph = read_route_graph(Path(request.graph_filepath))
        except NavseqError as error:
            self._log.warning(f"Failed to set new route graph: {error_text(error)}")
            response.success = False
            return response
        with self._lock:
            self.graph = graph
        self._publish_graph()
        response.success = True
        return response

    def _request_reroute(self, _request: Any, response: Any) -> Any:
        self._log.info("A reroute has been requested!")
        self._reroute.set()
        response.success = True
        return response

    def _publish_graph(self) -> None:
        """The graph as Nav2 draws it: node spheres, edge lines, id labels."""
        graph = self.graph
        stamp = self._stamp()
        markers: list[Marker] = []
        nodes = _marker(self._frame, stamp, "route_graph_nodes", Marker.SPHERE_LIST, 0.1)
        nodes.color.r = 1.0
        edges = _marker(self._frame, stamp, "route_graph_edges", Marker.LINE_LIST, 0.05)
        edges.color.g, edges.color.a = 1.0, 0.5
        if graph is not None:  # no graph: empty markers, which clear a display's old graph
            for number, node in enumerate(graph.nodes.values(), 1):
                nodes.points.append(_point(node))
                markers.append(_label(self._frame, stamp, "route_graph_node_ids", number, node))
            for edge in graph.edges:
                start, end = graph.nodes[edge.start], graph.nodes[edge.end]
                edges.points.extend([_point(start), _point(end)])
        markers.extend([edges, nodes])
        self._graph_pub.publish(MarkerArray(markers=markers))


def _point(node: Any) -> Point:
    return Point(x=float(node.x), y=float(node.y), z=0.0)


def _marker(frame: str, stamp: Any, namespace: str, kind: int, scale: float) -> Marker:
    marker = Marker()
    marker.header.frame_id = frame
    marker.header.stamp = stamp
    marker.ns = namespace
    marker.type = kind
    marker.action = Marker.ADD
    marker.scale.x = marker.scale.y = marker.scale.z = scale
    marker.color.a = 1.0
    return marker


def _label(frame: str, stamp: Any, namespace: str, number: int, node: Any) -> Marker:
    marker = _marker(frame, stamp, namespace, Marker.TEXT_VIEW_FACING, 0.1)
    marker.id = number
    marker.color.r = 1.0
    marker.pose.position.x = float(node.x) + 0.07
    marker.pose.position.y = float(node.y)
    marker.text = str(node.id)
    return marker


__all__ = ["RouteServer"]
