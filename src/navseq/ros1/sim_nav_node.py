"""The simulator's navigation stack as a ROS 1 node: a ``move_base`` stand-in.

Debian ships no move_base, so this node offers move_base's interface on top of
:class:`navseq.sim.navserver.NavigationServer` (global planner on an inflated costmap
plus a local controller for a differential-drive robot). Any move_base client — navseq's
node, the classic ``move_base_seq`` tutorial, RViz's "2D Nav Goal" — can drive it.

Interface (names relative to the node's namespace, as with move_base):

- action server ``move_base`` (``move_base_msgs/MoveBaseAction``): one goal at a time;
  a new goal preempts the active one (PREEMPTED), a cancel ends it PREEMPTED and stops
  the robot, a goal with no plan (in a wall, unreachable) or about to collide ends
  ABORTED with the reason in the result text, a reached goal SUCCEEDED. Feedback carries
  ``base_position`` (the robot pose in the map frame) at ``~feedback_rate`` Hz;
- ``move_base_simple/goal`` (``geometry_msgs/PoseStamped``): turned into an action goal,
  as move_base does (RViz's "2D Nav Goal");
- ``move_base/NavfnROS/plan`` (``nav_msgs/Path``): the global plan, published whenever
  it changes (the topic move_base publishes with its default navfn planner);
- ``move_base/global_costmap/costmap`` (``nav_msgs/OccupancyGrid``, latched): the
  inflated costmap in costmap_2d's 0..100 scale, for RViz; with other robots, the
  planning costmap that holds them, republished (at most once a second) when it changes;
- services ``move_base/make_plan`` (``nav_msgs/GetPlan``; an empty start frame means
  "from the robot's pose", as in move_base) and ``move_base/clear_costmaps``
  (``std_srvs/Empty``);
- ``move_base/local_costmap/footprint`` (``geometry_msgs/PolygonStamped``): the robot's
  outline placed at its pose in the global frame, as costmap_2d publishes it, so one
  RViz config shows the footprint on this stand-in and on a real move_base;
- publishes ``cmd_vel`` (``geometry_msgs/Twist``) for the robot, zero when a goal ends.

For tests, ``~race_window`` (s of wall time, default 0 = off) reproduces move_base's
SUCCEEDED race (ros-planning/navigation #949): a goal that arrives within that window
after the previous goal's result ends SUCCEEDED at once, with the robot wherever it is
(with probability ``~race_probability``, default 1). move_base applies a plan still
being computed for the previous goal to the new one; a client that sends its next goal
a few milliseconds after a result triggers it.

The robot's outline, inflation, speed limits and goal tolerances come from ``~robot``
(a built-in robot name, default ``turtlebot3_burger``, or a robot YAML file; see
:mod:`navseq.ros1.robot_param`), through the same settings the in-process simulator
uses; ``~inflation_radius``, ``~cost_scaling_factor``, ``~xy_goal_tolerance`` and
``~yaw_goal_tolerance``, when set, still override the profile's values. Give the robot
node the same ``~robot``: this node plans and stops for the outline it is told of.

Nav2's costmap filters, which move_base has not, come from ``~filters`` (a mission's
``filters:`` list: ``mask``, ``type``, ``base``, ``multiplier``; ``navseq sim --ros1
--keepout/--speed-mask/--filters`` sets it): a keepout zone is an obstacle of the
costmap (never planned through; a goal in it aborts) and a speed zone limits the
controller, as on the in-process simulator and the ROS 2 stand-in.

It knows the robot only through ROS: its pose from TF (``~global_frame`` ->
``~base_frame``) and its velocity from ``odom``, so it drives navseq's sim robot node,
or a real base, alike. The map comes from ``~map`` (a map_server YAML) or, when that is
empty, from the first message on the ``map`` topic.

In a fleet, ``~other_robots`` lists the other robots' base frames (e.g.
``[robot2/base_footprint]``); their poses come from TF every control step and the
server plans around them, stops short of them, and waits for one that blocks the only
way (see :mod:`navseq.sim.navserver` and :mod:`navseq.ros1.fleet`); they are taken to
be the same model as this robot.

Control runs at ``~controller_frequency`` Hz of ROS time, so under ``use_sim_time`` the
whole stack follows the simulated clock and its speed factor.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import random
import sys
import time
from collections.abc import Callable
from typing import Any

import actionlib
import numpy as np
import rospy
import tf2_ros
from geometry_msgs.msg import Point32, PolygonStamped, PoseStamped, Twist
from move_base_msgs.msg import (
    MoveBaseAction,
    MoveBaseActionGoal,
    MoveBaseFeedback,
    MoveBaseGoal,
    MoveBaseResult,
)
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Odometry, Path
from nav_msgs.srv import GetPlan, GetPlanRequest, GetPlanResponse
from std_srvs.srv import Empty, EmptyRequest, EmptyResponse

from navseq.errors import NavseqError
from navseq.geometry import Pose2D, compose
from navseq.mission.costmap_filters import CostmapFilter, filters_summary
from navseq.ros1.conversions import (
    grid_from_msg,
    grid_to_msg,
    pose2d_from_pose,
    pose2d_from_transform,
    pose_from_pose2d,
)
from navseq.ros1.fleet import OtherRobots, other_robots_param
from navseq.ros1.params import bool_param, float_param, param_error, str_param
from navseq.ros1.robot_param import describe_settings, sim_settings_param
from navseq.sim.costmap import INSCRIBED, LETHAL, NO_INFORMATION, Costmap, CostmapParams
from navseq.sim.filters import with_filters
from navseq.sim.footprint import Footprint
from navseq.sim.navserver import NavigationServer, NavParams, NavState
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.planner import Plan
from navseq.sim.profile import SimSettings

ACTION = "move_base"
PLAN_TOPIC = f"{ACTION}/NavfnROS/plan"
COSTMAP_TOPIC = f"{ACTION}/global_costmap/costmap"
FOOTPRINT_TOPIC = f"{ACTION}/local_costmap/footprint"
FOOTPRINT_PERIOD = 0.2  # s of ROS time between two footprint messages (RViz needs no more)
COSTMAP_PERIOD = 1.0  # s of ROS time at least between two costmap messages (they are big)
# The local planner name under which the robot's limits and tolerances are shown, as
# move_base shows its local planner's parameters (this stand-in's controller is a
# regulated pure pursuit).
LOCAL_PLANNER = "RegulatedPurePursuit"


def costmap_to_occupancy_values(cost: np.ndarray) -> np.ndarray:
    """costmap_2d's publishing scale: free 0, inflated 1..98, inscribed 99, lethal 100,
    unknown -1 (what RViz's "costmap" colour scheme expects)."""
    values = np.empty(cost.shape, dtype=np.int8)
    inflated = (cost > 0) & (cost < INSCRIBED)
    values[cost == 0] = 0
    values[inflated] = (1 + (97 * (cost[inflated].astype(np.int32) - 1)) // 251).astype(np.int8)
    values[cost == INSCRIBED] = 99
    values[cost == LETHAL] = 100
    values[cost == NO_INFORMATION] = -1
    return values


def plan_to_path(plan: Plan | None, goal: Pose2D | None, frame: str, stamp: rospy.Time) -> Path:
    """A ``nav_msgs/Path`` along ``plan``: each pose faces the next point, the last one
    has the goal's yaw. An empty path when there is no plan."""
    path = Path()
    path.header.frame_id = frame
    path.header.stamp = stamp
    if plan is None:
        return path
    points = np.asarray(plan.points, dtype=float)
    for index, (x, y) in enumerate(points):
        if index + 1 < len(points):
            nx, ny = points[index + 1]
            yaw = math.atan2(ny - y, nx - x)
        elif goal is not None:
            yaw = goal.yaw
        elif index > 0:
            px, py = points[index - 1]
            yaw = math.atan2(y - py, x - px)
        else:
            yaw = 0.0
        pose = PoseStamped()
        pose.header = path.header
        pose.pose = pose_from_pose2d(Pose2D(float(x), float(y), yaw))
        path.poses.append(pose)
    return path


@dataclasses.dataclass(frozen=True)
class NavNodeConfig:
    """The node's private parameters (see the module docstring)."""

    map_yaml: str
    global_frame: str
    base_frame: str
    controller_frequency: float
    feedback_rate: float
    pose_timeout: float
    transform_tolerance: float
    publish_costmap: bool
    settings: SimSettings  # the robot (``~robot``), before the per-parameter overrides
    costmap: CostmapParams
    nav: NavParams
    other_robots: tuple[str, ...]
    race_window: float = 0.0
    race_probability: float = 1.0
    filters: tuple[CostmapFilter, ...] = ()  # ~filters: Nav2 keepout and speed masks

    @property
    def footprint(self) -> Footprint:
        return self.settings.footprint

    @classmethod
    def from_params(cls) -> NavNodeConfig:
        settings = sim_settings_param()
        # The profile gives the defaults; the node's own parameters (move_base's names)
        # win where set, as they did before there was a profile.
        costmap_defaults = settings.costmap_params
        nav_defaults = settings.nav_params
        base_frame = str_param("base_frame", "base_footprint")
        config = cls(
            settings=settings,
            map_yaml=str_param("map", ""),
            global_frame=str_param("global_frame", "map"),
            base_frame=base_frame,
            controller_frequency=float_param("controller_frequency", 20.0),
            feedback_rate=float_param("feedback_rate", 5.0),
            pose_timeout=float_param("pose_timeout", 2.0),
            transform_tolerance=float_param("transform_tolerance", 1.0),
            publish_costmap=bool_param("publish_costmap", True),
            costmap=dataclasses.replace(
                costmap_defaults,
                inflation_radius=float_param("inflation_radius", costmap_defaults.inflation_radius),
                cost_scaling_factor=float_param(
                    "cost_scaling_factor", costmap_defaults.cost_scaling_factor
                ),
            ),
            nav=dataclasses.replace(
                nav_defaults,
                xy_tolerance=float_param("xy_goal_tolerance", nav_defaults.xy_tolerance),
                yaw_tolerance=float_param("yaw_goal_tolerance", nav_defaults.yaw_tolerance),
            ),
            other_robots=other_robots_param(base_frame),
            race_window=float_param("race_window", 0.0),
            race_probability=float_param("race_probability", 1.0),
            filters=filters_param("filters"),
        )
        for name in ("controller_frequency", "feedback_rate", "pose_timeout"):
            if not getattr(config, name) > 0:
                raise param_error(name, f"must be a positive number, got {getattr(config, name)}")
        if not config.race_window >= 0:
            raise param_error("race_window", f"must be >= 0 s, got {config.race_window}")
        if not 0.0 <= config.race_probability <= 1.0:
            raise param_error(
                "race_probability", f"must be between 0 and 1, got {config.race_probability}"
            )
        return config


def navstack_params(config: NavNodeConfig) -> dict[str, Any]:
    """The robot this node drives, under the parameter names a real move_base uses.

    A client that reads the robot from move_base's parameters
    (:mod:`navseq.ros1.navstack_params`, ``navseq run --navigator ros1``) then checks and
    judges the mission with the simulated robot, not with a guess. Keys are relative to
    the node's namespace; none of them is a parameter this node reads, so a restart with
    another ``~robot`` is not overridden by what an earlier run wrote.
    """
    limits = config.nav.limits
    return {
        "global_costmap/footprint": [[float(x), float(y)] for x, y in config.footprint.polygon],
        "global_costmap/inflation_layer/inflation_radius": config.costmap.inflation_radius,
        "global_costmap/inflation_layer/cost_scaling_factor": config.costmap.cost_scaling_factor,
        "base_local_planner": f"navseq/{LOCAL_PLANNER}",
        f"{LOCAL_PLANNER}/xy_goal_tolerance": config.nav.xy_tolerance,
        f"{LOCAL_PLANNER}/yaw_goal_tolerance": config.nav.yaw_tolerance,
        f"{LOCAL_PLANNER}/max_vel_x": limits.max_v,
        f"{LOCAL_PLANNER}/max_vel_theta": limits.max_w,
        f"{LOCAL_PLANNER}/acc_lim_x": limits.acc_v,
        f"{LOCAL_PLANNER}/acc_lim_theta": limits.acc_w,
    }


def filters_param(name: str) -> tuple[CostmapFilter, ...]:
    """``~filters``: Nav2 costmap filters as a mission's ``filters:`` list, e.g.
    ``[{mask: /maps/keepout.yaml, type: 0}, {mask: /maps/speed.yaml, type: 1, base: 100,
    multiplier: -1}]`` (mask paths absolute, or relative to the working directory)."""
    from navseq.mission import fields
    from navseq.mission.costmap_filters import read_filters
    from navseq.mission.located import from_plain
    from navseq.mission.navseq_format import read_map_path

    value = rospy.get_param(f"~{name}", [])
    where = f"param {rospy.resolve_name('~' + name)}"
    return read_filters(
        from_plain(value, where),
        where,
        lambda node, what: read_map_path(node, what, None),
        fields.number,
    )


def wait_for_map(topic: str) -> OccupancyGrid:
    """The first map on ``topic``; logs while waiting, gives up only at shutdown."""
    while not rospy.is_shutdown():
        try:
            msg = rospy.wait_for_message(topic, OccupancyGridMsg, timeout=5.0)
        except rospy.ROSException:
            rospy.loginfo("waiting for a map on %s", rospy.resolve_name(topic))
            continue
        return grid_from_msg(msg, source=f"topic {rospy.resolve_name(topic)}")
    raise NavseqError("shut down before a map arrived", source=f"topic {topic}")


class SimNavNode:
    """move_base's ROS interface around a :class:`NavigationServer`.

    Concurrency: actionlib calls the goal and preempt callbacks while holding its
    action server lock (an RLock), and any call into the simple action server takes it
    too. The node therefore uses that same lock for everything that touches the
    navigation server, which gives one lock order and no deadlock.
    """

    def __init__(self, config: NavNodeConfig, grid: OccupancyGrid) -> None:
        self.config = config
        self.costmap = Costmap.from_grid(grid, config.costmap)
        self.server = NavigationServer(self.costmap, config.nav, config.footprint)
        self._goal: Pose2D | None = None
        self._published_plan_version = -1
        self._velocity = (0.0, 0.0)
        self._last_step: rospy.Time | None = None
        self._last_feedback = rospy.Time(0)
        self._pose_missing_since: rospy.Time | None = None
        self._last_result_wall: float | None = None  # when the last goal ended (race option)
        self._last_footprint = rospy.Time(0)

        self._tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(10.0))
        self._tf_listener = tf2_ros.TransformListener(self._tf_buffer)
        self._others = (
            OtherRobots(
                self._tf_buffer,
                config.global_frame,
                config.other_robots,
                tolerance=config.transform_tolerance,
                footprint=config.footprint,
            )
            if config.other_robots
            else None
        )
        self._cmd_pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
        self._plan_pub = rospy.Publisher(PLAN_TOPIC, Path, queue_size=1, latch=True)
        self._footprint_pub = rospy.Publisher(FOOTPRINT_TOPIC, PolygonStamped, queue_size=1)
        self._simple_goal_pub = rospy.Publisher(f"{ACTION}/goal", MoveBaseActionGoal, queue_size=10)
        self._goal_ids = actionlib.GoalIDGenerator()
        self._costmap_pub = None
        self._published_costmap_version = self.server.costmap_version
        self._last_costmap_stamp = rospy.Time(0)
        if config.publish_costmap:
            self._costmap_pub = rospy.Publisher(
                COSTMAP_TOPIC, OccupancyGridMsg, queue_size=1, latch=True
            )
            self._publish_costmap(self.costmap, rospy.Time.now())
        rospy.Subscriber("odom", Odometry, self._on_odom, queue_size=10)
        rospy.Subscriber("move_base_simple/goal", PoseStamped, self._on_simple_goal, queue_size=10)

        self._as = actionlib.SimpleActionServer(ACTION, MoveBaseAction, auto_start=False)
        self._as.register_goal_callback(self._on_goal)
        self._as.register_preempt_callback(self._on_preempt)
        self._lock = self._as.action_server.lock
        rospy.Service(f"{ACTION}/make_plan", GetPlan, self._on_make_plan)
        rospy.Service(f"{ACTION}/clear_costmaps", Empty, self._on_clear_costmaps)
        self._as.start()

    # -- robot state -------------------------------------------------------------------

    def _on_odom(self, msg: Odometry) -> None:
        self._velocity = (float(msg.twist.twist.linear.x), float(msg.twist.twist.angular.z))

    def robot_pose(self) -> Pose2D | None:
        """The robot's latest pose in the global frame from TF, or None if unknown/stale."""
        try:
            transform = self._tf_buffer.lookup_transform(
                self.config.global_frame, self.config.base_frame, rospy.Time(0)
            )
        except (
            tf2_ros.LookupException,
            tf2_ros.ConnectivityException,
            tf2_ros.ExtrapolationException,
        ):
            return None
        age = (rospy.Time.now() - transform.header.stamp).to_sec()
        if age > self.config.transform_tolerance:
            return None
        return pose2d_from_transform(transform)

    def _goal_pose(self, target: PoseStamped) -> Pose2D | str:
        """The goal in the global frame, or why it cannot be used."""
        frame = target.header.frame_id.lstrip("/")
        if frame and frame != self.config.global_frame:
            try:
                transform = self._tf_buffer.lookup_transform(
                    self.config.global_frame, frame, rospy.Time(0), rospy.Duration(0.2)
                )
            except (
                tf2_ros.LookupException,
                tf2_ros.ConnectivityException,
                tf2_ros.ExtrapolationException,
            ) as error:
                return (
                    f"goal frame {frame!r} cannot be transformed to "
                    f"{self.config.global_frame!r}: {error}"
                )
            return compose(pose2d_from_transform(transform), pose2d_from_pose(target.pose))
        q = target.pose.orientation
        if not all(
            math.isfinite(v)
            for v in (q.x, q.y, q.z, q.w, target.pose.position.x, target.pose.position.y)
        ):
            return "goal pose has non-finite numbers"
        if abs(q.x) + abs(q.y) + abs(q.z) + abs(q.w) == 0.0:
            return "goal orientation is the zero quaternion (set w = 1 for yaw 0)"
        return pose2d_from_pose(target.pose)

    # -- action server callbacks (called with the action server lock held) ---------------

    def _on_goal(self) -> None:
        idle = self._goal is None  # no goal was active: this one follows a result
        goal: MoveBaseGoal | None = self._as.accept_new_goal()
        if goal is None:
            return
        target = self._goal_pose(goal.target_pose)
        if isinstance(target, str):
            rospy.logwarn("goal aborted: %s", target)
            self._finish(lambda: self._as.set_aborted(MoveBaseResult(), target))
            return
        if self._as.is_preempt_requested():
            self._finish(lambda: self._as.set_preempted(MoveBaseResult(), "canceled at once"))
            return
        if idle and self._race_strikes():
            pose = self.robot_pose()
            away = math.hypot(target.x - pose.x, target.y - pose.y) if pose else float("nan")
            rospy.logwarn(
                "race (~race_window): goal (%.2f, %.2f) SUCCEEDED at once, robot %.2f m away",
                target.x,
                target.y,
                away,
            )
            self._finish(lambda: self._as.set_succeeded(MoveBaseResult(), "goal reached"))
            return
        rospy.loginfo("new goal (%.2f, %.2f, %.2f rad)", target.x, target.y, target.yaw)
        self._goal = target
        self._last_step = None
        self._pose_missing_since = None
        self.server.set_goal(target)

    def _on_preempt(self) -> None:
        if self._as.is_new_goal_available():
            return  # _on_goal follows at once; accepting the new goal preempts this one
        rospy.loginfo("goal canceled")
        self._finish(lambda: self._as.set_preempted(MoveBaseResult(), "canceled by the client"))

    def _race_strikes(self) -> bool:
        """The test option ``~race_window`` makes this goal inherit the last one's success."""
        window = self.config.race_window
        last = self._last_result_wall
        if window <= 0 or last is None or time.monotonic() - last > window:
            return False
        return random.random() < self.config.race_probability

    def _finish(self, report: Callable[[], None]) -> None:
        """End the active goal: stop the server and the robot, then tell the client."""
        self.server.cancel()
        self._goal = None
        self._cmd_pub.publish(Twist())
        report()
        self._last_result_wall = time.monotonic()

    # -- topics and services ----------------------------------------------------------------

    def _on_simple_goal(self, msg: PoseStamped) -> None:
        """RViz's 2D Nav Goal: wrap it into an action goal, as move_base does."""
        action_goal = MoveBaseActionGoal()
        action_goal.header.stamp = rospy.Time.now()
        action_goal.goal_id = self._goal_ids.generate_ID()
        action_goal.goal.target_pose = msg
        self._simple_goal_pub.publish(action_goal)

    def _on_make_plan(self, request: GetPlanRequest) -> GetPlanResponse:
        goal = self._goal_pose(request.goal)
        if request.start.header.frame_id:
            start: Pose2D | str | None = self._goal_pose(request.start)
        else:
            start = self.robot_pose()
        if isinstance(goal, str) or isinstance(start, str) or start is None:
            reason = goal if isinstance(goal, str) else start or "robot pose unknown"
            rospy.logwarn("make_plan: %s", reason)
            return GetPlanResponse(
                plan=plan_to_path(None, None, self.config.global_frame, rospy.Time.now())
            )
        with self._lock:
            plan = self.server.make_plan(start, goal)
        return GetPlanResponse(
            plan=plan_to_path(plan, goal, self.config.global_frame, rospy.Time.now())
        )

    def _on_clear_costmaps(self, _request: EmptyRequest) -> EmptyResponse:
        with self._lock:
            self.server.clear_costmaps()
        return EmptyResponse()

    # -- control loop ----------------------------------------------------------------------

    def _publish_costmap(self, costmap: Costmap, now: rospy.Time) -> None:
        if self._costmap_pub is None:
            return
        msg = grid_to_msg(costmap.grid, self.config.global_frame, now)
        msg.data = costmap_to_occupancy_values(costmap.cost).ravel().tolist()
        self._costmap_pub.publish(msg)
        self._last_costmap_stamp = now

    def _publish_costmap_if_new(self, now: rospy.Time) -> None:
        """The planning costmap, once the other robots in it have moved; not too often."""
        server = self.server
        if server.costmap_version == self._published_costmap_version:
            return
        if self._costmap_pub is None or (now - self._last_costmap_stamp).to_sec() < COSTMAP_PERIOD:
            return
        with self._lock:
            version, costmap = server.costmap_version, server.planning_costmap
        self._published_costmap_version = version
        self._publish_costmap(costmap, now)

    def control_step(self) -> None:
        """One controller cycle: read the poses, ask the server for a command, report."""
        pose = self.robot_pose()
        others = self._others.poses() if self._others is not None else None
        now = rospy.Time.now()
        self._publish_costmap_if_new(now)
        if pose is not None:
            self._publish_footprint(pose, now)
        with self._lock:
            if others is not None:
                self.server.set_other_robots(others)
            if not self._as.is_active() or self._goal is None:
                return
            if pose is None:
                self._on_pose_missing(now)
                return
            self._pose_missing_since = None
            period = 1.0 / self.config.controller_frequency
            dt = period if self._last_step is None else (now - self._last_step).to_sec()
            if dt <= 0.0:
                # /clock has not moved since the last cycle (a loaded machine runs two
                # cycles in one tick): nothing to integrate, and the server's safety
                # check would brake a moving robot over zero-length steps for ever.
                return
            self._last_step = now
            v, w = self._velocity
            cmd_v, cmd_w = self.server.compute_velocity(pose, v, w, min(max(dt, 0.0), 5 * period))
            self._publish_plan_if_new(now)
            state = self.server.state
            if state is NavState.SUCCEEDED:
                rospy.loginfo("goal reached")
                self._finish(lambda: self._as.set_succeeded(MoveBaseResult(), "goal reached"))
            elif state is NavState.ABORTED:
                text = self.server.status_text or "navigation failed"
                rospy.logwarn("goal aborted: %s", text)
                self._finish(lambda: self._as.set_aborted(MoveBaseResult(), text))
            elif state is NavState.CANCELED:
                self._finish(lambda: self._as.set_preempted(MoveBaseResult(), "canceled"))
            else:
                twist = Twist()
                twist.linear.x, twist.angular.z = cmd_v, cmd_w
                self._cmd_pub.publish(twist)
                self._publish_feedback(pose, now)

    def _on_pose_missing(self, now: rospy.Time) -> None:
        self._cmd_pub.publish(Twist())
        if self._pose_missing_since is None:
            self._pose_missing_since = now
        elif (now - self._pose_missing_since).to_sec() > self.config.pose_timeout:
            text = (
                f"no recent transform {self.config.global_frame} -> {self.config.base_frame} "
                f"for {self.config.pose_timeout:.1f} s (is the robot node running?)"
            )
            rospy.logwarn("goal aborted: %s", text)
            self._finish(lambda: self._as.set_aborted(MoveBaseResult(), text))

    def _publish_feedback(self, pose: Pose2D, now: rospy.Time) -> None:
        if (now - self._last_feedback).to_sec() < 1.0 / self.config.feedback_rate:
            return
        self._last_feedback = now
        feedback = MoveBaseFeedback()
        feedback.base_position.header.frame_id = self.config.global_frame
        feedback.base_position.header.stamp = now
        feedback.base_position.pose = pose_from_pose2d(pose)
        self._as.publish_feedback(feedback)

    def _publish_footprint(self, pose: Pose2D, now: rospy.Time) -> None:
        """The outline at the robot's pose, global frame: what costmap_2d publishes."""
        if now >= self._last_footprint and (now - self._last_footprint).to_sec() < FOOTPRINT_PERIOD:
            return
        self._last_footprint = now
        polygon = PolygonStamped()
        polygon.header.frame_id = self.config.global_frame
        polygon.header.stamp = now
        polygon.polygon.points = [
            Point32(x=float(x), y=float(y), z=0.0) for x, y in self.server.footprint.at(pose)
        ]
        self._footprint_pub.publish(polygon)

    def _publish_plan_if_new(self, now: rospy.Time) -> None:
        if self.server.plan_version == self._published_plan_version:
            return
        self._published_plan_version = self.server.plan_version
        self._plan_pub.publish(
            plan_to_path(self.server.plan, self._goal, self.config.global_frame, now)
        )

    def spin(self) -> None:
        rate = rospy.Rate(self.config.controller_frequency)
        while not rospy.is_shutdown():
            self.control_step()
            try:
                rate.sleep()
            except rospy.ROSTimeMovedBackwardsException:
                self._last_step = None
                self._last_costmap_stamp = rospy.Time(0)
            except rospy.ROSInterruptException:
                break

    def shutdown(self) -> None:
        """Leave the robot standing: a navigation stack that dies must not keep it moving."""
        with contextlib.suppress(Exception):
            self._cmd_pub.publish(Twist())


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``rosrun navseq sim_nav_node`` (node name ``move_base``)."""
    rospy.init_node("move_base", argv=argv if argv is not None else sys.argv)
    try:
        config = NavNodeConfig.from_params()
        # Before the action server exists: a client that found the server finds these.
        for name, value in navstack_params(config).items():
            rospy.set_param(f"~{name}", value)
        grid = load_map(config.map_yaml) if config.map_yaml else wait_for_map("map")
        grid = with_filters(grid, config.filters)  # a mask that cannot be read ends here
        node = SimNavNode(config, grid)
    except NavseqError as error:
        rospy.logfatal("%s", error)
        return 2
    rospy.on_shutdown(node.shutdown)
    rospy.loginfo(
        "sim move_base ready: action %s on %s, robot frame %s, %s, inflation %g m x %g, "
        "tolerance %g m / %g rad",
        rospy.resolve_name(ACTION),
        config.map_yaml or "map from topic",
        config.base_frame,
        describe_settings(config.settings),
        config.costmap.inflation_radius,
        config.costmap.cost_scaling_factor,
        config.nav.xy_tolerance,
        config.nav.yaw_tolerance,
    )
    if config.filters:
        rospy.loginfo("costmap filters: %s", filters_summary(config.filters))
    node.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
