"""``navseq sim --ros2|--ros1``: the simulated robot and a navigation stand-in, as ROS nodes.

``--ros2`` runs :mod:`navseq.ros2.sim_node` (Nav2's interfaces) in this process; ``--ros1``
starts the ROS 1 sim nodes (move_base's interface) as child processes, and a rosmaster
when none answers (:mod:`navseq.ros1.sim_launcher`). Either serves until Ctrl-C (exit 0).
Both take the same options (:mod:`navseq.commands.sim_options`), checked before any ROS is
imported; without the chosen ROS the command says so and exits 2.
"""

from __future__ import annotations

import argparse

from navseq.errors import NavseqError

ROS2_MISSING = (
    "ROS 2 is not importable here (no rclpy / nav2_msgs): source ROS 2 first, e.g. "
    "`source /opt/ros/jazzy/setup.bash`, then run navseq sim --ros2 again"
)


def configure(parser: argparse.ArgumentParser) -> None:
    from navseq.commands.sim_options import add_arguments

    middleware = parser.add_mutually_exclusive_group(required=True)
    middleware.add_argument(
        "--ros2",
        action="store_true",
        help="serve Nav2's interfaces over ROS 2 (navigate_to_pose, odom, tf, map, ...)",
    )
    middleware.add_argument(
        "--ros1",
        action="store_true",
        help="the ROS 1 sim nodes: move_base (actionlib), odom, tf, map; uses the master at "
        "ROS_MASTER_URI or starts one",
    )
    add_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from navseq.commands.sim_options import config_from_args

    # Bad options are reported even where the chosen ROS is missing.
    config = config_from_args(args, ros1=args.ros1)
    if args.ros1:
        from navseq.ros1 import sim_launcher

        start = sim_launcher.start_pose(config)  # a start in a wall is bad input, too
        if sim_launcher.ros1_missing() is not None:
            raise NavseqError(sim_launcher.ROS1_MISSING, source="navseq sim --ros1")
        return sim_launcher.run(config, start, args.robot)
    from navseq.ros2 import ros2_missing

    if ros2_missing() is not None:
        raise NavseqError(ROS2_MISSING, source="navseq sim --ros2")
    from navseq.ros2.sim_node import run as run_node

    return run_node(config)
