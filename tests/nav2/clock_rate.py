"""Simulated seconds per wall second: ``/clock`` and the robots' odometry stamps.

usage: clock_rate.py --seconds W [ODOM_TOPIC ...]

Listens for W wall seconds (after the first ``/clock`` message) and prints one JSON
object: ``{"clock": RTF, "odom": {TOPIC: RTF}}`` where RTF is the stamps' advance over
the wall time between the first and last message heard (null if fewer than two came).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import rclpy
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rosgraph_msgs.msg import Clock

Samples = list[tuple[float, float]]  # (wall, stamp)


def rate(samples: Samples) -> float | None:
    if len(samples) < 2 or samples[-1][0] <= samples[0][0]:
        return None
    return (samples[-1][1] - samples[0][1]) / (samples[-1][0] - samples[0][0])


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("odom", nargs="*")
    args = parser.parse_args()
    rclpy.init()
    node = Node("navseq_clock_rate")
    clock: Samples = []
    odom: dict[str, Samples] = {topic: [] for topic in args.odom}

    def seconds(stamp) -> float:  # type: ignore[no-untyped-def]
        return stamp.sec + stamp.nanosec * 1e-9

    node.create_subscription(
        Clock, "/clock", lambda m: clock.append((time.monotonic(), seconds(m.clock))), 10
    )
    for topic, samples in odom.items():
        node.create_subscription(
            Odometry,
            topic,
            lambda m, s=samples: s.append((time.monotonic(), seconds(m.header.stamp))),
            10,
        )
    end = time.monotonic() + 60.0
    while not clock and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    for samples in (clock, *odom.values()):
        samples.clear()
    end = time.monotonic() + args.seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    print(json.dumps({"clock": rate(clock), "odom": {t: rate(s) for t, s in odom.items()}}))
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
