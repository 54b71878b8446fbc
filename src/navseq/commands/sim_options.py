"""The simulator's command-line options, shared by ``navseq sim`` and
``python -m navseq.ros2.sim_node`` so that both take the same options with the same
meaning; the checks behind them are :func:`navseq.sim.options.checked_config`."""

from __future__ import annotations

import argparse
from pathlib import Path

from navseq.commands.common import parse_pose
from navseq.commands.filter_options import add_sim_filter_options, sim_filters_of
from navseq.sim.options import SimConfig, checked_config


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The simulator's options (map, start, namespace, speed, robot, fleet, clock)."""
    parser.add_argument(
        "--map",
        type=Path,
        metavar="MAP",
        help="map_server YAML (default: the TurtleBot3 world of a source checkout)",
    )
    parser.add_argument(
        "--start",
        type=parse_pose,
        metavar="X,Y,YAW",
        help="start pose, metres, metres, degrees (default: the roomy point nearest the "
        "map origin)",
    )
    parser.add_argument(
        "--ns",
        default="",
        metavar="NS",
        help="ROS namespace of the robot (robot1 -> /robot1/navigate_to_pose with --ros2, "
        "/robot1/move_base with --ros1); its frames follow --tf-convention",
    )
    parser.add_argument(
        "--speed",
        type=float,
        default=1.0,
        metavar="S",
        help="simulated seconds per wall second; 1 = wall-clock time, otherwise /clock is "
        "published and clients should use use_sim_time (default 1)",
    )
    parser.add_argument(
        "--robot",
        metavar="NAME|FILE",
        help="robot profile: a built-in name (turtlebot3_burger, turtlebot3_waffle, "
        "turtlebot3_waffle_pi) or a YAML file like a mission's robot: section "
        "(default turtlebot3_burger)",
    )
    parser.add_argument(
        "--other-robots",
        default="",
        metavar="NS[,NS...]",
        help="namespaces of the other simulated robots of a fleet (e.g. robot2): their "
        "poses are read from their transforms (/NS/tf under Nav2's convention, /tf with "
        "NS/ frames under ROS 1's) and their "
        "footprints (this robot's model) are obstacles to plan around and never to drive "
        "into (see launch/multi_robot.launch.py)",
    )
    parser.add_argument(
        "--follow-clock",
        nargs="?",
        const="true",
        default="false",
        metavar="true|false",
        help="step with the /clock another simulator node publishes instead of a clock of "
        "its own: a fleet faster than wall-clock time has one robot with --speed S and the "
        "others with --follow-clock, all on one simulated time",
    )
    parser.add_argument(
        "--replan-period",
        type=float,
        default=0.0,
        metavar="S",
        help="(--ros2, for tests) simulated seconds between the re-plans of Nav2's default "
        'tree (its RateController hz="1.0" is 1 s): a navigate_to_pose goal that preempts '
        "another keeps the old path until the next re-plan, and ends SUCCEEDED if the robot "
        "reaches the old goal first, as on Nav2. 0 (default): planned at once",
    )
    parser.add_argument(
        "--docks",
        type=Path,
        metavar="FILE",
        help="(--ros2) the docking server's docks, in Nav2's docks YAML (docks: [name] "
        "and name: {type, frame, pose: [x, y, yaw]}, or a dock database file): "
        "dock_robot goals by id drive to them",
    )
    parser.add_argument(
        "--route-graph",
        type=Path,
        metavar="FILE",
        help="(--ros2) the route server's graph, in Nav2's GeoJSON route graph format "
        "(Point features: nodes; LineString features: one-way edges startid -> endid): "
        "compute_route and compute_and_track_route plan on it",
    )
    add_datum_argument(parser)
    add_world_arguments(parser)
    add_sim_filter_options(parser)


def add_datum_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--datum",
        default="",
        metavar="LAT,LON[,YAW]",
        help="(--ros2) the map frame's origin on the globe and its x axis' heading "
        "(degrees counter-clockwise from east, default 0), as navsat_transform's datum: "
        "follow_gps_waypoints and fromLL convert with it",
    )


def add_world_arguments(parser: argparse.ArgumentParser) -> None:
    """The ROS 2 stand-in's world: TF convention, odometry drift, initial pose."""
    parser.add_argument(
        "--tf-convention",
        choices=["nav2", "ros1"],
        default=None,
        help="how a namespaced robot publishes its transforms: nav2 (default with --ros2; "
        "nav2_bringup's multi-robot launch) on /NS/tf and /NS/tf_static with plain frames "
        "map, odom, base_footprint; ros1 (the only one of --ros1) on the global /tf with "
        "frames NS/odom, NS/base_footprint",
    )
    parser.add_argument(
        "--odom-drift",
        type=float,
        default=0.0,
        metavar="D",
        help="(--ros2) odometry error per metre driven: each metre reads 1+D metres and "
        "turns the heading D rad; the amcl-like localisation corrects it as the robot "
        "drives. 0 (default): exact odometry",
    )
    parser.add_argument(
        "--initial-pose",
        choices=["estimate", "teleport"],
        default="estimate",
        help="(--ros2) what initialpose does: estimate (default, as amcl) sets the "
        "localisation's estimate (map -> odom) and the robot stays where it is; teleport "
        "puts the simulated robot there (scripts that place the robot between runs)",
    )


def config_from_args(args: argparse.Namespace, *, ros1: bool = False) -> SimConfig:
    """The checked settings of parsed options; every bad value is a NavseqError naming
    its option. ``ros1``: for ``navseq sim --ros1`` (ROS 1's name rules)."""
    return checked_config(
        map_yaml=args.map,
        start=args.start,
        namespace=args.ns,
        speed=args.speed,
        robot=args.robot,
        other_robots=args.other_robots,
        follow_clock=args.follow_clock,
        replan_period=args.replan_period,
        docks=args.docks,
        tf_convention=args.tf_convention,
        odom_drift=args.odom_drift,
        initial_pose=args.initial_pose,
        ros1=ros1,
        datum=getattr(args, "datum", ""),
        filters=sim_filters_of(args),
        route_graph=getattr(args, "route_graph", None),
    )
