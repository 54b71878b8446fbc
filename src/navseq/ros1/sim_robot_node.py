"""The simulated robot as a ROS 1 node: a differential-drive base that obeys ``cmd_vel``.

This is the body half of navseq's embedded simulator (the navigation half is
:mod:`navseq.ros1.sim_nav_node`). Like Nav2's loopback simulator it has no sensors and no
physics beyond differential-drive kinematics: the ROS-free body,
:class:`navseq.sim.base.SimulatedBase`, integrates velocity commands and refuses any step
that would put its footprint on an occupied or unknown cell of the map (it stops as if
it had hit a bumper); this module speaks ROS around it.

The robot is the one ``~robot`` names: a built-in profile (``turtlebot3_burger``, the
default, ``turtlebot3_waffle``, ``turtlebot3_waffle_pi``) or a robot YAML file, as
``navseq run --robot`` takes (see :mod:`navseq.ros1.robot_param`). Its outline is what
collides and what ``footprint`` shows; its speed and acceleration limits bound what
``cmd_vel`` can make it do.

Interface (names relative to the node's namespace, so ``ns:=robot1`` gives
``/robot1/cmd_vel`` ...):

- subscribes ``cmd_vel`` (``geometry_msgs/Twist``): forward speed ``linear.x`` and turn
  rate ``angular.z``, reached within the robot's speed and acceleration limits; the
  robot stops when no command arrives for ``~cmd_vel_timeout`` seconds, like a real
  base driver;
- subscribes ``initialpose`` (``geometry_msgs/PoseWithCovarianceStamped``, RViz's
  "2D Pose Estimate"): teleports the robot there (refused inside an obstacle);
- publishes ``odom`` (``nav_msgs/Odometry``) and the TF chain
  ``map -> odom -> base_footprint`` at every step;
- publishes ``/clock`` when ``/use_sim_time`` is true, running ``~speed`` times faster
  than the wall clock (1.0 = real time, for RViz; tests use 5-10). With several robots
  exactly one node drives the clock; the others get ``~publish_clock: false`` and step
  with the ROS time it publishes;
- publishes ``footprint`` (``geometry_msgs/PolygonStamped``, base frame): the robot's
  outline, at 5 Hz for RViz;
- publishes ``map`` (``nav_msgs/OccupancyGrid``, latched) loaded from ``~map`` (a
  map_server YAML) when ``~publish_map`` is true. Without ``~map`` the node takes the
  map for its collision checks from the ``map`` topic instead (e.g. a real map_server).

In a fleet, ``~other_robots`` lists the other robots' base frames (e.g.
``[robot2/base_footprint]``): their poses come from TF in ``~global_frame`` every
step, and the body refuses to overlap them as it refuses to overlap walls (see
:mod:`navseq.ros1.fleet`). The other robots are taken to be the same model as this one
(one ``robot`` for the whole fleet in ``multi_robot.launch``).

Odometry behaves like a real robot's: the ``odom`` frame starts at the start pose and
odometry is continuous; a teleport moves the robot in the map and shifts the
``map -> odom`` transform, as a localisation jump would.
"""

from __future__ import annotations

import sys
import threading
import time
from dataclasses import dataclass

import rospy
import tf2_ros
from geometry_msgs.msg import Point32, PolygonStamped, PoseWithCovarianceStamped, Twist
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.ros1.conversions import (
    grid_from_msg,
    grid_to_msg,
    pose2d_from_pose,
    pose_from_pose2d,
    transform_stamped,
)
from navseq.ros1.fleet import OtherRobots, other_robots_param
from navseq.ros1.params import bool_param, float_param, param_error, str_param
from navseq.ros1.robot_param import describe_settings, sim_settings_param
from navseq.sim.base import SimulatedBase
from navseq.sim.occupancy import load_map
from navseq.sim.profile import SimSettings

FOOTPRINT_RATE = 5.0  # Hz of sim time: enough for RViz, cheap at high speed factors
OTHER_POSE_TOLERANCE = 1.0  # s of ROS time: an older pose of another robot is not used


@dataclass(frozen=True)
class RobotNodeConfig:
    """The node's private parameters (see the module docstring)."""

    map_yaml: str
    start: Pose2D
    speed: float
    rate: float
    cmd_vel_timeout: float
    global_frame: str
    odom_frame: str
    base_frame: str
    publish_map: bool
    publish_clock: bool
    use_sim_time: bool
    other_robots: tuple[str, ...]
    settings: SimSettings  # the robot (``~robot``): outline and limits

    @classmethod
    def from_params(cls) -> RobotNodeConfig:
        base_frame = str_param("base_frame", "base_footprint")
        config = cls(
            settings=sim_settings_param(),
            map_yaml=str_param("map", ""),
            start=Pose2D(float_param("x", 0.0), float_param("y", 0.0), float_param("yaw", 0.0)),
            speed=float_param("speed", 1.0),
            rate=float_param("rate", 20.0),
            cmd_vel_timeout=float_param("cmd_vel_timeout", 0.5),
            global_frame=str_param("global_frame", "map"),
            odom_frame=str_param("odom_frame", "odom"),
            base_frame=base_frame,
            publish_map=bool_param("publish_map", True),
            publish_clock=bool_param("publish_clock", True),
            use_sim_time=bool(rospy.get_param("/use_sim_time", False)),
            other_robots=other_robots_param(base_frame),
        )
        for name, value in (("speed", config.speed), ("rate", config.rate)):
            if not value > 0:
                raise param_error(name, f"must be a positive number, got {value}")
        return config


class SimRobotNode:
    """Runs a :class:`SimulatedBase` in (scaled) real time and speaks ROS around it."""

    def __init__(self, config: RobotNodeConfig) -> None:
        self.config = config
        self._lock = threading.Lock()
        grid = load_map(config.map_yaml) if config.map_yaml else None
        settings = config.settings
        self.base = SimulatedBase(
            config.start,
            grid,
            footprint=settings.footprint,
            limits=settings.nav_params.limits,
            cmd_vel_timeout=config.cmd_vel_timeout,
        )
        if self.base.collides(config.start):
            raise NavseqError(
                f"start pose ({config.start.x:.2f}, {config.start.y:.2f}) puts the robot on an "
                f"obstacle, unknown space or off the map {config.map_yaml}",
                source=f"params {rospy.resolve_name('~x')}, {rospy.resolve_name('~y')}",
            )
        self.dt = 1.0 / config.rate
        # Under use_sim_time exactly one node may drive /clock; the others follow it.
        self.drives_clock = config.use_sim_time and config.publish_clock
        if not self.drives_clock and config.speed != 1.0:
            rospy.logwarn(
                "~speed %.2f ignored: only the node publishing /clock sets the speed",
                config.speed,
            )
        self.speed = config.speed if self.drives_clock else 1.0

        self._odom_pub = rospy.Publisher("odom", Odometry, queue_size=10)
        self._clock_pub = (
            rospy.Publisher("/clock", Clock, queue_size=10) if self.drives_clock else None
        )
        self._tf = tf2_ros.TransformBroadcaster()
        self._footprint_pub = rospy.Publisher("footprint", PolygonStamped, queue_size=1)
        self._footprint_every = max(1, round(config.rate / FOOTPRINT_RATE))
        self._steps = 0
        self._map_pub = None
        if grid is not None and config.publish_map:
            self._map_pub = rospy.Publisher("map", OccupancyGridMsg, queue_size=1, latch=True)
            self._map_pub.publish(grid_to_msg(grid, config.global_frame, self._stamp()))
        if grid is None:
            rospy.Subscriber("map", OccupancyGridMsg, self._on_map, queue_size=1)
        rospy.Subscriber("cmd_vel", Twist, self._on_cmd_vel, queue_size=10)
        rospy.Subscriber(
            "initialpose", PoseWithCovarianceStamped, self._on_initial_pose, queue_size=10
        )
        self._others: OtherRobots | None = None
        if config.other_robots:
            tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(10.0))
            self._tf_listener = tf2_ros.TransformListener(tf_buffer)
            self._others = OtherRobots(
                tf_buffer,
                config.global_frame,
                config.other_robots,
                tolerance=OTHER_POSE_TOLERANCE,
                footprint=settings.footprint,
            )

    # -- callbacks (rospy threads) -------------------------------------------------------

    def _on_cmd_vel(self, msg: Twist) -> None:
        with self._lock:
            self.base.command(float(msg.linear.x), float(msg.angular.z))

    def _on_initial_pose(self, msg: PoseWithCovarianceStamped) -> None:
        frame = msg.header.frame_id.lstrip("/")
        if frame and frame != self.config.global_frame:
            rospy.logwarn(
                "initialpose ignored: frame %r is not the map frame %r",
                frame,
                self.config.global_frame,
            )
            return
        pose = pose2d_from_pose(msg.pose.pose)
        with self._lock:
            moved = self.base.teleport(pose)
        if moved:
            rospy.loginfo("teleported to (%.2f, %.2f, %.2f rad)", pose.x, pose.y, pose.yaw)
        else:
            rospy.logwarn(
                "initialpose (%.2f, %.2f) refused: the robot would be on an obstacle "
                "or another robot",
                pose.x,
                pose.y,
            )

    def _on_map(self, msg: OccupancyGridMsg) -> None:
        try:
            grid = grid_from_msg(msg, source=f"topic {rospy.resolve_name('map')}")
        except NavseqError as error:
            rospy.logerr("%s", error)
            return
        with self._lock:
            self.base.grid = grid

    # -- main loop ------------------------------------------------------------------------

    def _stamp(self) -> rospy.Time:
        if self.drives_clock:
            return rospy.Time.from_sec(self.base.time)
        return rospy.Time.now()

    def publish_state(self) -> None:
        """Clock, TF and odometry for the current instant."""
        config = self.config
        with self._lock:
            stamp = self._stamp()
            map_to_odom = self.base.map_to_odom
            odom_pose = self.base.odom_pose
            v, w = self.base.robot.v, self.base.robot.w
        if self._clock_pub is not None:
            self._clock_pub.publish(Clock(clock=stamp))
        self._tf.sendTransform(
            [
                transform_stamped(map_to_odom, config.global_frame, config.odom_frame, stamp),
                transform_stamped(odom_pose, config.odom_frame, config.base_frame, stamp),
            ]
        )
        odom = Odometry()
        odom.header.stamp = stamp
        odom.header.frame_id = config.odom_frame
        odom.child_frame_id = config.base_frame
        odom.pose.pose = pose_from_pose2d(odom_pose)
        odom.twist.twist.linear.x = v
        odom.twist.twist.angular.z = w
        self._odom_pub.publish(odom)
        self._steps += 1
        if self._steps % self._footprint_every == 0:
            self._publish_footprint(stamp)

    def _publish_footprint(self, stamp: rospy.Time) -> None:
        """The robot outline in its base frame, for RViz (costmap_2d publishes the same)."""
        polygon = PolygonStamped()
        polygon.header.stamp = stamp
        polygon.header.frame_id = self.config.base_frame
        polygon.polygon.points = [
            Point32(x=float(x), y=float(y), z=0.0) for x, y in self.base.footprint.polygon
        ]
        self._footprint_pub.publish(polygon)

    def step(self, dt: float | None = None) -> None:
        others = self._others.poses() if self._others is not None else None
        with self._lock:
            if others is not None:
                self.base.set_other_robots(others)
            moved = self.base.step(self.dt if dt is None else dt)
        if not moved:
            rospy.logwarn_throttle(
                1.0,
                "cmd_vel refused: the robot would hit an obstacle or another robot "
                "(bumped %d times)",
                self.base.refused_steps,
            )
        self.publish_state()

    def spin(self) -> None:
        if self.config.use_sim_time and not self.drives_clock:
            self._spin_following_clock()
        else:
            self._spin_on_wall_clock()

    def _spin_following_clock(self) -> None:
        """Step at ``~rate`` Hz of ROS time that another node's /clock drives."""
        rate = rospy.Rate(self.config.rate)
        last = rospy.Time.now()
        while not rospy.is_shutdown():
            try:
                rate.sleep()
            except rospy.ROSTimeMovedBackwardsException:
                last = rospy.Time.now()
                continue
            except rospy.ROSInterruptException:
                break
            now = rospy.Time.now()
            if now <= last:
                # The /clock owner has not ticked since our last step (Rate wakes on any
                # clock message): stepping by zero would republish TF with the same stamp,
                # which every TF listener reports as TF_REPEATED_DATA.
                continue
            self.step(min((now - last).to_sec(), 5 * self.dt))
            last = now

    def _spin_on_wall_clock(self) -> None:
        """Step every ``dt / speed`` wall seconds until shutdown.

        Timing uses the wall clock, never ``rospy.sleep``: under ``use_sim_time`` this node
        is the one that makes ROS time advance.
        """
        period = self.dt / self.speed
        self.publish_state()
        next_tick = time.monotonic()
        while not rospy.is_shutdown():
            self.step()
            next_tick += period
            delay = next_tick - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            elif delay < -0.25:
                # Too slow for the asked speed (busy CPU): simulated time just runs
                # slower instead of catching up in a burst.
                next_tick = time.monotonic()


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``rosrun navseq sim_robot_node``."""
    rospy.init_node("sim_robot", argv=argv if argv is not None else sys.argv)
    try:
        node = SimRobotNode(RobotNodeConfig.from_params())
    except NavseqError as error:
        rospy.logfatal("%s", error)
        return 2
    rospy.loginfo(
        "sim robot at (%.2f, %.2f, %.2f rad), %s, %s, speed x%.1f%s",
        node.base.pose.x,
        node.base.pose.y,
        node.base.pose.yaw,
        f"map {node.config.map_yaml}" if node.config.map_yaml else "map from topic",
        describe_settings(node.config.settings),
        node.speed,
        f", other robots {', '.join(node.config.other_robots)}" if node.config.other_robots else "",
    )
    node.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
