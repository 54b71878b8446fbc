"""``navseq record``: record waypoints from RViz goals (or a pose topic) into a mission
file, on ROS 1. The recording itself is :func:`navseq.ros1.record.record_main`; this
module only reads the command line (:mod:`navseq.ros1.record` imports rospy only when
recording starts)."""

from __future__ import annotations

import argparse
from pathlib import Path

from navseq.ros1.record import DEFAULT_TOPIC


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("out", type=Path, help="mission file to write (navseq YAML)")
    parser.add_argument(
        "--topic",
        default=DEFAULT_TOPIC,
        help="pose topic: PoseStamped, or PoseWithCovarianceStamped for */initialpose "
        f"(default {DEFAULT_TOPIC})",
    )
    parser.add_argument("--force", action="store_true", help="replace an existing file")
    parser.add_argument(
        "--from-tf",
        action="store_true",
        help="also offer the ~record service that records the robot's current TF pose",
    )
    parser.add_argument(
        "--base-frame",
        default="base_footprint",
        help="the robot's TF frame whose pose --from-tf records (default base_footprint)",
    )
    parser.add_argument("--frame", default="map", help="frame of TF-recorded poses (default map)")


def run(args: argparse.Namespace) -> int:
    from navseq.ros1.record import record_main

    return record_main(
        args.out,
        args.topic,
        overwrite=args.force,
        from_tf=args.from_tf,
        base_frame=args.base_frame,
        frame=args.frame,
    )
