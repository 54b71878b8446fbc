#!/usr/bin/env python3
"""A scripted MoveBase action server: a stand-in for move_base whose outcomes tests choose.

Each goal it receives, in arrival order, follows the next behaviour of ``--script``
(then ``--then`` for every later goal). A behaviour is ``KIND[:SECONDS]``:

``succeed``  accept, drive the reported pose toward the goal, SUCCEEDED after SECONDS
             (and one feedback period more: the feedback showing the robot at the goal,
             facing its yaw, goes out first, as navseq checks a SUCCEEDED against it)
``abort``    accept, ABORTED after SECONDS
``reject``   REJECTED after SECONDS without accepting
``preempt``  accept, then the server itself cancels it: PREEMPTED after SECONDS
``recall``   leave it pending, then cancel it: RECALLED after SECONDS
``hang``     accept and never finish (only a cancel or a newer goal ends it)
``die``      accept, then the whole process exits abruptly after SECONDS (server lost)
``jump``     accept, and after SECONDS set ``/clock`` back by :data:`JUMP_BACK` (a simulator
             restart); then like ``hang``. Needs ``--clock``.

Like move_base, a newer goal preempts the active one and a cancel request ends an active
goal PREEMPTED (a pending one RECALLED). Everything observable — goals with their poses,
frames and stamps, cancels, results, clear_costmaps calls — is appended as JSON lines to
``--log`` so tests can assert what a client really sent.

``--clear-costmaps`` says how its ``clear_costmaps`` service behaves: ``answer`` (at
once), ``silent`` (takes the call, logs it, never answers: a move_base stuck in a long
recovery) or ``absent`` (no such service).

``--clock`` publishes ``/clock`` (from :data:`CLOCK_START` s, at wall speed), as a
simulator does; the client must run with ``/use_sim_time`` true. ``--cancel ignore``
makes the server deaf to cancel requests (a wedged move_base): actionlib's server would
otherwise acknowledge every cancel by itself (PREEMPTING / RECALLING), whatever the
server's own callback does.

It is a real actionlib ``ActionServer`` on a real ROS master; nothing is mocked.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import actionlib
import rospy
from geometry_msgs.msg import PoseStamped
from move_base_msgs.msg import MoveBaseAction, MoveBaseFeedback, MoveBaseResult
from nav_msgs.msg import Path as PathMsg
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty, EmptyResponse

KINDS = ("succeed", "abort", "reject", "preempt", "recall", "hang", "die", "jump")
FEEDBACK_PERIOD = 0.1  # s of wall time between feedback messages
CLOCK_START = 100.0  # s: where --clock starts
JUMP_BACK = 90.0  # s the clock goes back on a ``jump``
CLOCK_PERIOD = 0.01  # s of wall time between /clock messages


class JumpingClock:
    """``/clock`` at wall speed from CLOCK_START; :meth:`jump_back` sets it back."""

    def __init__(self) -> None:
        self._pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self._zero = time.monotonic() - CLOCK_START
        threading.Thread(target=self._run, daemon=True).start()

    def jump_back(self) -> None:
        self._zero += JUMP_BACK

    def _run(self) -> None:
        while not rospy.is_shutdown():
            self._pub.publish(Clock(clock=rospy.Time.from_sec(time.monotonic() - self._zero)))
            time.sleep(CLOCK_PERIOD)


@dataclass(frozen=True)
class Behaviour:
    kind: str
    seconds: float

    @classmethod
    def parse(cls, text: str) -> Behaviour:
        kind, _, seconds = text.partition(":")
        if kind not in KINDS:
            raise argparse.ArgumentTypeError(f"unknown behaviour {kind!r}; one of {KINDS}")
        return cls(kind, float(seconds) if seconds else 0.3)


@dataclass
class TrackedGoal:
    handle: Any
    behaviour: Behaviour
    received: float  # time.monotonic()
    start_xy: tuple[float, float]
    goal_xy: tuple[float, float]
    accepted: bool = False
    done: bool = False
    arrival_published: bool = False  # a feedback at the goal went out (succeed only)
    extra: dict[str, Any] = field(default_factory=dict)


class ScriptedMoveBase:
    def __init__(
        self,
        action: str,
        script: list[Behaviour],
        then: Behaviour,
        log: Path | None,
        clear_costmaps: str = "answer",
        clock: JumpingClock | None = None,
        cancel: str = "answer",
    ):
        self._script = list(script)
        self._then = then
        self._log_path = log
        self._lock = threading.RLock()
        self._goals: list[TrackedGoal] = []
        self._count = 0
        self._robot_xy = (0.0, 0.0)
        self._plan_pub = rospy.Publisher(f"{action}/NavfnROS/plan", PathMsg, queue_size=2)
        self._clear_answers = clear_costmaps == "answer"
        if clear_costmaps != "absent":
            rospy.Service(f"{action}/clear_costmaps", Empty, self._clear_costmaps)
        self._clock = clock
        self._server = actionlib.ActionServer(
            action, MoveBaseAction, self._on_goal, self._on_cancel, auto_start=False
        )
        if cancel == "ignore":
            # Before start(), which subscribes this very attribute to the cancel topic.
            self._server.internal_cancel_callback = self._ignore_cancel
        self._server.start()

    # -- log ---------------------------------------------------------------------------

    def log(self, event: str, **fields: Any) -> None:
        if self._log_path is None:
            return
        record = {"event": event, "t": time.time(), "pid": os.getpid(), **fields}
        with open(self._log_path, "a", encoding="utf-8") as sink:
            sink.write(json.dumps(record) + "\n")

    # -- callbacks (rospy threads) -------------------------------------------------------

    def _on_goal(self, handle: Any) -> None:
        goal = handle.get_goal()
        pose = goal.target_pose
        q = pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        with self._lock:
            behaviour = self._script.pop(0) if self._script else self._then
            self._count += 1
            goal_id = handle.get_goal_id().id
            self.log(
                "goal",
                id=goal_id,
                n=self._count,
                x=pose.pose.position.x,
                y=pose.pose.position.y,
                z=pose.pose.position.z,
                yaw=yaw,
                frame=pose.header.frame_id,
                stamp=pose.header.stamp.to_sec(),
                behaviour=behaviour.kind,
            )
            tracked = TrackedGoal(
                handle=handle,
                behaviour=behaviour,
                received=time.monotonic(),
                start_xy=self._robot_xy,
                goal_xy=(pose.pose.position.x, pose.pose.position.y),
            )
            # Like move_base: a newer goal preempts whatever is still running.
            for older in self._goals:
                if not older.done and older.accepted:
                    self._finish(older, "PREEMPTED", "preempted by a newer goal")
            self._goals = [g for g in self._goals if not g.done]
            self._goals.append(tracked)
            if behaviour.kind not in ("reject", "recall"):
                handle.set_accepted()
                tracked.accepted = True
                self.log("accepted", id=goal_id)
                path = PathMsg()
                path.header.frame_id = pose.header.frame_id
                for fraction in (0.0, 0.5, 1.0):
                    point = PoseStamped()
                    point.header.frame_id = pose.header.frame_id
                    point.pose.position.x = tracked.start_xy[0] + fraction * (
                        tracked.goal_xy[0] - tracked.start_xy[0]
                    )
                    point.pose.position.y = tracked.start_xy[1] + fraction * (
                        tracked.goal_xy[1] - tracked.start_xy[1]
                    )
                    point.pose.orientation.w = 1.0
                    path.poses.append(point)
                self._plan_pub.publish(path)

    def _on_cancel(self, handle: Any) -> None:
        goal_id = handle.get_goal_id().id
        with self._lock:
            self.log("cancel", id=goal_id)
            for tracked in self._goals:
                if tracked.handle.get_goal_id().id == goal_id and not tracked.done:
                    status = "PREEMPTED" if tracked.accepted else "RECALLED"
                    self._finish(tracked, status, "canceled by the client")

    def _ignore_cancel(self, goal_id: Any) -> None:
        self.log("cancel_ignored", id=goal_id.id)

    def _clear_costmaps(self, _request: Any) -> EmptyResponse:
        self.log("clear_costmaps")
        while not self._clear_answers and not rospy.is_shutdown():
            time.sleep(0.1)  # rospy serves each call on a thread of its own
        return EmptyResponse()

    # -- behaviour -----------------------------------------------------------------------

    def _finish(self, tracked: TrackedGoal, status: str, text: str) -> None:
        tracked.done = True
        handle = tracked.handle
        result = MoveBaseResult()
        if status == "SUCCEEDED":
            handle.set_succeeded(result, text)
        elif status == "ABORTED":
            handle.set_aborted(result, text)
        elif status == "REJECTED":
            handle.set_rejected(result, text)
        else:
            # actionlib decides: PREEMPTED for an accepted goal, RECALLED for a pending one.
            handle.set_canceled(result, text)
        self.log("done", id=handle.get_goal_id().id, status=status, text=text)

    def step(self) -> None:
        now = time.monotonic()
        # actionlib calls _on_goal/_on_cancel holding the server's lock, and they take
        # ours; take the two in the same order here, or a goal arriving while a result
        # goes out deadlocks the server.
        with self._server.lock, self._lock:
            for tracked in self._goals:
                if tracked.done:
                    continue
                kind, seconds = tracked.behaviour.kind, tracked.behaviour.seconds
                elapsed = now - tracked.received
                if tracked.accepted:
                    self._feedback(tracked, min(1.0, elapsed / max(seconds, 1e-3)))
                if kind == "jump" and elapsed >= seconds and not tracked.extra.get("jumped"):
                    tracked.extra["jumped"] = True
                    assert self._clock is not None, "jump needs --clock"
                    self._clock.jump_back()
                    self.log("jump", back=JUMP_BACK)
                if kind in ("hang", "jump") or elapsed < seconds:
                    continue
                if kind == "succeed" and not tracked.arrival_published:
                    # Feedback and result travel on separate topics: give the feedback
                    # at the goal a step's head start, so a client sees the robot there.
                    tracked.arrival_published = True
                    continue
                if kind == "die":
                    self.log("die")
                    os._exit(3)
                status = {
                    "succeed": "SUCCEEDED",
                    "abort": "ABORTED",
                    "reject": "REJECTED",
                    "preempt": "PREEMPTED",
                    "recall": "RECALLED",
                }[kind]
                self._finish(tracked, status, f"scripted {kind}")
            self._goals = [g for g in self._goals if not g.done]

    def _feedback(self, tracked: TrackedGoal, fraction: float) -> None:
        if tracked.behaviour.kind == "succeed":
            (x0, y0), (x1, y1) = tracked.start_xy, tracked.goal_xy
            self._robot_xy = (x0 + fraction * (x1 - x0), y0 + fraction * (y1 - y0))
        feedback = MoveBaseFeedback()
        target = tracked.handle.get_goal().target_pose
        feedback.base_position.header.frame_id = target.header.frame_id
        feedback.base_position.header.stamp = rospy.Time.now()
        feedback.base_position.pose.position.x = self._robot_xy[0]
        feedback.base_position.pose.position.y = self._robot_xy[1]
        if tracked.behaviour.kind == "succeed" and fraction >= 1.0:
            feedback.base_position.pose.orientation = target.pose.orientation  # turned
        else:
            feedback.base_position.pose.orientation.w = 1.0
        tracked.handle.publish_feedback(feedback)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--action", default="move_base")
    parser.add_argument("--node-name", default="scripted_move_base")
    parser.add_argument("--script", default="", help="space-separated KIND[:SECONDS] per goal")
    parser.add_argument("--then", type=Behaviour.parse, default=Behaviour("succeed", 0.3))
    parser.add_argument("--log", type=Path)
    parser.add_argument(
        "--clear-costmaps", choices=("answer", "silent", "absent"), default="answer"
    )
    parser.add_argument("--clock", action="store_true", help="publish /clock (see doc)")
    parser.add_argument("--cancel", choices=("answer", "ignore"), default="answer")
    args = parser.parse_args(rospy.myargv()[1:])
    script = [Behaviour.parse(item) for item in args.script.split()]
    rospy.init_node(args.node_name)
    clock = JumpingClock() if args.clock else None
    server = ScriptedMoveBase(
        args.action, script, args.then, args.log, args.clear_costmaps, clock, args.cancel
    )
    server.log("ready")
    print("scripted move_base ready", flush=True)
    while not rospy.is_shutdown():
        server.step()
        time.sleep(FEEDBACK_PERIOD)


if __name__ == "__main__":
    main()
