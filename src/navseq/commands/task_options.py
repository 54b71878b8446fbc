"""The options that say what a mission's tasks may do, for ``navseq run`` and
``navseq validate``: ``--allow-run`` and ``--simulate-tasks[=SECONDS]``."""

from __future__ import annotations

import argparse
import math

from navseq.mission.fields import MAX_SECONDS
from navseq.tasks.options import DEFAULT_SIMULATED_SECONDS, TaskOptions


def add_task_options(parser: argparse.ArgumentParser) -> None:
    """What the waypoints' tasks may do (``navseq run`` and ``navseq validate``)."""
    parser.add_argument(
        "--allow-run",
        action="store_true",
        help="let the mission's run: tasks start their programs (a mission file may not "
        "run programs by itself)",
    )
    parser.add_argument(
        "--simulate-tasks",
        type=parse_simulated_seconds,
        nargs="?",
        const=DEFAULT_SIMULATED_SECONDS,
        metavar="SECONDS",
        help="on the simulator, rehearse ROS tasks (wait_for, snapshot, call, publish): "
        f"each is logged and succeeds after SECONDS (default {DEFAULT_SIMULATED_SECONDS:g})",
    )


def parse_simulated_seconds(text: str) -> float:
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and 0 <= seconds <= MAX_SECONDS):
        raise argparse.ArgumentTypeError(f"must be a number of seconds >= 0, not {text!r}")
    return seconds


def task_options_of(args: argparse.Namespace) -> TaskOptions:
    return TaskOptions(allow_run=args.allow_run, simulate_ros_s=args.simulate_tasks)
