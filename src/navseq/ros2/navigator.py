"""The ``nav2`` navigator: goals to Nav2's ``navigate_to_pose`` action over rclpy.

One ``nav2_msgs/action/NavigateToPose`` goal per waypoint; everything else (timeouts,
stall, retries, skip/stop, dwell, loops, pass-through, journal, resume) is the
executor's. How it maps Nav2 onto :class:`~navseq.navigators.base.Navigator`:

- Terminal statuses: SUCCEEDED -> succeeded; ABORTED and CANCELED -> failed, with
  Nav2's status name and its ``error_msg`` / ``error_code`` as the text (a goal another
  client preempted ends ABORTED in Nav2: that is a failed attempt too, and the policy
  decides); a rejected goal -> failed ``REJECTED`` (Nav2 rejects while bt_navigator is
  not active: its action server exists from configure on, so it is found, but takes
  goals only once activated; :func:`navseq.roscore.navigator.rejected`); a result
  ``UNKNOWN`` (a restarted server that never heard of the goal) -> lost.
- Pass-through: a new goal simply replaces the tracked one; Nav2 preempts its running
  goal with it, so the robot keeps rolling. The replaced goal's late result (ABORTED,
  "preempted") is not tracked any more and never reaches the executor.
- A server that disappears from the ROS graph for ``lost_after`` seconds is
  :class:`ServerLost` (the goal died with it); once the server is back,
  :class:`ServerBack`, and the executor resends (the rule is shared with ROS 1:
  :mod:`navseq.roscore.server`). How fast DDS notices a killed process is its lease
  duration (Cyclone DDS: 10 s by default).
- Costmaps are cleared through Nav2's ``global_costmap/clear_entirely_global_costmap``
  and ``local_costmap/clear_entirely_local_costmap`` (``nav2_msgs/srv/ClearEntireCostmap``),
  waiting (bounded, ``clear_wait`` for both) for the answers so the retry plans on the
  cleared maps; a missing or silent service delays the retry by at most that, and is
  named once in the log.
- Robot pose: ``map -> odom -> base`` composed from ``/tf`` and ``/tf_static`` with
  :class:`navseq.geometry.FrameTree` (no tf2 Python library needed), else the goal
  feedback's ``current_pose``. Odometry pose (for distance driven): the ``odom`` topic.
- Feedback: ``distance_remaining`` (0, which Nav2 sends before it has a path, is
  "unknown"), ``number_of_recoveries`` and ``navigation_time`` go into
  :class:`GoalFeedback`.

Threads: rclpy's executor spins one node on a thread of its own; its callbacks only
record and put events on a queue, which :meth:`poll` drains on the caller's thread.
Every call into the action client (send, cancel, service calls) is handed to that
executor thread (``Executor.create_task``), so rclpy's client is never used from two
threads at once. The caller's thread only waits on events, so Ctrl-C and SIGTERM reach
it at once; the runner then cancels the goal, and :meth:`close` waits (bounded) for
Nav2's cancel response before the node goes away.

Time: :meth:`now` is the node's clock. With ``use_sim_time`` (True, or None: "auto",
on when someone publishes ``/clock`` once the server is found, as Nav2 run in
simulation does) it is ROS time from ``/clock``; :meth:`wait_for_server` then waits,
bounded, for a valid (non-zero) clock, so no timeout counts from time 0. Goals are
stamped with that clock. Time jumping back ends the tracked goal as a failed attempt
(:mod:`navseq.roscore.clock` says why, for ROS 1 and ROS 2 alike).

The node: by default a :class:`~navseq.ros2.session.Ros2Session` of the navigator's
own (rclpy in a context of its own, without rclpy's signal handlers: navseq's runner
handles SIGINT/SIGTERM), shut down by :meth:`close`. The ROS 2 ``navseq_node`` hands
its own session instead, so that its parameters, topics, services and the navigator's
clients are one node; :meth:`close` then leaves the session to its owner.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Mapping, Sequence
from typing import Any

from nav2_msgs.action import NavigateToPose
from nav2_msgs.srv import ClearEntireCostmap
from nav_msgs.msg import Odometry
from nav_msgs.msg import Path as PathMsg
from rclpy.action import ActionClient
from rclpy.parameter import Parameter
from rclpy.qos import (
    DurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
)
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from navseq.errors import NavseqError
from navseq.geometry import FrameTree, Pose2D, pose2d_from_pose
from navseq.mission.recovery import Recovery
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    NavEvent,
    PublishedSink,
)
from navseq.navigators.catchup import ResultHold
from navseq.navigators.stack_map import MAP_WAIT, MapCatch, StackMap, stack_map_from_message
from navseq.ros2.messages import (
    add_transforms,
    navigate_goal,
    seconds_of,
    terminal_status,
)
from navseq.ros2.record import TopicTap
from navseq.ros2.recovery_actions import Nav2Recoveries
from navseq.ros2.results import goal_done
from navseq.ros2.session import Ros2Session
from navseq.ros2.task_port import Ros2TaskPort
from navseq.roscore.clock import CLOCK_WAIT
from navseq.roscore.navigator import CANCEL_WAIT, NavigatorCore, rejected

DEFAULT_ACTION = "navigate_to_pose"
DEFAULT_NODE_NAME = "navseq"
CLEAR_WAIT = 1.0  # s of wall time for both clear-costmap services' answers
PARAMS_WAIT = 2.0  # s of wall time to read the robot from Nav2's node parameters
# Nav2's action servers reject a goal only while their lifecycle node is not active
# (configured, not yet activated; or deactivated): name the likely cause.
REJECTED_CAUSE = "is bt_navigator active? Nav2 takes goals only while it is"
LOST_AFTER = 0.3  # s of wall time the server must be gone from the graph to be lost
COSTMAP_SERVICES = (
    "global_costmap/clear_entirely_global_costmap",
    "local_costmap/clear_entirely_local_costmap",
)
# tf2's listener QoS: /tf reliable and volatile, /tf_static transient local.
TF_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
TF_STATIC_QOS = QoSProfile(
    depth=100, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


def join_name(namespace: str, name: str) -> str:
    """The absolute ROS 2 name of ``name`` in ``namespace`` (an absolute name stays)."""
    if name.startswith("/"):
        return name
    namespace = namespace.strip("/")
    return f"/{namespace}/{name}" if namespace else f"/{name}"


class Nav2Navigator:
    """A :class:`~navseq.navigators.base.Navigator` over Nav2's ``navigate_to_pose``.

    ``namespace="robot1"`` talks to ``/robot1/navigate_to_pose`` and reads
    ``/robot1/odom``; frames are then looked up as ``robot1/odom`` ... on ``/tf`` (ROS
    1's convention) and as plain ``odom`` ... on ``/robot1/tf`` (Nav2's multi-robot
    launch, the simulator's default). ``frame`` overrides each goal's frame (None: the
    goal's own). ``use_sim_time``: True, False, or None to follow ``/clock`` when it is
    published (see the module docstring). ``session``: the node to use (its namespace
    then applies, not ``namespace``'s node placement) instead of one of its own.
    """

    def __init__(
        self,
        action: str = DEFAULT_ACTION,
        frame: str | None = None,
        *,
        namespace: str = "",
        use_sim_time: bool | None = None,
        base_frames: Sequence[str] = ("base_footprint", "base_link"),
        odom_topic: str = "odom",
        plan_topic: str | None = "plan",
        node_name: str = DEFAULT_NODE_NAME,
        clock_wait: float = CLOCK_WAIT,
        cancel_wait: float = CANCEL_WAIT,
        clear_wait: float = CLEAR_WAIT,
        lost_after: float = LOST_AFTER,
        session: Ros2Session | None = None,
    ) -> None:
        self.namespace = namespace.strip("/")
        self.action = action
        self.resolved_action = join_name(self.namespace, action)
        self.frame = frame
        self.base_frames = tuple(base_frames)
        self.clock_wait = clock_wait
        self.cancel_wait = cancel_wait
        self.clear_wait = clear_wait
        self.lost_after = lost_after
        self._sim_time_asked = use_sim_time

        self._result_hold = ResultHold()  # a SUCCEEDED waits for /tf to catch up with it
        # The tracked goal (its handle: a ClientGoalHandle, once Nav2 accepted it), the
        # events for poll() (woken on every /clock message too), the server watch and
        # the clock rules: shared with ROS 1.
        self._core = NavigatorCore(
            self,
            self.resolved_action,
            lost_after=lost_after,
            cancel_wait=cancel_wait,
            on_drop=self._result_hold.drop,
        )
        self._inbox = self._core.inbox
        self._plans = self._core.plans  # a plan (and distance remaining) is the goal it ends at
        self._book = self._core.book
        self._feedback_pose: Pose2D | None = None
        self._odom_pose: Pose2D | None = None
        self._last_now = 0.0
        self._closed = False
        # /tf with the frames prefixed by the namespace, and the namespace's own tf.
        self._tf = FrameTree()
        self._local_tf = FrameTree() if self.namespace else None
        prefix = f"{self.namespace}/" if self.namespace else ""
        self._tf_base_frames = tuple(prefix + base for base in self.base_frames)

        self._owns_session = session is None
        if session is None:
            overrides = [Parameter("use_sim_time", value=True)] if use_sim_time else []
            session = Ros2Session(
                f"{node_name}_{os.getpid()}",  # unique, as ROS 1's anonymous nodes
                namespace=self.namespace or None,
                parameter_overrides=overrides,
                thread_name="navseq-nav2",
            )
        self._session = session
        self._task_port: Ros2TaskPort | None = None  # made for the first ROS task
        self._tap: TopicTap | None = None  # --record-topics
        self._context = session.context
        self._node = session.node
        try:
            sim_time = bool(use_sim_time) or bool(self._node.get_parameter("use_sim_time").value)
            # On a shared session the executor already spins: rclpy guards the node's
            # entity lists, and no goal is out before these exist.
            self._setup_node(odom_topic, plan_topic, sim_time)
        except BaseException:
            if self._owns_session:
                session.close()
            raise

    def _setup_node(self, odom_topic: str, plan_topic: str | None, sim_time: bool) -> None:
        node = self._node
        self._client = ActionClient(node, NavigateToPose, self.action)
        self._costmap_clients = [
            node.create_client(ClearEntireCostmap, name) for name in COSTMAP_SERVICES
        ]
        node.create_subscription(TFMessage, "/tf", self._on_tf(self._tf, dynamic=True), TF_QOS)
        node.create_subscription(TFMessage, "/tf_static", self._on_tf(self._tf), TF_STATIC_QOS)
        if self._local_tf is not None:
            node.create_subscription(
                TFMessage, "tf", self._on_tf(self._local_tf, dynamic=True), TF_QOS
            )
            node.create_subscription(
                TFMessage, "tf_static", self._on_tf(self._local_tf), TF_STATIC_QOS
            )
        # Best effort takes both reliable and best-effort publishers (robots use either).
        node.create_subscription(Odometry, odom_topic, self._on_odom, qos_profile_sensor_data)
        if plan_topic:
            node.create_subscription(PathMsg, plan_topic, self._on_plan, 1)
        self._clock_sub: Any = None
        if sim_time:
            self._watch_clock()
        # A retry's recoveries: Nav2's behaviour actions (spin, backup, wait).
        self._recoveries = Nav2Recoveries(node, self._in_ros, self._inbox.put, self.clear_costmaps)

    def _in_ros(self, callback: Any, *args: Any) -> None:
        """Run ``callback(*args)`` on the executor's thread (rclpy is not used from two)."""
        if not self._closed:
            self._session.call_soon(callback, *args)

    # -- Navigator protocol -----------------------------------------------------------

    def record_topics(self, topics: Sequence[str], write: PublishedSink) -> None:
        """Hand every message published on ``topics`` to ``write`` as it came (CDR),
        with its type's full definition (:mod:`navseq.ros2.record`); stamped with the
        clock the stack uses (:meth:`now`)."""
        self._tap = TopicTap(self._session, topics, write, self.now, self.warn)

    def ros_tasks(self) -> Ros2TaskPort:
        """The mission's ROS tasks on this navigator's node (:mod:`navseq.ros2.task_port`)."""
        if self._task_port is None:
            self._task_port = Ros2TaskPort(self._session)
        return self._task_port

    def now(self) -> float:
        """The node's clock (ROS time under use_sim_time); after close, its last value."""
        if self._context.ok():
            self._last_now = self._node.get_clock().now().nanoseconds * 1e-9
        return self._last_now

    @property
    def uses_sim_time(self) -> bool:
        return bool(self._node.get_parameter("use_sim_time").value)

    def spin(self, seconds: float) -> None:
        """Wait until ``seconds`` of the node's time have passed, or :meth:`poll` has news.

        Under ``use_sim_time`` each ``/clock`` message wakes the wait to look at the
        time, and a wait begun before the clock starts lasts until ``seconds`` after
        it does. A clock that jumps back (a restarted simulator) ends the tracked goal
        (:mod:`navseq.roscore.clock`).
        """
        self._core.spin(seconds, self._has_news)

    def wait_for_server(self, timeout: float) -> bool:
        """Wait (wall time) for the server, then settle the clock (module docstring).

        Raises :class:`NavseqError` when the server is there but no valid ROS time
        comes within ``clock_wait`` seconds.
        """
        if not self._core.wait_for_server(timeout, lambda: not self._context.ok()):
            return False
        self._follow_the_stacks_clock()
        self._core.wait_for_valid_time(
            self.clock_wait, "run with --use-sim-time false for a robot on wall time"
        )
        return True

    # -- the client library, as navseq.roscore asks for it (ClientLibrary) -------------

    def clock_wakes(self) -> bool:
        return self._clock_sub is not None

    def check_running(self) -> None:
        if not self._context.ok():
            raise NavseqError("ROS 2 was shut down", source="rclpy")

    def server_present(self) -> bool:
        return self._context.ok() and bool(self._client.server_is_ready())

    def server_ready(self) -> bool:
        return self.server_present()

    def warn(self, text: str) -> None:
        self._node.get_logger().warning(text)

    def require_server(self, timeout: float) -> None:
        """Like :meth:`wait_for_server`, but a missing server is a clear :class:`NavseqError`."""
        if not self.wait_for_server(timeout):
            domain = os.environ.get("ROS_DOMAIN_ID", "0")
            raise NavseqError(
                f"no action server '{self.resolved_action}' (nav2_msgs/action/NavigateToPose) "
                f"answered within {timeout:g} s in ROS_DOMAIN_ID {domain}; is Nav2 (or "
                "`navseq sim --ros2`) running in the same ROS_DOMAIN_ID, and are the action "
                "name and namespace (--ns) right?",
                source=f"action {self.resolved_action}",
            )

    def _follow_the_stacks_clock(self) -> None:
        """use_sim_time "auto": on when /clock has a publisher once the server is there."""
        if self._sim_time_asked is not None or self.uses_sim_time:
            return
        if self._node.count_publishers("/clock") == 0:
            return
        self._node.set_parameters([Parameter("use_sim_time", value=True)])
        self._watch_clock()

    def _watch_clock(self) -> None:
        self._clock_sub = self._node.create_subscription(
            Clock, "/clock", lambda _msg: self._inbox.wake(), qos_profile_sensor_data
        )

    def send_goal(self, goal: Goal) -> None:
        self._core.sending_goal()
        frame = self.frame or goal.frame or "map"
        message = navigate_goal(goal.pose, frame, self._node.get_clock().now().to_msg(), goal.z)
        with self._book.lock:
            # The goal tracked so far is simply dropped: Nav2 preempts it with this one
            # without stopping the robot. Callbacks carry the send number, so the dropped
            # goal's late result is ignored, also when the same goal is sent again.
            seq = self._book.start(goal.goal_id)
            self._plans.track(goal.goal_id, goal.pose, frame)
            self._result_hold.drop()  # a held result of the replaced goal is void
        self._in_ros(self._send, seq, goal.goal_id, message)

    def cancel_goal(self) -> None:
        """Ask Nav2 to cancel the tracked goal (once); :meth:`close` waits for the answer.

        A goal not accepted yet is cancelled as soon as Nav2 accepts it.
        """
        with self._book.lock:
            asked, handle = self._book.ask_cancel()
        if asked and handle is not None:
            self._in_ros(self._send_cancel, handle)

    def clear_costmaps(self) -> None:
        """Call both clear-costmap services and wait (bounded) for their answers.

        Both calls go out at once and share one ``clear_wait``: a service that is
        missing or does not answer in time costs at most that long, never a hang, and
        the retry goes out anyway. Each such service is named once per run (a warning
        on every retry would bury the rest of the log).
        """
        calls: list[tuple[str, threading.Event]] = []
        missing: list[str] = []
        for name, client in zip(COSTMAP_SERVICES, self._costmap_clients, strict=True):
            if client.service_is_ready():
                done = threading.Event()
                self._in_ros(self._call_clear, client, done)
                calls.append((name, done))
            else:
                missing.append(name)
        deadline = time.monotonic() + self.clear_wait
        for _name, done in calls:
            done.wait(max(deadline - time.monotonic(), 0.0))
        silent = [name for name, done in calls if not done.is_set()]
        for name in missing:
            self._core.warn_once(
                f"missing {name}", f"{name} unavailable: retrying without clearing that costmap"
            )
        for name in silent:
            self._core.warn_once(
                f"silent {name}",
                f"{name} did not answer within {self.clear_wait:g} s: retrying without "
                "waiting for it",
            )

    def run_recovery(self, recovery_id: int, recovery: Recovery) -> None:
        """Run ``recovery`` through Nav2's behaviour server (spin, backup, wait) or the
        costmaps' clear services (:mod:`navseq.ros2.recovery_actions`)."""
        self._recoveries.run(recovery_id, recovery)

    def cancel_recovery(self) -> None:
        self._recoveries.cancel()

    def read_parameters(
        self, nodes: Mapping[str, str], timeout: float = PARAMS_WAIT
    ) -> dict[str, dict[str, Any]]:
        """Every parameter of each Nav2 node in ``nodes`` (our name -> its name relative
        to the robot's namespace), through its ``list_parameters`` / ``get_parameters``
        services; ``timeout`` wall seconds for all. A node that is not there or does not
        answer in time is left out of the answer."""
        from rcl_interfaces.srv import GetParameters, ListParameters

        deadline = time.monotonic() + timeout
        clients = {
            key: (
                self._node.create_client(ListParameters, f"{name}/list_parameters"),
                self._node.create_client(GetParameters, f"{name}/get_parameters"),
            )
            for key, name in nodes.items()
        }
        answers: dict[str, dict[str, Any]] = {}
        try:
            # Discovery takes a moment: wait until every node's services are seen, or
            # the deadline; a node not seen by then is left out.
            while time.monotonic() < deadline and not all(
                lister.service_is_ready() and getter.service_is_ready()
                for lister, getter in clients.values()
            ):
                time.sleep(0.05)
            asked = {
                key: self._ask_parameters(lister, getter)
                for key, (lister, getter) in clients.items()
                if lister.service_is_ready() and getter.service_is_ready()
            }
            for key, (done, found) in asked.items():
                if done.wait(max(deadline - time.monotonic(), 0.0)) and found:
                    answers[key] = found
        finally:
            for lister, getter in clients.values():
                self._in_ros(self._node.destroy_client, lister)
                self._in_ros(self._node.destroy_client, getter)
        return answers

    def read_map(self, topics: Sequence[str], timeout: float = MAP_WAIT) -> StackMap | None:
        """The stack's map (``nav_msgs/OccupancyGrid``) from the best of ``topics``
        (absolute names, best first) heard within ``timeout`` wall seconds, or None.

        Subscribed as Nav2's map_server publishes (reliable, transient local, depth 1),
        so its last map reaches this late subscriber at once; a publisher that offers
        only volatile durability is not matched by DDS and not heard. Which topic wins
        is :class:`~navseq.navigators.stack_map.MapCatch`'s rule; NavseqError when the
        message's fields do not make a map.
        """
        from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg

        qos = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        catch = MapCatch(topics)

        def offer(topic: str) -> Any:
            return lambda message: catch.offer(topic, message)

        subscriptions = [
            self._node.create_subscription(OccupancyGridMsg, topic, offer(topic), qos)
            for topic in catch.topics
        ]
        try:
            heard = catch.wait(timeout, lambda topic: self._node.count_publishers(topic) > 0)
        finally:
            for subscription in subscriptions:
                self._in_ros(self._node.destroy_subscription, subscription)
        return None if heard is None else stack_map_from_message(heard[1], heard[0])

    def _ask_parameters(self, lister: Any, getter: Any) -> tuple[threading.Event, dict[str, Any]]:
        """List a node's parameters, then get them all (on the executor's thread)."""
        from rcl_interfaces.srv import GetParameters, ListParameters
        from rclpy.parameter import parameter_value_to_python

        done = threading.Event()
        found: dict[str, Any] = {}

        def got(names: list[str], future: Any) -> None:
            if future.exception() is None:
                for name, value in zip(names, future.result().values, strict=False):
                    found[name] = parameter_value_to_python(value)
            done.set()

        def listed(future: Any) -> None:
            if future.exception() is not None:
                done.set()
                return
            names = list(future.result().result.names)
            call = getter.call_async(GetParameters.Request(names=names))
            call.add_done_callback(lambda answer: got(names, answer))

        def ask() -> None:
            lister.call_async(ListParameters.Request()).add_done_callback(listed)

        self._in_ros(ask)
        return done, found

    def robot_pose(self) -> Pose2D | None:
        frame = self.frame or "map"
        pose = self._lookup(frame, self.base_frames, self._tf_base_frames)
        return pose if pose is not None else self._feedback_pose

    def odometry_pose(self) -> Pose2D | None:
        """The pose the ``odom`` topic gives: continuous (no localisation jumps), so the
        executor measures distance driven on it. None before the first message."""
        return self._odom_pose

    def poll(self) -> list[NavEvent]:
        released = self._result_hold.release(time.monotonic())
        return [*self._inbox.drain(), *released, *self._check_server()]

    def close(self) -> None:
        """Cancel the tracked goal, wait (bounded) for Nav2's answer, end the node."""
        if self._closed:
            return
        if self._task_port is not None:
            self._task_port.close()
        if self._tap is not None:
            self._tap.close()
        self._recoveries.cancel()
        self._core.cancel_and_wait()
        self.now()  # keep the clock's last value for after close
        self._closed = True
        if self._owns_session:
            self._session.close(self._client)

    # -- lookups -----------------------------------------------------------------------

    def _lookup(
        self, target: str, local_sources: Sequence[str], global_sources: Sequence[str]
    ) -> Pose2D | None:
        """``target`` <- the first base frame that resolves: the namespace's own tf with
        plain names first, then /tf with the namespace's prefix."""
        if self._local_tf is not None:
            for source in local_sources:
                pose = self._local_tf.lookup(target, source)
                if pose is not None:
                    return pose
        for source in global_sources:
            pose = self._tf.lookup(target, source)
            if pose is not None:
                return pose
        return None

    # -- server liveness ---------------------------------------------------------------

    def _has_news(self) -> bool:
        return self._core.has_news() or self._result_hold.ready(time.monotonic())

    def _check_server(self) -> list[NavEvent]:
        return self._core.check_server("it left the ROS graph")

    # -- on the executor's thread: rclpy calls and callbacks (record and enqueue) --------

    def _send(self, seq: int, goal_id: int, message: Any) -> None:
        future = self._client.send_goal_async(
            message, feedback_callback=lambda fb: self._on_feedback(seq, goal_id, fb)
        )
        future.add_done_callback(lambda done: self._on_goal_response(seq, goal_id, done))

    def _send_cancel(self, handle: Any) -> None:
        future = handle.cancel_goal_async()
        future.add_done_callback(lambda _done: self._book.cancel_answered.set())

    def _call_clear(self, client: Any, done: threading.Event) -> None:
        future = client.call_async(ClearEntireCostmap.Request())
        future.add_done_callback(lambda _future: done.set())

    def _on_goal_response(self, seq: int, goal_id: int, future: Any) -> None:
        error = future.exception()
        handle = None if error is not None else future.result()
        with self._book.lock:
            if not self._book.is_current(seq, goal_id):
                return  # replaced meanwhile: Nav2 preempts it with the newer goal
            if handle is None or not handle.accepted:
                self._book.drop()
                if error is not None:
                    text = f"the goal request failed: {error}"
                    self._inbox.put(GoalDone.failed(goal_id, "REJECTED", text))
                else:
                    self._inbox.put(rejected(goal_id, "", REJECTED_CAUSE))
                return
            self._book.handle = handle
            cancel_now = self._book.cancel_pending(seq)
            self._inbox.put(GoalAccepted(goal_id))
        if cancel_now:
            self._send_cancel(handle)
        result = handle.get_result_async()
        result.add_done_callback(lambda done: self._on_result(seq, goal_id, done))

    def _on_result(self, seq: int, goal_id: int, future: Any) -> None:
        with self._book.lock:
            if not self._book.is_current(seq, goal_id):
                return  # a goal we replaced or gave up on
            self._book.drop()  # a finished goal needs no cancel
        error = future.exception()
        if error is not None:
            self._inbox.put(GoalDone.lost(goal_id, f"no result: {error}"))
            return
        response = future.result()
        # Humble's NavigateToPose result has neither error_code nor error_msg.
        done = goal_done(goal_id, terminal_status(response.status), response.result)
        stamp = self._node.get_clock().now().nanoseconds * 1e-9
        if self._result_hold.should_hold(done, stamp):
            # Judged on the robot's pose: wait (bounded) until /tf is as recent as this.
            self._result_hold.hold(done, stamp, time.monotonic())
            self._inbox.wake()
            return
        self._inbox.put(done)

    def _on_feedback(self, seq: int, goal_id: int, message: Any) -> None:
        feedback = message.feedback
        pose = pose2d_from_pose(feedback.current_pose.pose)
        self._feedback_pose = pose
        if not self._book.is_current(seq, goal_id):
            return
        remaining = float(feedback.distance_remaining)
        if not self._plans.distance_is_this_goals():
            # Measured along the preempted goal's path, which Nav2 follows until it re-plans.
            remaining = 0.0
        self._inbox.put(
            GoalFeedback(
                goal_id,
                pose,
                # Nav2 sends 0 until it has a path: unknown, not "arrived".
                remaining if remaining > 0.0 else None,
                recoveries=int(feedback.number_of_recoveries),
                navigation_time=seconds_of(feedback.navigation_time),
            )
        )

    def _on_tf(self, tree: FrameTree, *, dynamic: bool = False) -> Any:
        def on_tf(message: Any) -> None:
            add_transforms(tree, message)
            if dynamic and message.transforms:
                stamps = (seconds_of(t.header.stamp) for t in message.transforms)
                self._result_hold.saw_pose(max(stamps))

        return on_tf

    def _on_odom(self, message: Any) -> None:
        self._odom_pose = pose2d_from_pose(message.pose.pose)

    def _on_plan(self, message: Any) -> None:
        if self._book.goal_id is None:
            return
        points = tuple((p.pose.position.x, p.pose.position.y) for p in message.poses)
        plan = self._plans.plan_for(points, message.header.frame_id)
        if plan is not None:
            self._inbox.put(plan)
