"""The simulator's settings: command-line options and their checks, without ROS.

Shared by ``python -m navseq.ros2.sim_node``, ``navseq sim --ros2`` and ``navseq sim
--ros1`` (:mod:`navseq.ros1.sim_launcher`) so that all take the same options with the
same meaning; importing this module imports no ROS.
"""

from __future__ import annotations

import argparse
import math
import re
from dataclasses import dataclass
from pathlib import Path

from navseq.commands.common import parse_pose, require_file
from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.sim.fleet import other_robots_problem

# Name rules for one namespace token: letters, digits, underscores; ROS 2 refuses a digit
# first, ROS 1 anything but a letter first.
_NAMESPACE_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_ROS1_NAMESPACE_TOKEN = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
MAX_SPEED = 100.0  # beyond this the simulation cannot keep up on any machine anyway


def default_map() -> Path | None:
    """The TurtleBot3 world of a source checkout (``maps/`` next to ``src/``), if there."""
    candidate = Path(__file__).resolve().parents[3] / "maps" / "turtlebot3_world.yaml"
    return candidate if candidate.is_file() else None


def add_arguments(parser: argparse.ArgumentParser) -> None:
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
        "/robot1/move_base with --ros1; frames robot1/odom, robot1/base_footprint)",
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
        "poses are read from /tf (map -> NS/odom -> NS/base_footprint) and their "
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


@dataclass(frozen=True)
class SimConfig:
    """Everything the ROS 2 simulator node needs to start."""

    map_yaml: Path
    start: Pose2D | None
    namespace: str  # "" or "robot1" (no slashes at the ends)
    speed: float
    robot: RobotProfile
    other_robots: tuple[str, ...] = ()  # namespaces of the other robots of a fleet
    follow_clock: bool = False  # step with another node's /clock (a fleet at speed != 1)
    replan_period: float = 0.0  # s: Nav2's re-plan tick on preemption; 0 = plan at once
    rate: float = 20.0  # simulation steps per simulated second

    @property
    def frame_prefix(self) -> str:
        """``robot1/`` in a namespace, as the ROS 1 sim nodes name their frames."""
        return f"{self.namespace}/" if self.namespace else ""

    @property
    def sim_time(self) -> bool:
        """Whether the node stamps with simulated time: it publishes /clock (at any
        speed but wall-clock speed) or follows another node's."""
        return self.speed != 1.0 or self.follow_clock

    @property
    def publishes_clock(self) -> bool:
        return self.speed != 1.0 and not self.follow_clock


def namespace_of(text: str, option: str = "--ns", *, ros1: bool = False) -> str:
    """``/robot1/`` -> ``robot1``; a clear error for a name ROS 2 (or ROS 1) would refuse."""
    stripped = text.strip().strip("/")
    if not stripped:
        return ""
    token = _ROS1_NAMESPACE_TOKEN if ros1 else _NAMESPACE_TOKEN
    if not all(token.fullmatch(part) for part in stripped.split("/")):
        rule = "each part starting with a letter" if ros1 else "not starting with a digit"
        raise NavseqError(
            f"{text!r} is not a ROS {1 if ros1 else 2} namespace (letters, digits and "
            f"underscores, separated by '/', {rule})",
            source=option,
        )
    return stripped


def other_robots_of(text: str, own: str, *, ros1: bool = False) -> tuple[str, ...]:
    """``robot2,robot3`` -> their namespaces, checked against this robot's own."""
    if not text.strip():
        return ()
    names = tuple(namespace_of(part, "--other-robots", ros1=ros1) for part in text.split(","))
    problem = other_robots_problem(names, own, "namespace")
    if problem is not None:
        raise NavseqError(problem, source="--other-robots")
    return names


def follow_clock_of(text: str, speed: float) -> bool:
    """``--follow-clock [true|false]``; the speed is then the clock publisher's, so a
    speed of this node's own is refused rather than ignored."""
    value = text.strip().lower()
    if value not in ("true", "false"):
        raise NavseqError(f"expected true or false, got {text!r}", source="--follow-clock")
    if value == "true" and speed != 1.0:
        raise NavseqError(
            f"--speed {speed:g} with --follow-clock: the node that publishes /clock sets "
            "the speed; give --speed to that one only",
            source="--follow-clock",
        )
    return value == "true"


def replan_period_of(value: float, *, ros1: bool = False) -> float:
    """``--replan-period``: seconds >= 0; Nav2's rule, so ROS 1's move_base has none."""
    if not (math.isfinite(value) and value >= 0.0):
        raise NavseqError(f"must be >= 0 s, got {value:g}", source="--replan-period")
    if ros1 and value > 0.0:
        raise NavseqError(
            "Nav2's re-plan on preemption has no move_base twin: use it with --ros2 (the "
            "ROS 1 move_base stand-in has ~race_window for move_base's SUCCEEDED race)",
            source="--replan-period",
        )
    return value


def config_from_args(args: argparse.Namespace, *, ros1: bool = False) -> SimConfig:
    """The checked settings; every bad value is a NavseqError naming its option.

    ``ros1``: for ``navseq sim --ros1``, whose nodes live under ROS 1's name rules.
    """
    from navseq.mission.robot_format import robot_from_option

    map_yaml = args.map if args.map is not None else default_map()
    if map_yaml is None:
        raise NavseqError("no map: give --map MAP.yaml (a map_server YAML)", source="--map")
    require_file(map_yaml, "--map")
    speed = float(args.speed)
    if not (math.isfinite(speed) and 0.0 < speed <= MAX_SPEED):
        raise NavseqError(f"must be > 0 and <= {MAX_SPEED:g}, got {args.speed}", source="--speed")
    robot = robot_from_option(args.robot) if args.robot is not None else DEFAULT_PROFILE
    namespace = namespace_of(args.ns, ros1=ros1)
    return SimConfig(
        map_yaml=map_yaml,
        start=args.start,
        namespace=namespace,
        speed=speed,
        robot=robot,
        other_robots=other_robots_of(args.other_robots, namespace, ros1=ros1),
        follow_clock=follow_clock_of(args.follow_clock, speed),
        replan_period=replan_period_of(float(args.replan_period), ros1=ros1),
    )
