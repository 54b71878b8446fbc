"""``navseq sim --ros2``: the simulated robot and a Nav2 stand-in, as ROS 2 nodes.

Runs :mod:`navseq.ros2.sim_node` in this process until Ctrl-C (exit 0). ROS 2 must be
sourced (rclpy importable); without it the command says so and exits 2. ``--ros1`` (the
ROS 1 sim nodes) is not there yet: ``roslaunch navseq sim.launch`` starts them.
"""

from __future__ import annotations

import argparse

from navseq.errors import NavseqError

ROS2_MISSING = (
    "ROS 2 is not importable here (no rclpy / nav2_msgs): source ROS 2 first, e.g. "
    "`source /opt/ros/jazzy/setup.bash`, then run navseq sim --ros2 again"
)


def configure(parser: argparse.ArgumentParser) -> None:
    from navseq.ros2.sim_config import add_arguments

    middleware = parser.add_mutually_exclusive_group(required=True)
    middleware.add_argument(
        "--ros2",
        action="store_true",
        help="serve Nav2's interfaces over ROS 2 (navigate_to_pose, odom, tf, map, ...)",
    )
    middleware.add_argument(
        "--ros1",
        action="store_true",
        help="the ROS 1 sim nodes (not yet: use `roslaunch navseq sim.launch`)",
    )
    add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from navseq.ros2.sim_config import config_from_args

    if args.ros1:
        raise NavseqError(
            "--ros1 is not available yet: start the ROS 1 simulator with "
            "`roslaunch navseq sim.launch` (or sim_robot.launch)",
            source="navseq sim",
        )
    config = config_from_args(args)  # bad options are reported even without ROS 2
    from navseq.ros2 import ros2_missing

    if ros2_missing() is not None:
        raise NavseqError(ROS2_MISSING, source="navseq sim --ros2")
    from navseq.ros2.sim_node import run as run_node

    return run_node(config)
