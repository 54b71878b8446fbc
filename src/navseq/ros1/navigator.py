"""The ``ros1`` navigator: goals to a move_base ``MoveBaseAction`` server over actionlib.

How it stays out of actionlib's traps:

- actionlib calls its callbacks on rospy's threads. Here they only put events on a
  thread-safe queue; :meth:`Ros1Navigator.poll`, called by the executor's loop on the
  main thread, drains it. No goal is ever sent from inside a callback: the tutorial's
  ``done_cb`` pattern makes Noetic's ``SimpleActionClient`` ignore the next goal's result
  (ros/actionlib issue 193) and the mission stalls after its second goal.
- It uses actionlib's lower-level ``ActionClient``, which reports every status a server
  can give (SUCCEEDED, ABORTED, REJECTED, PREEMPTED, RECALLED, and LOST when the server
  forgets a goal) for any goal, also one replaced by a newer goal.
- What ROS 1 and ROS 2 do alike is :class:`~navseq.roscore.navigator.NavigatorCore`'s:
  a server that stops publishing its status for ``status_timeout`` seconds (move_base
  publishes it at 5 Hz) is :class:`ServerLost`, and :class:`ServerBack` once it
  publishes again *and* has connected to our goal and cancel topics (so the resent
  goal cannot vanish in transit); a rejected goal, ROS time jumping back and a cancel
  that is never answered are handled as :mod:`navseq.roscore.navigator` says.

Time: :meth:`now` is the navigation stack's clock and :meth:`spin` waits on it, so
under ``use_sim_time`` the executor's timeouts run on the simulation clock. Which clock
that is gets settled once the server is found (:meth:`wait_for_server`): rospy reads
``/use_sim_time`` only once, in ``init_node``, so a navseq started at the same moment as
a simulator may have come up on wall time before the simulator set the parameter. If
``/use_sim_time`` is true by then while rospy runs on wall time, the navigator takes
its time from ``/clock`` itself (goal stamps included). Either way it then waits, on
wall time and bounded, for a valid (non-zero) clock, so no timeout or journal time is
counted from time 0 before the first ``/clock`` (actionlib #137); none is a
:class:`NavseqError` naming ``/clock`` and ``use_sim_time``. The server wait itself is
on wall time and needs no clock. :meth:`spin` returns early as soon as a callback
queues an event (or the server is lost or back, or ROS time jumped back:
:mod:`navseq.roscore.clock`).

move_base's SUCCEEDED race (ros-planning/navigation #949): a goal sent a few
milliseconds after the previous goal's result can inherit the plan still being computed
for the old one and end SUCCEEDED at once, metres from its pose. :meth:`send_goal`
therefore sends a goal that follows a result only once ``settle`` seconds (wall time,
default 0.05) have passed since that result *and* the server's status array lists the
previous goal as terminal (waited for up to 0.5 s). A goal that replaces an active one
(pass-through) goes out at once. ``settle=0`` turns the precaution off.

Goals are stamped with ``rospy.Time.now()`` (``stamp="now"``, what RViz does);
``stamp="latest"`` stamps them with time zero, which tells move_base to use the latest
transform when the goal frame differs from its global frame — safer when TF lags behind
the clock (it avoids "extrapolation into the future" errors). Before ``/clock`` arrives,
ROS time is zero and both are the same.

Robot pose: from TF (``frame`` -> the first of ``base_frames`` that resolves) when
available, else from the goal feedback's ``base_position``. :meth:`odometry_pose` is the
pose in the odometry frame (``odom_frame`` -> base frame, from TF): it drifts but never
jumps, unlike the map pose when localisation corrects itself.
"""

from __future__ import annotations

import functools
import io
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, Literal

import actionlib
import rosgraph
import rosgraph.names
import rospy
from actionlib.action_client import CommState
from move_base_msgs.msg import MoveBaseAction
from nav_msgs.msg import Path as PathMsg
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.recovery import Recovery
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    GoalOutcome,
    NavEvent,
    PublishedSink,
)
from navseq.navigators.plain_recoveries import PLAIN_KINDS, PlainRecoveries
from navseq.ros1.conversions import move_base_goal, pose2d_from_pose, pose2d_from_transform
from navseq.ros1.conversions import terminal_status as terminal_status_of
from navseq.ros1.task_port import Ros1TaskPort
from navseq.roscore.clock import CLOCK_WAIT
from navseq.roscore.navigator import CANCEL_WAIT, REJECTED_STATUS, NavigatorCore, rejected

DEFAULT_NODE_NAME = "navseq"
MASTER_WAIT = 5.0  # s of wall time to find a ROS master before giving up
DEFAULT_SETTLE = 0.05  # s of wall time between a result and the next goal (race #949)
# Longest wall-time wait for the server's status array to list a finished goal as such.
STATUS_LISTING_WAIT = 0.5
CLEAR_WAIT = 1.0  # s of wall time clear_costmaps waits for move_base, service lookup included
# actionlib_msgs/GoalStatus codes of a finished goal.
_TERMINAL_CODES = frozenset({2, 3, 4, 5, 8, 9})
# Client states in which the server has taken in our cancel.
_CANCEL_SEEN = (CommState.RECALLING, CommState.PREEMPTING, CommState.DONE)
# move_base never rejects a goal itself; a server that does without a word:
REJECTED_CAUSE = "it gave no reason"


def ensure_node(name: str = DEFAULT_NODE_NAME, *, anonymous: bool = True) -> None:
    """Make this process a ROS node if it is not one yet (rospy allows one per process).

    rospy's own signal handlers are disabled: Ctrl-C must reach navseq's runner as
    KeyboardInterrupt so the active goal is cancelled *before* rospy shuts down.
    Raises :class:`NavseqError` if no ROS master answers (``init_node`` would otherwise
    wait for one forever).
    """
    if rospy.core.is_initialized():
        return
    uri = rosgraph.get_master_uri()
    deadline = time.monotonic() + MASTER_WAIT
    while not rosgraph.is_master_online(uri):
        if time.monotonic() >= deadline:
            raise NavseqError(
                f"no ROS master answers at {uri}; start roscore (or roslaunch) first, "
                "or set ROS_MASTER_URI",
                source="ROS_MASTER_URI",
            )
        time.sleep(0.1)
    rospy.init_node(name, anonymous=anonymous, disable_signals=True)


class _TimedActionClient(actionlib.ActionClient):
    """actionlib's ActionClient that also remembers when the server last spoke.

    ``on_status`` is called (on a rospy thread) after every status message.
    """

    def __init__(self, ns: str, spec: Any, on_status: Callable[[], None]):
        self.last_status_wall: float | None = None
        self._on_status = on_status  # set before super(): its subscribers start at once
        super().__init__(ns, spec)

    def _status_cb(self, msg: Any) -> None:
        self.last_status_wall = time.monotonic()
        super()._status_cb(msg)
        self._on_status()

    def server_connected(self) -> bool:
        """The server we last heard from is connected to our goal and cancel topics.

        The same test as ``ActionClient.wait_for_server``, without blocking.
        """
        status = self.last_status_msg
        if status is None:
            return False
        server_id = status._connection_header["callerid"]
        return bool(
            self.pub_goal.impl.has_connection(server_id)
            and self.pub_cancel.impl.has_connection(server_id)
        )


class Ros1Navigator:
    """A :class:`~navseq.navigators.base.Navigator` over a move_base action server.

    ``action`` is resolved in ``namespace`` (``namespace="/robot1"`` talks to
    ``/robot1/move_base``, for fleets). ``frame`` overrides the mission frame in goals
    (None: each goal's own frame). The caller needs no ``rospy.init_node``: an anonymous
    node is started if the process is not a node yet.
    """

    def __init__(
        self,
        action: str = "move_base",
        frame: str | None = None,
        *,
        namespace: str = "",
        base_frames: Sequence[str] = ("base_footprint", "base_link"),
        stamp: Literal["now", "latest"] = "now",
        status_timeout: float = 2.0,
        plan_topic: str | None = "NavfnROS/plan",
        use_tf: bool = True,
        node_name: str = DEFAULT_NODE_NAME,
        settle: float = DEFAULT_SETTLE,
        odom_frame: str = "odom",
        clock_wait: float = CLOCK_WAIT,
        clear_wait: float = CLEAR_WAIT,
        cancel_wait: float = CANCEL_WAIT,
    ):
        if stamp not in ("now", "latest"):
            raise NavseqError(f"stamp must be 'now' or 'latest', not {stamp!r}", subject="stamp")
        if status_timeout <= 0:
            raise NavseqError("must be > 0 s", subject="status_timeout")
        if not settle >= 0:
            raise NavseqError(f"must be >= 0 s (0: off), not {settle!r}", subject="settle")
        ensure_node(node_name)
        self.action = rosgraph.names.ns_join(namespace, action) if namespace else action
        self.resolved_action = rospy.resolve_name(self.action)
        self.frame = frame
        self.base_frames = tuple(base_frames)
        self.stamp = stamp
        self.status_timeout = status_timeout
        self.settle = settle
        self.odom_frame = odom_frame
        self.clock_wait = clock_wait
        self.clear_wait = clear_wait
        # Set when the navigation stack runs on /clock but rospy came up on wall time:
        # the latest /clock time, read instead of rospy's (None: rospy's time is right).
        self._clock_time: float | None = None
        # (wall time, actionlib goal id) of the last result of a goal we tracked.
        self._last_result: tuple[float, str] | None = None

        # The tracked goal (its handle: a ClientGoalHandle), the events for poll(), the
        # server watch and the clock rules: shared with ROS 2. lost_after 0: "present"
        # already means a status within status_timeout (server_present).
        self._core = NavigatorCore(
            self, self.resolved_action, lost_after=0.0, cancel_wait=cancel_wait
        )
        self._inbox = self._core.inbox
        self._recoveries = PlainRecoveries(self.now, self.clear_costmaps)
        self._plans = self._core.plans
        self._book = self._core.book
        self._feedback_pose: Pose2D | None = None
        self._closed = False
        self._taps: list[Any] = []  # subscribers of record_topics
        self._task_port: Ros1TaskPort | None = None  # made for the first ROS task
        # Created after the state its callbacks read: they may run at once.
        self._client = _TimedActionClient(self.action, MoveBaseAction, self._on_status)

        self._plan_sub = None
        if plan_topic:
            self._plan_sub = rospy.Subscriber(
                rosgraph.names.ns_join(self.action, plan_topic),
                PathMsg,
                self._on_plan,
                queue_size=1,
            )
        self._tf_buffer = None
        if use_tf:
            import tf2_ros  # only when asked: it subscribes to /tf, which can be busy

            self._tf_buffer = tf2_ros.Buffer()
            self._tf_listener = tf2_ros.TransformListener(self._tf_buffer)
        self._clock_sub = None
        if not rospy.rostime.is_wallclock():
            # Under use_sim_time, each /clock message wakes spin() to look at the time:
            # a wall-time slice would overshoot a short wait on a fast simulation clock.
            self._clock_sub = rospy.Subscriber("/clock", Clock, self._on_clock)
        rospy.on_shutdown(self._on_rospy_shutdown)

    # -- Navigator protocol -----------------------------------------------------------

    def ros_tasks(self) -> Ros1TaskPort:
        """The mission's ROS tasks on this node (:mod:`navseq.ros1.task_port`)."""
        if self._task_port is None:
            self._task_port = Ros1TaskPort()
        return self._task_port

    def now(self) -> float:
        if self._clock_time is not None:
            return self._clock_time
        return rospy.get_time()

    @property
    def follows_clock_topic(self) -> bool:
        """Time comes from ``/clock`` read by this navigator, not from rospy."""
        return self._clock_time is not None

    def _stamp_now(self) -> rospy.Time:
        return rospy.Time.from_sec(self.now()) if self._clock_time is not None else rospy.Time.now()

    def spin(self, seconds: float) -> None:
        """Wait until ``seconds`` of ROS time have passed or :meth:`poll` has news.

        News is an event queued by an actionlib callback, or the server lost or back.
        Like ``rospy.sleep``: under ``use_sim_time`` the wait is on the simulation clock
        and, while the clock has not started (time zero), lasts until ``seconds`` after
        it starts; raises ``rospy.ROSInterruptException`` on ROS shutdown. ROS time
        jumping back ends the tracked goal (:mod:`navseq.roscore.clock`).
        """
        self._core.spin(seconds, self._has_news)

    def wait_for_server(self, timeout: float) -> bool:
        """Wait (wall time) for the server, then settle the clock (see the module doc).

        Raises :class:`NavseqError` when the server is there but no valid ROS time
        comes within ``clock_wait`` seconds.
        """
        if not self._core.wait_for_server(timeout, rospy.is_shutdown):
            return False
        self._follow_the_stacks_clock()
        self._core.wait_for_valid_time(
            self.clock_wait,
            "set /use_sim_time false (rosparam set /use_sim_time false) for a robot on wall time",
        )
        return True

    # -- the client library, as navseq.roscore asks for it (ClientLibrary) -------------

    def clock_wakes(self) -> bool:
        return self._clock_sub is not None

    def check_running(self) -> None:
        if rospy.is_shutdown():
            raise rospy.ROSInterruptException("ROS shutdown request")

    def server_present(self) -> bool:
        return self._status_fresh()

    def server_ready(self) -> bool:
        return self._status_fresh() and self._client.server_connected()

    def warn(self, text: str) -> None:
        rospy.logwarn("navseq: %s", text)

    def _follow_the_stacks_clock(self) -> None:
        """Take time from /clock if the stack set /use_sim_time after rospy started."""
        if self._clock_time is not None or not rospy.rostime.is_wallclock():
            return
        try:
            sim_time = rospy.get_param("/use_sim_time", False)
        except (rospy.ROSException, OSError):
            return
        if sim_time not in (True, "true", "True"):
            return
        rospy.logwarn(
            "navseq: /use_sim_time became true after this node started on wall time; "
            "taking time from /clock"
        )
        self._clock_time = 0.0
        self._clock_sub = rospy.Subscriber("/clock", Clock, self._on_clock, queue_size=1)

    def require_server(self, timeout: float) -> None:
        """Like :meth:`wait_for_server`, but a missing server is a clear :class:`NavseqError`."""
        if not self.wait_for_server(timeout):
            raise NavseqError(
                f"no action server '{self.resolved_action}' (move_base_msgs/MoveBaseAction) "
                f"answered within {timeout:g} s on the ROS master at "
                f"{rosgraph.get_master_uri()}; is move_base (or `roslaunch navseq "
                "sim.launch`) running, and is the action name/namespace right?",
                source=f"action {self.resolved_action}",
            )

    def send_goal(self, goal: Goal) -> None:
        self._settle_after_result()
        self._core.sending_goal()
        frame = self.frame or goal.frame or "map"
        stamp = self._stamp_now() if self.stamp == "now" else rospy.Time(0)
        message = move_base_goal(goal.pose, frame, stamp, goal.z)
        with self._book.lock:
            # The previous goal is simply no longer tracked: like move_base's own
            # preemption, the new goal replaces it without stopping the robot. Callbacks
            # carry the send number, so a replaced goal's late callbacks are ignored even
            # when the same goal is sent again (pause/resume).
            seq = self._book.start(goal.goal_id)
            self._plans.track(goal.goal_id, goal.pose, frame)
        # Not under the book's lock: actionlib holds its own locks while calling our callbacks,
        # which take the book's lock; holding ours while it takes its own would deadlock.
        handle = self._client.send_goal(
            message,
            transition_cb=lambda h: self._on_transition(seq, goal.goal_id, h),
            feedback_cb=lambda h, fb: self._on_feedback(seq, goal.goal_id, fb),
        )
        with self._book.lock:
            # actionlib only keeps a weak reference: this one keeps the goal's callbacks alive.
            if self._book.is_current(seq) and handle.get_comm_state() != CommState.DONE:
                self._book.handle = handle

    def _settle_after_result(self) -> None:
        """Keep a goal that follows a result out of move_base's race (module doc)."""
        if self.settle <= 0:
            return
        with self._book.lock:
            replacing = self._book.handle is not None  # an active goal: no result to race with
            last = self._last_result
        if replacing or last is None:
            return
        result_at, previous_id = last
        settled_at = result_at + self.settle
        give_up_listing_at = result_at + max(self.settle, STATUS_LISTING_WAIT)
        while not rospy.is_shutdown():
            now = time.monotonic()
            if now >= settled_at and (
                now >= give_up_listing_at or self._status_lists_as_terminal(previous_id)
            ):
                return
            time.sleep(min(0.005, max(settled_at - now, 0.001)))

    def _status_lists_as_terminal(self, goal_id: str) -> bool:
        status = self._client.last_status_msg
        if status is None:
            return False
        return any(
            entry.goal_id.id == goal_id and entry.status in _TERMINAL_CODES
            for entry in status.status_list
        )

    def cancel_goal(self) -> None:
        with self._book.lock:
            asked, handle = self._book.ask_cancel()
            if asked and (handle is None or handle.get_comm_state() == CommState.DONE):
                self._book.cancel_answered.set()  # nothing out there to cancel
                return
        if not asked:
            return
        try:
            handle.cancel()
        except (rospy.ROSException, OSError, ValueError) as error:
            rospy.logwarn("navseq: could not cancel the active goal: %s", error)

    def clear_costmaps(self) -> None:
        """Call move_base's ``clear_costmaps``, waiting at most ``clear_wait`` in all.

        rospy's service calls have no timeout, and a move_base busy in a long recovery
        (or wedged) takes the call but never answers: the call therefore runs on a
        thread of its own, left behind (daemon) if it does not answer in time. Either
        way the retry goes out after at most ``clear_wait``; what went wrong is said
        once per kind (missing, silent, failed), not on every retry.
        """
        service = rosgraph.names.ns_join(self.resolved_action, "clear_costmaps")
        deadline = time.monotonic() + self.clear_wait
        try:
            rospy.wait_for_service(service, timeout=self.clear_wait)
        except rospy.ROSException:
            self._core.warn_once("unavailable", f"{service} unavailable, retrying without it")
            return
        answered = threading.Event()
        errors: list[Exception] = []

        def call() -> None:
            try:
                rospy.ServiceProxy(service, Empty)()
            except (rospy.ROSException, rospy.ServiceException, OSError) as error:
                errors.append(error)
            finally:
                answered.set()

        threading.Thread(target=call, name="navseq-clear-costmaps", daemon=True).start()
        if not answered.wait(max(deadline - time.monotonic(), 0.0)):
            self._core.warn_once(
                "silent",
                f"{service} did not answer within {self.clear_wait:g} s, "
                "retrying without waiting for it",
            )
        elif errors:
            self._core.warn_once("failed", f"{service} failed, retrying anyway ({errors[0]})")

    #: The recoveries it runs (a node's run refuses the others before the robot moves).
    recovery_kinds = PLAIN_KINDS

    def run_recovery(self, recovery_id: int, recovery: Recovery) -> None:
        """``wait`` on ROS time and ``clear_costmaps`` through move_base's service;
        move_base has no spin or backup to ask for (refused before the run)."""
        self._recoveries.run(recovery_id, recovery)

    def cancel_recovery(self) -> None:
        self._recoveries.cancel()

    def robot_pose(self) -> Pose2D | None:
        if self._tf_buffer is not None:
            frame = self.frame or "map"
            for base in self.base_frames:
                try:
                    transform = self._tf_buffer.lookup_transform(frame, base, rospy.Time(0))
                except Exception:  # tf2 raises several unrelated types; any means "not now"
                    continue
                return pose2d_from_transform(transform)
        return self._feedback_pose

    def odometry_pose(self) -> Pose2D | None:
        """The robot pose in ``odom_frame`` from TF; None when TF has none (or is off).

        Continuous, unlike the map pose that localisation may shift at any time: what
        to measure a short movement with (how far the robot really drove for a goal).
        """
        if self._tf_buffer is None:
            return None
        for base in self.base_frames:
            try:
                transform = self._tf_buffer.lookup_transform(self.odom_frame, base, rospy.Time(0))
            except Exception:  # tf2 raises several unrelated types; any means "not now"
                continue
            return pose2d_from_transform(transform)
        return None

    def poll(self) -> list[NavEvent]:
        why_lost = f"no status for {self.status_timeout:g} s"
        ended = self._recoveries.poll()
        return [*self._inbox.drain(), *ended, *self._core.check_server(why_lost)]

    def close(self) -> None:
        """Cancel the tracked goal and wait (bounded) until move_base takes the cancel in."""
        if self._closed:
            return
        self._closed = True
        for tap in self._taps:
            tap.unregister()
        if self._task_port is not None:
            self._task_port.close()
        self._core.cancel_and_wait()

    def record_topics(self, topics: Sequence[str], write: PublishedSink) -> None:
        """Hand every message published on ``topics`` to ``write`` as it came, serialised.

        ``rospy.AnyMsg`` keeps the bytes undecoded; the publisher's connection header
        names the type and carries its full definition, so anything a stack publishes
        is recorded (``navseq run --record-topics /scan``) without its Python message.
        Stamped with the clock the stack uses (:meth:`now`).
        """
        self._taps = [
            rospy.Subscriber(topic, rospy.AnyMsg, functools.partial(self._on_tapped, topic, write))
            for topic in topics
        ]

    def _on_tapped(self, topic: str, write: PublishedSink, message: Any) -> None:
        if isinstance(message, rospy.AnyMsg):
            header = getattr(message, "_connection_header", None) or {}
            type_name, definition = header.get("type"), header.get("message_definition")
            if type_name and definition is not None:
                write(topic, type_name, definition, bytes(message._buff), self.now())
            return
        # rospy shares one subscription per topic in a process: where this navigator
        # subscribes already (the plan), its message class decodes for every callback.
        buffer = io.BytesIO()
        message.serialize(buffer)
        write(topic, message._type, message._full_text, buffer.getvalue(), self.now())

    def _has_news(self) -> bool:
        """:meth:`poll` has something to report: a queued event, or the server lost or back."""
        return self._core.has_news()

    def _status_fresh(self) -> bool:
        last = self._client.last_status_wall
        return last is not None and time.monotonic() - last <= self.status_timeout

    # -- actionlib callbacks (rospy threads: only record and enqueue) ---------------------

    def _on_transition(self, seq: int, goal_id: int, handle: Any) -> None:
        with self._book.lock:
            if not self._book.is_current(seq):
                return  # a goal we replaced or gave up on
            state = handle.get_comm_state()
            if state in _CANCEL_SEEN:
                self._book.cancel_answered.set()
            # PENDING only means the server received it; ACTIVE means it took it on.
            if state == CommState.ACTIVE and not self._book.accepted:
                self._book.accepted = True
                self._inbox.put(GoalAccepted(goal_id))
            elif state == CommState.DONE:
                outcome, status = terminal_status_of(handle.get_goal_status()) or (
                    GoalOutcome.LOST,
                    "LOST",
                )
                text = handle.get_goal_status_text()
                if outcome is GoalOutcome.LOST:
                    # The server forgot the goal (e.g. restarted quickly): let poll()
                    # announce ServerBack once it is ready, so the executor resends.
                    self._core.watch.forget()
                if status == REJECTED_STATUS:
                    self._inbox.put(rejected(goal_id, text, REJECTED_CAUSE))
                else:
                    self._inbox.put(GoalDone(goal_id, outcome, status, text))
                self._last_result = (
                    time.monotonic(),
                    handle.comm_state_machine.action_goal.goal_id.id,
                )
                self._book.drop()

    def _on_feedback(self, seq: int, goal_id: int, feedback: Any) -> None:
        pose = pose2d_from_pose(feedback.base_position.pose)
        self._feedback_pose = pose
        if self._book.is_current(seq):
            self._inbox.put(GoalFeedback(goal_id, pose))

    def _on_plan(self, path: Any) -> None:
        if self._book.goal_id is None:
            return
        points = tuple((p.pose.position.x, p.pose.position.y) for p in path.poses)
        plan = self._plans.plan_for(points, path.header.frame_id)
        if plan is not None:
            self._inbox.put(plan)

    def _on_status(self) -> None:
        if self._core.watch.up is False:
            self._inbox.wake()  # the server may be back: let spin() check

    def _on_clock(self, clock: Any) -> None:
        if self._clock_time is not None:
            self._clock_time = clock.clock.to_sec()
        self._inbox.wake()  # ROS time moved: let spin() check its deadline

    def _on_rospy_shutdown(self) -> None:
        self._inbox.wake()
        # Runs before rospy closes its publishers (rosnode kill, signal_shutdown), so
        # the cancel still goes out and the robot does not drive on without us.
        if not self._closed:
            self._closed = True
            self._core.cancel_and_wait()
