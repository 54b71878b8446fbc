"""navseq's simulator as one ROS 2 node that serves Nav2's interfaces.

So that Nav2 users can try navseq — and any Nav2 client — without Gazebo or Nav2, one
process holds a simulated robot (:class:`navseq.sim.world.SimWorld`: the same body and
:class:`~navseq.sim.navserver.NavigationServer` as the ROS 1 sim nodes and the in-process
simulator) and speaks Nav2's ROS 2 interface around it. The rules of Nav2's navigators
(preemption, pass-through, missed waypoints) live in :mod:`navseq.ros2.standin`; this
module only translates.

Interface (names relative to the namespace ``--ns``; a namespaced robot's transforms
on ``/NS/tf`` with plain frame names, Nav2's multi-robot convention, or with
``--tf-convention ros1`` on ``/tf`` with frames prefixed ``NS/``):

- actions ``navigate_to_pose``, ``navigate_through_poses`` (``nav2_msgs/action/...``)
  with Nav2's feedback (current pose, navigation time, time remaining, recoveries,
  distance remaining, poses remaining) and results SUCCEEDED / ABORTED (with Nav2's
  planner or controller ``error_code`` and ``error_msg``) / CANCELED; a new goal
  preempts the running one, which ends ABORTED, as in Nav2;
- ``follow_waypoints`` (result ``missed_waypoints``; parameter ``stop_on_failure``,
  default true as in Nav2);
- the planner's ``compute_path_to_pose`` and ``compute_path_through_poses``, the
  smoother's ``smooth_path`` and the controller's ``follow_path``
  (:mod:`navseq.ros2.path_actions`);
- both costmaps' topics (``global_costmap/costmap``, ``costmap_raw``,
  ``published_footprint``, the local ones) and ``get_costmap`` services
  (:mod:`navseq.ros2.costmap_topics`), their region clears and ``get_cost``, and the
  planner's ``is_path_valid`` (:mod:`navseq.ros2.costmap_services`);
- bt_navigator's ``behavior_tree_log`` and its trees' ``controller_selector`` and
  ``planner_selector`` (:mod:`navseq.ros2.bt_topics`);
- the route server's ``compute_route`` and ``compute_and_track_route`` on the graph of
  ``--route-graph`` (:mod:`navseq.ros2.route_server`);
- opennav_docking's ``dock_robot`` / ``undock_robot`` on the docks of ``--docks``
  (:mod:`navseq.ros2.docking`, :mod:`navseq.ros2.docking_actions`);
- the behaviour server's ``spin``, ``backup``, ``drive_on_heading``, ``wait`` and
  ``assisted_teleop`` (with ``cmd_vel_teleop`` and ``preempt_teleop``), acting
  on the simulated robot with Nav2's collision check ahead, time allowance and error
  codes (:mod:`navseq.sim.behaviors`, :mod:`navseq.ros2.behavior_actions`); while one
  runs, a navigation goal's controller waits;
- topics ``odom`` (``nav_msgs/Odometry``, drifting with ``--odom-drift``), ``tf``
  (``map -> odom`` the localisation's estimate, ``odom -> base_footprint``),
  ``tf_static`` (``base_footprint -> base_link -> base_scan``), ``plan``
  and the controller's copy of it, ``received_global_plan`` (``nav_msgs/Path``),
  ``goal_pose`` (RViz's "Goal Pose": a ``navigate_to_pose`` goal),
  ``/clock`` when ``--speed`` is not 1 (subscribed instead with ``--follow-clock``);
- Nav2's world around the robot: ``map_server`` (``map``, ``map_server/map``,
  ``map_server/load_map``: :mod:`navseq.ros2.map_server`), ``amcl`` (``initialpose``
  sets the estimate, ``amcl_pose``, ``particle_cloud``:
  :mod:`navseq.ros2.localization_topics`), the laser (``scan``:
  :mod:`navseq.ros2.scan_topic`), the velocity chain ``cmd_vel_nav`` ->
  ``cmd_vel_smoothed`` -> ``cmd_vel`` with ``speed_limit``, and teleop on ``cmd_vel``
  while no goal runs (:mod:`navseq.ros2.velocity_topics`);
- Nav2's costmap filters given by ``--keepout``, ``--speed-mask`` or ``--filters``: a
  keepout zone is lethal in both costmaps (never planned through; a goal deeper in it
  than the planner's tolerance aborts), a speed zone limits the controller; the masks and
  their filter info are published by lifecycle nodes of Nav2's names under their own
  lifecycle managers, the speed filter's ``speed_limit`` by this node
  (:mod:`navseq.ros2.filter_topics`);
- services ``global_costmap/clear_entirely_global_costmap``,
  ``local_costmap/clear_entirely_local_costmap`` (``nav2_msgs/srv/ClearEntireCostmap``);
  every clear-costmap call is logged (``global_costmap: cleared``), so a client's
  clearing can be checked against the goals that follow;
- the robot's parameters where Nav2 keeps them, on nodes of Nav2's names
  (``planner_server``: ``GridBased.tolerance``;
  ``controller_server``: ``general_goal_checker.xy_goal_tolerance`` and
  ``yaw_goal_tolerance``, ``FollowPath.desired_linear_vel`` and
  ``rotate_to_heading_angular_vel``; ``global_costmap/global_costmap`` and
  ``local_costmap/local_costmap``: ``footprint``, ``inflation_layer.inflation_radius``
  and ``cost_scaling_factor``), so that a client reading the robot from Nav2 finds the
  simulated one (:func:`nav2_server_parameters`, :func:`nav2_costmap_nodes`);
- Nav2's lifecycle: a lifecycle node per Nav2 server (``bt_navigator``, ``amcl``,
  ``planner_server`` ...) and both lifecycle managers (``manage_nodes``, ``is_active``),
  brought up at start (:mod:`navseq.ros2.lifecycle`). An action whose server is not
  active rejects new goals, as Nav2's action servers do between configure and activate
  ("Action server is inactive. Rejecting the goal."); goals already running go on.

Several robots that see each other: with ``--other-robots robot2`` the node also listens
to ``/robot2/tf`` (or, in ROS 1's convention, to ``/tf`` for ``robot2/``-prefixed frames)
for the other robots' ``map -> odom -> base_footprint``
(:class:`navseq.sim.fleet.SeenRobots`) and hands their poses to the world every step,
so their footprints are obstacles for the planner and the controller and the body
refuses to drive into them — as the ROS 1 sim nodes do with ``~other_robots``. A robot
not heard from for ``OTHER_POSE_TOLERANCE`` wall seconds is left out, with a warning.
A fleet faster than wall-clock time shares one simulated time: one node publishes
``/clock`` (``--speed S``), the others step with it (``--follow-clock``), as robot2
follows robot1's clock in ROS 1's ``multi_robot.launch``.

Goal poses may be given in the map, odom or base frame (the node knows those
transforms); a ``navigate_*`` goal in another frame ends ABORTED with error_code 0 and
an empty error_msg, the frame named in the node's log, as Nav2's bt_navigator does (this
stand-in has no TF listener). A goal in an obstacle or unknown space is planned to the
nearest free cell within the planner's tolerance (``planner_server``'s
``GridBased.tolerance``, 0.5 m as nav2_bringup's) and SUCCEEDS there, as NavFn plans.

For tests, ``--replan-period S`` (simulated seconds, default 0 = off) reproduces Nav2's
re-plan race on preemption: a ``navigate_to_pose`` goal that preempts another keeps the
old path until the next re-plan tick, and ends SUCCEEDED at the old goal if the robot
gets there first (see :mod:`navseq.ros2.standin`); each such goal is logged as a
warning.

Run it with ``python -m navseq.ros2.sim_node --map MAP`` or ``navseq sim --ros2``;
SIGINT / SIGTERM end every goal (ABORTED), stop the robot and exit 0.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from types import FrameType
from typing import Any

import rclpy
from geometry_msgs.msg import PoseStamped, TransformStamped
from nav2_msgs.action import (
    FollowWaypoints,
    NavigateThroughPoses,
    NavigateToPose,
)
from nav2_msgs.srv import ClearEntireCostmap
from nav_msgs.msg import Odometry, Path
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from navseq.commands.sim_options import add_arguments, config_from_args
from navseq.errors import NavseqError, error_text
from navseq.geometry import Pose2D, compose, pose2d_from_transform
from navseq.mission.costmap_filters import filters_summary
from navseq.mission.robot import RobotProfile
from navseq.ros2.behavior_actions import BehaviorActions
from navseq.ros2.bt_topics import BtTopics
from navseq.ros2.collision_monitor import CollisionMonitorTopics
from navseq.ros2.costmap_layers import CostmapLayers
from navseq.ros2.costmap_nodes import nav2_costmap_nodes
from navseq.ros2.costmap_services import CostmapServices
from navseq.ros2.costmap_topics import CostmapTopics
from navseq.ros2.docking_actions import DockingActions
from navseq.ros2.filter_topics import (
    FilterTopics,
    filter_lifecycle_groups,
    filter_server_parameters,
)
from navseq.ros2.gps_actions import GpsWaypointActions
from navseq.ros2.lifecycle import Nav2Lifecycle
from navseq.ros2.localization_topics import LocalizationTopics
from navseq.ros2.map_server import MapServer
from navseq.ros2.messages import (
    duration_msg,
    finish_goal,
    path_msg,
    pose2d_of,
    pose_msg,
    pose_stamped,
    time_msg,
    transform_stamped,
)
from navseq.ros2.path_actions import PathActions
from navseq.ros2.route_server import RouteServer
from navseq.ros2.scan_topic import ScanTopic, base_scan_transform
from navseq.ros2.session import spin_until_shutdown
from navseq.ros2.standin import (
    NAV2_PLANNER_TOLERANCE,
    Ending,
    Nav2StandIn,
    Navigator,
    NavTask,
    Outcome,
    WaypointRun,
)
from navseq.ros2.velocity_topics import VelocityTopics
from navseq.ros2.waypoint_goals import see_waypoints_through
from navseq.sim.filters import with_filters
from navseq.sim.fleet import WARN_PERIOD, SeenRobots, missing_warning
from navseq.sim.occupancy import load_map
from navseq.sim.options import SimConfig
from navseq.sim.profile import SimSettings
from navseq.sim.velocity_chain import NAV2_BRINGUP_SMOOTHER, SmootherLimits
from navseq.sim.world import SimWorld, default_start
from navseq.text import printable

NODE_NAME = "navseq_sim"
MAP_FRAME = "map"
FEEDBACK_PERIOD = 0.1  # s of wall time between two feedback messages of a goal
BASE_LINK_Z = 0.010  # m: a TurtleBot3's base_link above base_footprint
# Wall seconds without another robot's transforms before it is left out. Its node
# publishes /tf every step (20 Hz); a second covers a busy CPU, not a dead node.
OTHER_POSE_TOLERANCE = 1.0
# Simulated seconds a clock follower may lag before it skips ahead instead of catching up
# in a burst of steps (the clock's node was busy, or restarted and went back in time).
CLOCK_SKIP = 1.0
# The Nav2 servers whose lifecycle state Nav2 clients (nav2_simple_commander, ...) ask.
TRANSIENT_LOCAL = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


class SimNode:
    """The ROS 2 face of a :class:`Nav2StandIn`; see the module docstring.

    Concurrency: the executor's threads run the callbacks (one per running goal waits in
    its execute callback) and one thread of our own steps the simulation; everything
    that touches the stand-in holds ``self._lock``.
    """

    def __init__(self, node: Node, config: SimConfig, lifecycle: Nav2Lifecycle) -> None:
        self.node = node
        self.config = config
        self.lifecycle = lifecycle
        grid = with_filters(load_map(config.map_yaml), config.filters)
        settings = SimSettings.of(config.robot)
        start = (
            config.start if config.start is not None else default_start(grid, settings.footprint)
        )
        world = SimWorld(
            grid,
            start,
            dt=1.0 / config.rate,
            costmap_params=settings.costmap_params,
            nav_params=settings.nav_params,
            footprint=settings.footprint,
        )
        self.standin = Nav2StandIn(
            world, replan_period=config.replan_period, odom_drift=config.odom_drift
        )
        self.standin.filters = config.filters
        self.others = (
            SeenRobots(config.other_robots, OTHER_POSE_TOLERANCE, settings.footprint, MAP_FRAME)
            if config.other_robots
            else None
        )
        self._last_missing_warning = -float("inf")
        self._other_poses: list[Any] = []  # the others as last seen (for the scan)
        # --follow-clock: the latest /clock heard, and simulated time minus our own time
        # (the clock's node started earlier; fixed at the first message heard).
        self._clock_target = 0.0
        self._clock_heard = threading.Event()
        self._clock_offset = 0.0
        self._clock_synced = False
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        prefix = config.frame_prefix
        self.odom_frame = f"{prefix}odom"
        self.base_frame = f"{prefix}base_footprint"
        self.base_link = f"{prefix}base_link"
        self.base_scan = f"{prefix}base_scan"
        self._plan_version = -1
        self._topic_goal: NavTask | None = None
        self.log = node.get_logger()
        node.declare_parameter("stop_on_failure", True)

        group = ReentrantCallbackGroup()
        self._odom_pub = node.create_publisher(Odometry, "odom", 10)
        # Nav2's multi-robot convention: /NS/tf with plain frames; ROS 1's: /tf, NS/ frames.
        tf_topic, tf_static_topic = config.tf_topics
        self._tf_pub = node.create_publisher(TFMessage, tf_topic, 100)
        self._tf_static_pub = node.create_publisher(TFMessage, tf_static_topic, TRANSIENT_LOCAL)
        self._plan_pub = node.create_publisher(Path, "plan", 1)
        # The controller server's copy of the plan it takes (Nav2's controller plugins
        # publish it in setPlan, depth 1): here each new plan the controller follows.
        self._received_plan_pub = node.create_publisher(Path, "received_global_plan", 1)
        self._clock_pub = (
            node.create_publisher(Clock, "/clock", 10) if config.publishes_clock else None
        )
        if config.follow_clock:
            node.create_subscription(Clock, "/clock", self._on_clock, 10, callback_group=group)
        node.create_subscription(
            PoseStamped, "goal_pose", self._on_goal_pose, 10, callback_group=group
        )
        self._subscribe_to_others(group)
        for service in (
            "global_costmap/clear_entirely_global_costmap",
            "local_costmap/clear_entirely_local_costmap",
        ):
            node.create_service(
                ClearEntireCostmap,
                service,
                self._clear_costmap_callback(service.partition("/")[0]),
                callback_group=group,
            )
        self._servers = lifecycle.action_servers(
            node,
            group,
            self.log.info,
            [
                *(
                    (action, navigator.value, self._navigation_executor(action, navigator))
                    for action, navigator in (
                        (NavigateToPose, Navigator.TO_POSE),
                        (NavigateThroughPoses, Navigator.THROUGH_POSES),
                    )
                ),
                (FollowWaypoints, "follow_waypoints", self._execute_waypoints),
            ],
        )
        self._behaviors = BehaviorActions(node, self.standin, self._lock, group, lifecycle)
        self._costmaps = CostmapTopics(
            node,
            self.standin,
            self._lock,
            group,
            stamp=self._stamp,
            map_frame=MAP_FRAME,
            odom_frame=self.odom_frame,
        )
        self._paths = PathActions(
            node,
            self.standin,
            self._lock,
            group,
            in_map=self._in_map,
            stamp=self._stamp,
            frame=MAP_FRAME,
            lifecycle=lifecycle,
        )
        self._costmap_services = CostmapServices(
            node, self.standin, self._lock, group, in_map=self._in_map
        )
        self._docking = DockingActions(
            node,
            self.standin,
            self._lock,
            group,
            lifecycle,
            docks=config.docks,
            in_map=self._in_map,
            stamp=self._stamp,
            frame=MAP_FRAME,
            base_frame=self.base_link,
            odom_frame=self.odom_frame,
        )
        self._gps = GpsWaypointActions(
            node, self.standin, self._lock, group, datum=config.datum, lifecycle=lifecycle,
            stamp=self._stamp, frame=MAP_FRAME,
        )  # fmt: skip
        self._bt = BtTopics(node, self.standin, self._lock, group, stamp=self._stamp)
        self._routes = RouteServer(
            node, self.standin, self._lock, group, lifecycle, graph=config.route_graph,
            in_map=self._in_map, stamp=self._stamp, frame=MAP_FRAME,
        )  # fmt: skip
        # -- Nav2's world: map_server, amcl, the laser, the velocity chain (issue 20) --
        servers = lifecycle.servers
        self._map_server = MapServer(
            servers["map_server"],
            self.standin,
            self._lock,
            group,
            active=lambda: lifecycle.is_active("map_server"),
            stamp=self._stamp,
            frame=MAP_FRAME,
        )
        self._localization = LocalizationTopics(
            servers["amcl"],
            self.standin,
            self._lock,
            group,
            stamp=self._stamp,
            frame=MAP_FRAME,
            teleport=config.initial_pose == "teleport",
        )
        self._scan = ScanTopic(
            node,
            self.standin,
            self._lock,
            stamp=self._stamp,
            frame=self.base_scan,
            others=lambda: self._other_poses,
        )
        self._velocities = VelocityTopics(node, self.standin, self._lock, group)
        self._filters = FilterTopics(
            node, self.standin, self._lock, group, lifecycle, filters=config.filters,
            stamp=self._stamp, frame=MAP_FRAME,
        )  # fmt: skip
        # -- costmap layers and the collision monitor (issue 20) --
        self._layers = CostmapLayers(
            node, self.standin, self._lock, group, stamp=self._stamp, map_frame=MAP_FRAME,
            odom_frame=self.odom_frame, sensor_height=BASE_LINK_Z + self._scan.spec.height,
        )  # fmt: skip
        self._monitor = CollisionMonitorTopics(
            servers["collision_monitor"], self.standin, self._lock, group,
            active=lambda: lifecycle.is_active("collision_monitor"),
            own_smoothed=lambda: self._velocities.last_smoothed, base_frame=self.base_frame,
        )  # fmt: skip
        stamp = self._stamp()
        # robot_state_publisher's part of a TurtleBot3's tree: the body above the floor,
        # the laser on it.
        base_link = TransformStamped()
        base_link.header.frame_id = self.base_frame
        base_link.header.stamp = stamp
        base_link.child_frame_id = self.base_link
        base_link.transform.translation.z = BASE_LINK_Z
        base_link.transform.rotation.w = 1.0
        scan = base_scan_transform(self.base_link, self.base_scan, stamp, self._scan.spec)
        self._tf_static_pub.publish(TFMessage(transforms=[base_link, scan]))
        self._publish_state()

    # -- life cycle ------------------------------------------------------------------

    def start(self) -> None:
        target = self._follow_clock if self.config.follow_clock else self._simulate
        self._thread = threading.Thread(target=target, name="navseq-sim", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """End every goal (ABORTED) and leave the robot standing."""
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        with self._lock:
            self.standin.abort_all("the simulator is shutting down")
        with contextlib.suppress(Exception):
            self._velocities.stop()

    # -- simulation thread -----------------------------------------------------------

    def _simulate(self) -> None:
        """Step every ``dt / speed`` wall seconds; a busy CPU slows simulated time down
        instead of catching up in a burst."""
        period = self.standin.world.dt / self.config.speed
        next_tick = time.monotonic()
        while not self._stopping.is_set():
            with self._lock:
                self._see_others()
                self.standin.step()
            self._publish_state()
            next_tick += period
            delay = next_tick - time.monotonic()
            if delay > 0:
                self._stopping.wait(delay)
            elif delay < -0.25:
                next_tick = time.monotonic()

    def _follow_clock(self) -> None:
        """Step whenever another node's /clock has gone a step further than ours."""
        dt = self.standin.world.dt
        while not self._stopping.is_set():
            if not self._clock_heard.wait(0.1):
                continue
            self._clock_heard.clear()
            stepped = False
            with self._lock:
                target = self._clock_target
                now = self.standin.time + self._clock_offset
                if not self._clock_synced or abs(target - now) > CLOCK_SKIP:
                    self._clock_offset = target - self.standin.time
                    self._clock_synced = True
                    now = target
                while now + dt / 2 <= target:
                    self._see_others()
                    self.standin.step()
                    now = self.standin.time + self._clock_offset
                    stepped = True
            if stepped:
                self._publish_state()

    def _on_clock(self, message: Clock) -> None:
        with self._lock:
            self._clock_target = message.clock.sec + message.clock.nanosec * 1e-9
        self._clock_heard.set()

    def _see_others(self) -> None:
        """Tell the world where the other robots are now (call with the lock)."""
        if self.others is None:
            return
        now = time.monotonic()
        found, missing = self.others.poses(now)
        self._other_poses = found
        self.standin.world.set_other_robots(found)
        if missing and now - self._last_missing_warning >= WARN_PERIOD:
            self._last_missing_warning = now
            self.log.warning(missing_warning(missing, MAP_FRAME))

    def _stamp(self) -> Any:
        if self.config.sim_time:
            return time_msg(self.standin.time + self._clock_offset)
        return self.node.get_clock().now().to_msg()

    def _publish_state(self) -> None:
        with self._lock:
            standin = self.standin
            world = standin.world
            body = world.body
            localization = standin.localization
            map_to_odom, odom_pose = localization.estimate, localization.odom_pose
            v, w = body.robot.v, body.robot.w
            server = world.server
            new_plan = server.plan_version != self._plan_version
            plan, goal = server.plan, server.goal
            self._plan_version = server.plan_version
            topic_goal = self._topic_goal
            topic_ending = topic_goal.ending if topic_goal is not None else None
            if topic_ending is not None:
                self._topic_goal = None
        stamp = self._stamp()
        if self._clock_pub is not None:
            self._clock_pub.publish(Clock(clock=stamp))
        self._tf_pub.publish(
            TFMessage(
                transforms=[
                    transform_stamped(map_to_odom, MAP_FRAME, self.odom_frame, stamp),
                    transform_stamped(odom_pose, self.odom_frame, self.base_frame, stamp),
                ]
            )
        )
        odom = Odometry()
        odom.header.stamp = stamp
        odom.header.frame_id = self.odom_frame
        odom.child_frame_id = self.base_frame
        odom.pose.pose = pose_msg(odom_pose)
        odom.twist.twist.linear.x = float(v)
        odom.twist.twist.angular.z = float(w)
        self._odom_pub.publish(odom)
        if new_plan and plan is not None:
            plan_message = path_msg(plan, goal, MAP_FRAME, stamp)
            self._plan_pub.publish(plan_message)
            self._received_plan_pub.publish(plan_message)
        self._velocities.publish()
        self._monitor.publish()
        self._localization.publish()
        self._scan.publish_if_due()
        if topic_ending is not None:
            self.log.info(
                f"goal_pose goal ended {topic_ending.outcome.value} {topic_ending.error_msg}"
            )

    # -- goal poses ------------------------------------------------------------------

    def _in_map(self, pose: PoseStamped) -> Pose2D | str:
        """A goal pose in the map frame, or why it cannot be used (call with the lock)."""
        planar = pose2d_of(pose.pose)
        if isinstance(planar, str):
            return planar
        frame = pose.header.frame_id.lstrip("/")
        localization = self.standin.localization  # the transforms the node publishes
        if frame in ("", MAP_FRAME):
            return planar
        if frame == self.odom_frame:
            return compose(localization.estimate, planar)
        if frame in (self.base_frame, self.base_link):
            return compose(localization.believed_pose, planar)
        return (
            f"frame {frame!r} is not {MAP_FRAME!r}, {self.odom_frame!r} or "
            f"{self.base_frame!r} (the simulator knows no other transform)"
        )

    def _poses_in_map(self, poses: Sequence[PoseStamped]) -> list[Pose2D] | str:
        found: list[Pose2D] = []
        for index, pose in enumerate(poses):
            planar = self._in_map(pose)
            if isinstance(planar, str):
                return f"pose {index}: {planar}" if len(poses) > 1 else planar
            found.append(planar)
        return found

    # -- navigate_to_pose / navigate_through_poses -------------------------------------

    def _navigation_executor(self, action: Any, navigator: Navigator) -> Callable[[Any], Any]:
        return lambda handle: self._execute_navigation(handle, action, navigator)

    def _execute_navigation(self, handle: Any, action: Any, navigator: Navigator) -> Any:
        request = handle.request
        raw = [request.pose] if navigator is Navigator.TO_POSE else list(request.poses)
        with self._lock:
            poses = self._poses_in_map(raw)
            if isinstance(poses, str):
                # Nav2's bt_navigator logs a goal it cannot transform and ends it ABORTED
                # with neither code nor message (measured on Nav2 Jazzy).
                task = None
                ending = Ending(Outcome.ABORTED)
                self.log.warning(f"{navigator.value}: goal ABORTED: {poses}")
            else:
                task = self.standin.navigate(navigator, poses)
        if task is not None:
            self.log.info(
                f"{navigator.value}: goal to ({task.poses[-1].x:.2f}, {task.poses[-1].y:.2f})"
                + (f" through {len(task.poses) - 1} poses" if len(task.poses) > 1 else "")
            )
            ending = self._follow_task(handle, task, action, navigator)
        result = action.Result()
        result.error_code = int(ending.error_code)
        result.error_msg = ending.error_msg
        finish_goal(handle, ending.outcome.value)
        if ending.outcome is not Outcome.SUCCEEDED:
            self.log.info(f"{navigator.value}: {ending.outcome.value} {ending.error_msg}")
        elif task is not None and task.succeeded_on_old_path:
            self._warn_old_path_success(navigator, task)
        return result

    def _warn_old_path_success(self, navigator: Navigator, task: NavTask) -> None:
        """Say when --replan-period made a goal succeed at the goal it preempted."""
        with self._lock:
            robot = self.standin.world.robot.pose
        goal = task.poses[-1]
        self.log.warning(
            f"{navigator.value}: goal ({goal.x:.2f}, {goal.y:.2f}) SUCCEEDED on the preempted "
            f"goal's path before the re-plan (--replan-period), robot "
            f"{robot.distance_to(goal):.2f} m away"
        )

    def _follow_task(self, handle: Any, task: NavTask, action: Any, navigator: Navigator) -> Ending:
        """Feedback until ``task`` ends; a cancel request cancels it."""
        while not task.done.wait(FEEDBACK_PERIOD):
            if handle.is_cancel_requested:
                with self._lock:
                    self.standin.cancel(task)
                break
            with self._lock:
                numbers = self.standin.feedback(task)
            feedback = action.Feedback()
            feedback.current_pose = pose_stamped(numbers.pose, MAP_FRAME, self._stamp())
            feedback.navigation_time = duration_msg(numbers.navigation_time)
            feedback.estimated_time_remaining = duration_msg(numbers.estimated_time_remaining)
            feedback.number_of_recoveries = int(numbers.number_of_recoveries)
            feedback.distance_remaining = float(numbers.distance_remaining)
            if navigator is Navigator.THROUGH_POSES:
                feedback.number_of_poses_remaining = int(numbers.poses_remaining)
            handle.publish_feedback(feedback)
        assert task.ending is not None
        return task.ending

    # -- follow_waypoints --------------------------------------------------------------

    def _execute_waypoints(self, handle: Any) -> Any:
        request = handle.request
        stop_on_failure = bool(self.node.get_parameter("stop_on_failure").value)
        run: WaypointRun | None = None
        refused: Ending | None = None
        with self._lock:
            poses = self._poses_in_map(list(request.poses))
            if isinstance(poses, str):
                refused = Ending(Outcome.ABORTED, 601, poses)  # TASK_EXECUTOR_FAILED
            else:
                run = self.standin.follow(
                    poses,
                    loops=int(request.number_of_loops),
                    start_index=int(request.goal_index),
                    stop_on_failure=stop_on_failure,
                )
        if run is not None:
            self.log.info(f"follow_waypoints: {len(run.poses)} waypoints")
        return see_waypoints_through(
            handle,
            run,
            refused,
            standin=self.standin,
            lock=self._lock,
            action=FollowWaypoints,
            frame=MAP_FRAME,
            stamp=self._stamp,
        )

    # -- topics and services -------------------------------------------------------------

    def _on_goal_pose(self, message: PoseStamped) -> None:
        """RViz's "Goal Pose": a navigate_to_pose goal, as bt_navigator makes of it."""
        with self._lock:
            pose = self._in_map(message)
            if isinstance(pose, str):
                self.log.warning(f"goal_pose ignored: {pose}")
                return
            self._topic_goal = self.standin.navigate(Navigator.TO_POSE, [pose])
        self.log.info(f"goal_pose: navigating to ({pose.x:.2f}, {pose.y:.2f})")

    def _subscribe_to_others(self, group: Any) -> None:
        """Hear the other robots' transforms: each one's ``/NS/tf`` under Nav2's
        convention, the global ``/tf`` under ROS 1's."""
        if self.others is None:
            return
        if self.config.tf_convention == "ros1":
            self.node.create_subscription(TFMessage, "/tf", self._on_tf, 100, callback_group=group)
            return
        for namespace in self.config.other_robots:
            self.node.create_subscription(
                TFMessage,
                f"/{namespace}/tf",
                lambda message, ns=namespace: self._on_tf(message, ns),
                100,
                callback_group=group,
            )

    def _on_tf(self, message: TFMessage, namespace: str | None = None) -> None:
        """The other robots' transforms (every other one, ours included, is ignored);
        ``namespace``: heard on that robot's own tf topic, with plain frame names."""
        assert self.others is not None
        now = time.monotonic()
        with self._lock:
            for transform in message.transforms:
                parent, child = transform.header.frame_id, transform.child_frame_id
                pose = pose2d_from_transform(transform)
                if namespace is None:
                    self.others.heard(parent, child, pose, now)
                else:
                    self.others.heard_from(namespace, parent, child, pose, now)

    def _clear_costmap_callback(self, costmap: str) -> Any:
        def clear(_request: Any, response: Any) -> Any:
            with self._lock:
                self.standin.world.server.clear_costmaps()
            self.log.info(f"{costmap}: cleared")
            return response

        return clear


def run(config: SimConfig, ros_args: Sequence[str] | None = None) -> int:
    """Serve until SIGINT / SIGTERM; 0 then, 2 when the simulator cannot start."""
    rclpy.init(
        args=list(ros_args) if ros_args else None, signal_handler_options=SignalHandlerOptions.NO
    )
    stop = threading.Event()
    previous: dict[int, Any] = {}

    def request_stop(signum: int, _frame: FrameType | None) -> None:
        stop.set()

    for signum in (signal.SIGINT, signal.SIGTERM):
        previous[signum] = signal.signal(signum, request_stop)
    sim: SimNode | None = None
    node: Node | None = None
    helpers: list[Node] = []
    spinner: threading.Thread | None = None
    executor = MultiThreadedExecutor(num_threads=8)
    try:
        overrides = [Parameter("use_sim_time", value=True)] if config.sim_time else []
        node = Node(NODE_NAME, namespace=config.namespace or None, parameter_overrides=overrides)
        lifecycle = Nav2Lifecycle(
            config.namespace,
            {
                **nav2_server_parameters(config.robot),
                **filter_server_parameters(config.filters, config.namespace),
            },
            groups=filter_lifecycle_groups(config.filters),
        )
        helpers = [
            *lifecycle.nodes,
            *nav2_costmap_nodes(config.robot, config.namespace, lifecycle),
        ]
        try:
            sim = SimNode(node, config, lifecycle)
        except NavseqError as error:
            print(f"navseq sim: {error_text(error)}", file=sys.stderr)
            return 2
        executor.add_node(node)
        for helper in helpers:
            executor.add_node(helper)
        lifecycle.start()
        spinner = threading.Thread(
            target=spin_until_shutdown, args=(executor, stop.is_set), name="navseq-ros2"
        )
        spinner.start()
        sim.start()
        pose = sim.standin.world.robot.pose
        namespace = f"/{config.namespace}" if config.namespace else ""
        print(
            f"navseq sim: ready: {namespace}/navigate_to_pose on "
            f"{printable(str(config.map_yaml))}, robot at "
            f"({pose.x:.2f}, {pose.y:.2f}), "
            + ("following /clock" if config.follow_clock else f"speed x{config.speed:g}")
            + (" (/clock published: use_sim_time:=true)" if config.publishes_clock else "")
            + (f", other robots {', '.join(config.other_robots)}" if config.other_robots else "")
            + (f", docks {', '.join(d.name for d in config.docks)}" if config.docks else "")
            + (f", {filters_summary(config.filters)}" if config.filters else "")
            + (
                f", route graph of {len(config.route_graph.nodes)} nodes"
                if config.route_graph is not None
                else ""
            )
            + (
                f", re-plan period {config.replan_period:g} s on preemption"
                if config.replan_period > 0
                else ""
            ),
            flush=True,
        )
        while not stop.wait(0.2):
            pass
        return 0
    finally:
        stop.set()  # from here on the spinner's errors are the shutdown's own
        if sim is not None:
            sim.stop()
        executor.shutdown(timeout_sec=5.0)
        if spinner is not None:
            spinner.join(timeout=5.0)
        for helper in helpers:
            helper.destroy_node()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
        for number, handler in previous.items():
            signal.signal(number, handler)


def nav2_server_parameters(robot: RobotProfile) -> dict[str, list[Parameter]]:
    """The robot's parameters where Nav2's servers keep them (``controller_server``'s goal
    checker and speeds, ``planner_server``'s tolerance; see :mod:`navseq.ros2.nav2_params`),
    so a client that reads the robot from Nav2 finds the simulated one. rclpy serves
    every node's parameters by itself."""
    tolerance = robot.goal_tolerance
    return {
        "controller_server": [
            Parameter("goal_checker_plugins", value=["general_goal_checker"]),
            Parameter("general_goal_checker.xy_goal_tolerance", value=tolerance.xy_m),
            Parameter("general_goal_checker.yaw_goal_tolerance", value=tolerance.yaw_rad),
            Parameter("controller_plugins", value=["FollowPath"]),
            Parameter("FollowPath.desired_linear_vel", value=robot.max_linear_speed),
            Parameter("FollowPath.rotate_to_heading_angular_vel", value=robot.max_angular_speed),
        ],
        "planner_server": [
            Parameter("planner_plugins", value=["GridBased"]),
            Parameter("GridBased.tolerance", value=NAV2_PLANNER_TOLERANCE),
        ],
        "velocity_smoother": velocity_smoother_parameters(NAV2_BRINGUP_SMOOTHER),
    }


def velocity_smoother_parameters(limits: SmootherLimits) -> list[Parameter]:
    """The limits the stand-in smooths with, under nav2_bringup's parameter names."""
    return [
        Parameter("smoothing_frequency", value=20.0),
        Parameter("feedback", value="OPEN_LOOP"),
        Parameter("max_velocity", value=[limits.max_v, 0.0, limits.max_w]),
        Parameter("min_velocity", value=[limits.min_v, 0.0, limits.min_w]),
        Parameter("max_accel", value=[limits.accel_v, 0.0, limits.accel_w]),
        Parameter("max_decel", value=[-limits.decel_v, 0.0, -limits.decel_w]),
        Parameter("velocity_timeout", value=limits.timeout),
    ]


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m navseq.ros2.sim_node [--map MAP] ... [--ros-args ...]``."""
    from rclpy.utilities import remove_ros_args

    from navseq.cli import _attach_negative_values  # --start -2,0,0 as argparse wants it

    everything = list(sys.argv if argv is None else ["navseq_sim", *argv])
    parser = argparse.ArgumentParser(
        prog="python -m navseq.ros2.sim_node",
        description="navseq's simulator serving Nav2's interfaces (ROS 2)",
    )
    add_arguments(parser)
    args = parser.parse_args(_attach_negative_values(remove_ros_args(everything)[1:]))
    try:
        config = config_from_args(args)
    except NavseqError as error:
        print(f"navseq sim: {error_text(error)}", file=sys.stderr)
        return 2
    return run(config, everything)


if __name__ == "__main__":
    sys.exit(main())
