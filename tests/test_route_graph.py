"""The route graph of ``navseq sim --ros2 --route-graph`` (Nav2's GeoJSON format) and the
route server's rules (:mod:`navseq.ros2.routing`), without ROS: the example graph of
the TurtleBot3 arena reads, every mistake is one error naming the file and the feature,
routes follow the one-way edges, pruning and node tracking are Nav2's."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.ros2.routing import (
    Rerouting,
    RouteErrorCode,
    RouteFailure,
    RouteGoal,
    RouteTracker,
    densify,
    plan_route,
)
from navseq.sim.options import checked_config
from navseq.sim.route_graph import RouteGraph, read_route_graph, shortest_route
from test_layers import run_without_ros

REPO = Path(__file__).resolve().parents[1]
MAP = REPO / "maps" / "turtlebot3_world.yaml"
GRAPH = REPO / "examples" / "turtlebot3_route_graph.geojson"
CLI = "import sys\nfrom navseq.cli import main\nsys.exit(main(sys.argv[1:]))\n"


def _point(node_id: int, x: float, y: float) -> dict:
    return {
        "type": "Feature",
        "properties": {"id": node_id},
        "geometry": {"type": "Point", "coordinates": [x, y]},
    }


def _line(edge_id: int, start: int, end: int, **extra: object) -> dict:
    return {
        "type": "Feature",
        "properties": {"id": edge_id, "startid": start, "endid": end, **extra},
        "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]},
    }


def write(tmp_path: Path, features: list[dict]) -> Path:
    path = tmp_path / "graph.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.fixture(scope="module")
def graph() -> RouteGraph:
    return read_route_graph(GRAPH)


def test_the_example_graph_reads_with_its_one_way_loops(graph: RouteGraph) -> None:
    assert len(graph.nodes) == 12 and len(graph.edges) == 26
    assert (graph.nodes[10].x, graph.nodes[10].y) == (0.55, -1.55)
    there = shortest_route(graph, 1, 10)
    back = shortest_route(graph, 10, 1)
    assert there is not None and back is not None
    assert [1, *(edge.end for edge in there[0])] == [1, 2, 9, 10]
    assert [10, *(edge.end for edge in back[0])] == [10, 3, 2, 1]
    assert there[1] == pytest.approx(3.2)


@pytest.mark.parametrize(
    ("features", "message"),
    [
        ([], "does not contain nodes (Point features) and edges"),
        ([_point(1, 0, 0), _line(5, 1, 2)], "feature 1: edge 5's endid 2 is not a node"),
        ([_point(1, 0, 0), _point(1, 1, 0), _line(5, 1, 1)], "feature 1: node id 1 is given twice"),
        ([_point(70000, 0, 0), _line(5, 1, 1)], "feature 0: id must be a whole number 0..65535"),
        (
            [{**_point(1, 0, 0), "properties": {"id": 1, "frame": "odom"}}, _line(5, 1, 1)],
            "feature 0: frame 'odom'",
        ),
        ([_point(1, 0, 0), _line(5, 1, 1, cost="high")], "feature 1: cost must be a number"),
    ],
)
def test_every_mistake_names_the_file_and_the_feature(
    tmp_path: Path, features: list[dict], message: str
) -> None:
    with pytest.raises(NavseqError) as caught:
        read_route_graph(write(tmp_path, features))
    assert "graph.geojson" in str(caught.value)
    assert message in str(caught.value)


def test_a_file_that_is_not_json_names_its_line(tmp_path: Path) -> None:
    path = tmp_path / "graph.geojson"
    path.write_text('{\n  "features": [\n    oops\n  ]\n}\n')
    with pytest.raises(NavseqError, match=r"graph\.geojson:3: not valid JSON"):
        read_route_graph(path)


def test_the_graph_is_part_of_the_ros2_simulators_checked_settings() -> None:
    config = checked_config(map_yaml=MAP, route_graph=GRAPH)
    assert config.route_graph is not None and len(config.route_graph.nodes) == 12
    with pytest.raises(NavseqError, match="--route-graph: the route server is Nav2's"):
        checked_config(map_yaml=MAP, route_graph=GRAPH, ros1=True)


def test_navseq_sim_refuses_a_bad_graph_before_any_ros(tmp_path: Path) -> None:
    bad = write(tmp_path, [_point(1, 0, 0), _line(5, 1, 2)])
    done = run_without_ros(CLI, "sim", "--ros2", "--map", str(MAP), "--route-graph", str(bad))
    assert done.returncode == 2, done.stderr
    assert "edge 5's endid 2 is not a node" in done.stderr
    assert "Traceback" not in done.stderr


def _goal(start: Pose2D | None, goal: Pose2D) -> RouteGoal:
    return RouteGoal(0, 0, start, goal, use_start=start is not None, use_poses=True)


def test_poses_go_to_their_nearest_nodes_and_passed_end_nodes_are_pruned(
    graph: RouteGraph,
) -> None:
    robot = Pose2D(-2.0, -0.5, 0.0)  # before node 1 (-1.65, -0.55): not past it
    route = plan_route(graph, _goal(None, Pose2D(0.55, -1.55, 0.0)), robot, Rerouting())
    assert route.node_ids() == [1, 2, 9, 10]
    # Started between nodes 1 and 2, goal between 9 and 10: both end nodes pruned.
    inside = plan_route(
        graph,
        _goal(Pose2D(-1.2, -0.55, 0.0), Pose2D(0.2, -1.55, 0.0)),
        robot,
        Rerouting(),
    )
    assert inside.node_ids() == [2, 9]
    assert inside.cost == pytest.approx(1.0)  # the edge 2 -> 9 alone


def test_ids_not_in_the_graph_and_no_route_fail_with_nav2s_codes(graph: RouteGraph) -> None:
    robot = Pose2D(-2.0, -0.5, 0.0)
    with pytest.raises(RouteFailure) as caught:
        plan_route(graph, RouteGoal(1, 99, None, None, False, False), robot, Rerouting())
    assert caught.value.code is RouteErrorCode.UNKNOWN
    one_way = RouteGraph(
        {1: graph.nodes[1], 2: graph.nodes[2]},
        [edge for edge in graph.edges if (edge.start, edge.end) == (1, 2)],
    )
    with pytest.raises(RouteFailure) as caught:
        plan_route(one_way, RouteGoal(2, 1, None, None, False, False), robot, Rerouting())
    assert caught.value.code is RouteErrorCode.NO_VALID_ROUTE


def test_the_dense_path_follows_the_edges_every_5_cm(graph: RouteGraph) -> None:
    route = plan_route(
        graph, RouteGoal(1, 10, None, None, False, False), Pose2D(0, 0, 0), Rerouting()
    )
    path = densify(graph, route)
    assert (path[0].x, path[0].y) == (-1.65, -0.55)
    assert (path[-1].x, path[-1].y) == pytest.approx((0.55, -1.55))
    assert max(a.distance_to(b) for a, b in itertools.pairwise(path)) <= 0.05 + 1e-9
    assert path[-1].yaw == pytest.approx(0.0)  # along the last edge, 9 -> 10


def test_the_tracker_passes_each_node_in_turn_as_the_robot_drives_the_path(
    graph: RouteGraph,
) -> None:
    route = plan_route(
        graph, RouteGoal(1, 10, None, None, False, False), Pose2D(0, 0, 0), Rerouting()
    )
    tracker = RouteTracker(graph, route)
    assert tracker.start().rerouted
    passed = []
    for pose in [Pose2D(-2.0, -0.55, 0.0), *densify(graph, route)]:
        update = tracker.update(pose)
        if update is not None:
            passed.append(update.last_node_id)
    assert passed == [1, 2, 9, 10]
    assert tracker.completed
    assert math.isclose(graph.nodes[10].y, -1.55)
