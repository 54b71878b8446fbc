"""The simulator's settings and their checks, without ROS.

Shared by ``python -m navseq.ros2.sim_node``, ``navseq sim --ros2`` and ``navseq sim
--ros1`` (:mod:`navseq.ros1.sim_launcher`) so that all check the same settings the same
way; their command-line options are in :mod:`navseq.commands.sim_options`. Importing
this module imports no ROS.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from navseq.errors import NavseqError
from navseq.files import require_file
from navseq.geometry import Pose2D
from navseq.mission.costmap_filters import CostmapFilter
from navseq.mission.geodesy import Datum, GeoPoint, check_latitude, check_longitude
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.sim.docks import Dock, read_docks_file
from navseq.sim.fleet import other_robots_problem
from navseq.sim.route_graph import RouteGraph, read_route_graph
from navseq.text import printable

# Name rules for one namespace token: letters, digits, underscores; ROS 2 refuses a digit
# first, ROS 1 anything but a letter first.
_NAMESPACE_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_ROS1_NAMESPACE_TOKEN = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
MAX_SPEED = 100.0  # beyond this the simulation cannot keep up on any machine anyway
# --tf-convention: where a namespaced robot's transforms go and how its frames are named.
# nav2: nav2_bringup's multi-robot launch (/NS/tf, /NS/tf_static, plain frame names);
# ros1: ROS 1's multi_robot.launch (the global /tf, frames NS/odom, NS/base_footprint).
TF_CONVENTIONS = ("nav2", "ros1")
# --initial-pose: what initialpose does. estimate: amcl's (the belief moves, the robot
# does not); teleport: the robot is put there (for scripts that place it, as before).
INITIAL_POSE_MODES = ("estimate", "teleport")
MAX_ODOM_DRIFT = 0.5  # per metre; more is no odometry at all


def default_map() -> Path | None:
    """The TurtleBot3 world of a source checkout (``maps/`` next to ``src/``), if there."""
    candidate = Path(__file__).resolve().parents[3] / "maps" / "turtlebot3_world.yaml"
    return candidate if candidate.is_file() else None


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
    docks: tuple[Dock, ...] = ()  # the docking server's docks (--docks, ROS 2 only)
    datum: Datum | None = None  # --datum: follow_gps_waypoints' and fromLL's (ROS 2)
    route_graph: RouteGraph | None = None  # --route-graph: the route server's (ROS 2)
    tf_convention: str = "nav2"  # one of TF_CONVENTIONS
    odom_drift: float = 0.0  # odometry error per metre driven (ROS 2 stand-in)
    initial_pose: str = "estimate"  # one of INITIAL_POSE_MODES (ROS 2 stand-in)
    # Nav2 costmap filters (--keepout, --speed-mask, --filters): keepout and speed zones
    filters: tuple[CostmapFilter, ...] = ()

    @property
    def frame_prefix(self) -> str:
        """``robot1/`` in a namespace under ROS 1's convention (the ROS 1 sim nodes');
        empty under Nav2's, whose frames are plain names on the namespace's own tf."""
        return f"{self.namespace}/" if self.namespace and self.tf_convention == "ros1" else ""

    @property
    def tf_topics(self) -> tuple[str, str]:
        """Where this robot's ``tf`` and ``tf_static`` go: ``/NS/tf`` under Nav2's
        convention in a namespace, else the global ``/tf``."""
        if self.namespace and self.tf_convention == "nav2":
            return f"/{self.namespace}/tf", f"/{self.namespace}/tf_static"
        return "/tf", "/tf_static"

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


def tf_convention_of(text: str | None, *, ros1: bool = False) -> str:
    """``--tf-convention``: ``nav2`` (default with --ros2) or ``ros1`` (the only one the
    ROS 1 nodes have)."""
    if text is None:
        return "ros1" if ros1 else "nav2"
    value = text.strip().lower()
    if value not in TF_CONVENTIONS:
        raise NavseqError(
            f"expected {' or '.join(TF_CONVENTIONS)}, got {text!r}", source="--tf-convention"
        )
    if ros1 and value != "ros1":
        raise NavseqError(
            "the ROS 1 sim nodes publish ROS 1's convention only (frames NS/odom on /tf)",
            source="--tf-convention",
        )
    return value


def odom_drift_of(value: float, *, ros1: bool = False) -> float:
    """``--odom-drift``: odometry error per metre, 0 to MAX_ODOM_DRIFT; --ros2 only."""
    if not (math.isfinite(value) and 0.0 <= value <= MAX_ODOM_DRIFT):
        raise NavseqError(
            f"must be >= 0 and <= {MAX_ODOM_DRIFT:g} (error per metre driven), got {value:g}",
            source="--odom-drift",
        )
    if ros1 and value > 0.0:
        raise NavseqError(
            "the ROS 1 sim nodes have no localisation to correct a drift: use it with --ros2",
            source="--odom-drift",
        )
    return value


def initial_pose_of(text: str, *, ros1: bool = False) -> str:
    """``--initial-pose estimate|teleport``; the ROS 1 nodes always teleport."""
    value = text.strip().lower()
    if value not in INITIAL_POSE_MODES:
        raise NavseqError(
            f"expected {' or '.join(INITIAL_POSE_MODES)}, got {text!r}", source="--initial-pose"
        )
    if ros1 and value != "teleport":
        return "teleport"  # ROS 1's stand-in has no amcl: its initialpose teleports
    return value


def checked_config(
    *,
    map_yaml: Path | None,
    start: Pose2D | None = None,
    namespace: str = "",
    speed: float = 1.0,
    robot: str | None = None,
    other_robots: str = "",
    follow_clock: str = "false",
    replan_period: float = 0.0,
    docks: Path | None = None,
    tf_convention: str | None = None,
    odom_drift: float = 0.0,
    initial_pose: str = "estimate",
    ros1: bool = False,
    datum: str = "",
    filters: tuple[CostmapFilter, ...] = (),
    route_graph: Path | None = None,
) -> SimConfig:
    """The checked settings from the values the options hold; every bad value is a
    NavseqError naming its option.

    ``robot``: a built-in profile name or a profile YAML file (None: the default robot).
    ``ros1``: for ``navseq sim --ros1``, whose nodes live under ROS 1's name rules.
    """
    from navseq.mission.robot_format import robot_from_option

    map_yaml = map_yaml if map_yaml is not None else default_map()
    if map_yaml is None:
        raise NavseqError("no map: give --map MAP.yaml (a map_server YAML)", source="--map")
    require_file(map_yaml, "--map")
    speed = float(speed)
    if not (math.isfinite(speed) and 0.0 < speed <= MAX_SPEED):
        raise NavseqError(f"must be > 0 and <= {MAX_SPEED:g}, got {speed:g}", source="--speed")
    profile = robot_from_option(robot) if robot is not None else DEFAULT_PROFILE
    own = namespace_of(namespace, ros1=ros1)
    return SimConfig(
        map_yaml=map_yaml,
        start=start,
        namespace=own,
        speed=speed,
        robot=profile,
        other_robots=other_robots_of(other_robots, own, ros1=ros1),
        follow_clock=follow_clock_of(follow_clock, speed),
        replan_period=replan_period_of(float(replan_period), ros1=ros1),
        docks=docks_of(docks, ros1=ros1),
        datum=datum_of(datum) if datum else None,
        route_graph=route_graph_of(route_graph, ros1=ros1),
        tf_convention=tf_convention_of(tf_convention, ros1=ros1),
        odom_drift=odom_drift_of(float(odom_drift), ros1=ros1),
        initial_pose=initial_pose_of(initial_pose, ros1=ros1),
        filters=filters_checked(map_yaml, filters),
    )


def filters_checked(
    map_yaml: Path, filters: tuple[CostmapFilter, ...]
) -> tuple[CostmapFilter, ...]:
    """``filters`` once their masks have been read onto the map: a mask that cannot be
    read is refused here, naming it, not when a node starts."""
    if filters:
        from navseq.sim.filters import load_filtered_map

        load_filtered_map(map_yaml, filters)
    return filters


def docks_of(path: Path | None, *, ros1: bool = False) -> tuple[Dock, ...]:
    """``--docks FILE``: the docks of a Nav2 docks file (ROS 2's docking server only)."""
    if path is None:
        return ()
    if ros1:
        raise NavseqError(
            "docking is Nav2's (opennav_docking): use it with --ros2", source="--docks"
        )
    require_file(path, "--docks")
    return read_docks_file(path)


def route_graph_of(path: Path | None, *, ros1: bool = False) -> RouteGraph | None:
    """``--route-graph FILE``: Nav2's GeoJSON route graph (ROS 2's route server only)."""
    if path is None:
        return None
    if ros1:
        raise NavseqError(
            "the route server is Nav2's (nav2_route): use it with --ros2", source="--route-graph"
        )
    require_file(path, "--route-graph")
    return read_route_graph(path)


def datum_of(text: str) -> Datum:
    """``--datum LAT,LON[,YAW]``: degrees, degrees and the map x axis' heading in degrees
    counter-clockwise from east (navseq's unit for yaw; navsat_transform's parameter has
    radians)."""
    parts = text.split(",")
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
        raise NavseqError(
            f"expected LAT,LON or LAT,LON,YAW (degrees), got {printable(text)!r}",
            source="--datum",
        )
    problem = check_latitude(values[0]) or check_longitude(values[1])
    if problem:
        raise NavseqError(problem, source="--datum")
    yaw = math.radians(values[2]) if len(values) == 3 else 0.0
    return Datum(GeoPoint(values[0], values[1]), yaw)
