#!/usr/bin/env python3
"""A scripted Nav2 ``navigate_to_pose`` server: the ROS 2 twin of ``ros_scripted_server.py``.

Each goal it receives, in arrival order, follows the next behaviour of ``--script``
(then ``--then`` for every later goal); a behaviour is ``KIND[:SECONDS]``, with the same
kinds and meanings as the ROS 1 server: ``succeed`` (feedback at the goal, then
SUCCEEDED after SECONDS), ``reject``, ``hang``, ``die`` (the process exits abruptly
after SECONDS) and ``jump`` (``/clock`` goes back by ``JUMP_BACK`` after SECONDS, then
like ``hang``; needs ``--clock``). A goal that is not running to its end is CANCELED
when a cancel is asked for.

``--clock`` publishes ``/clock`` from ``CLOCK_START`` s at wall speed (navseq then runs
on it: use_sim_time follows a published ``/clock``). ``--cancel ignore``: cancel
requests are taken but never answered (a wedged server). Every goal, cancel and result
goes to stdout as a JSON line; ``{"event": "ready"}`` first. Real rclpy; run it with
``ros2_support.ros2_environment``.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import signal
import threading
import time
from typing import Any

import rclpy
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock

KINDS = ("succeed", "reject", "hang", "die", "jump")
CLOCK_START = 100.0
JUMP_BACK = 90.0
CLOCK_PERIOD = 0.01
FEEDBACK_PERIOD = 0.1


def say(event: str, **fields: Any) -> None:
    print(json.dumps({"event": event, "t": time.monotonic(), **fields}), flush=True)


def parse(text: str) -> tuple[str, float]:
    kind, _, seconds = text.partition(":")
    if kind not in KINDS:
        raise argparse.ArgumentTypeError(f"unknown behaviour {kind!r}; one of {KINDS}")
    return kind, float(seconds) if seconds else 0.3


class ScriptedNav2:
    def __init__(
        self,
        node: Any,
        script: list[tuple[str, float]],
        then: tuple[str, float],
        clock: bool,
        cancel: str,
        stop: threading.Event,
    ) -> None:
        self.node = node
        self.script = collections.deque(script)
        self.then = then
        self.stop = stop
        self.cancel = cancel
        self.accepted: collections.deque[tuple[str, float]] = collections.deque()
        self.lock = threading.Lock()
        self.zero = time.monotonic() - CLOCK_START
        group = ReentrantCallbackGroup()
        if clock:
            self.clock_pub = node.create_publisher(Clock, "/clock", 10)
            threading.Thread(target=self._publish_clock, daemon=True).start()
        ActionServer(
            node,
            NavigateToPose,
            "navigate_to_pose",
            self.execute,
            goal_callback=self.on_goal,
            cancel_callback=self.on_cancel,
            callback_group=group,
        )

    def _publish_clock(self) -> None:
        while not self.stop.is_set():
            seconds = time.monotonic() - self.zero
            message = Clock()
            message.clock.sec = int(seconds)
            message.clock.nanosec = int((seconds % 1.0) * 1e9)
            self.clock_pub.publish(message)
            time.sleep(CLOCK_PERIOD)

    def on_goal(self, goal: Any) -> GoalResponse:
        with self.lock:
            behaviour = self.script.popleft() if self.script else self.then
            pose = goal.pose.pose.position
            say("goal", kind=behaviour[0], x=pose.x, y=pose.y)
            if behaviour[0] == "reject":
                return GoalResponse.REJECT
            self.accepted.append(behaviour)
            return GoalResponse.ACCEPT

    def on_cancel(self, _handle: Any) -> CancelResponse:
        if self.cancel == "ignore":
            say("cancel_ignored")
            self.stop.wait()  # never answers while the test runs
        say("cancel")
        return CancelResponse.ACCEPT

    def execute(self, handle: Any) -> Any:
        with self.lock:
            kind, seconds = self.accepted.popleft()
        start = time.monotonic()
        feedback = NavigateToPose.Feedback()
        jumped = False
        while not self.stop.is_set():
            elapsed = time.monotonic() - start
            if handle.is_cancel_requested:
                handle.canceled()
                say("done", status="CANCELED")
                return NavigateToPose.Result()
            if not handle.is_active:
                return NavigateToPose.Result()  # preempted by a newer goal
            # Like the ROS 1 server: the robot at the goal once it succeeds, else at the origin.
            feedback.current_pose.header = handle.request.pose.header
            if kind == "succeed":
                feedback.current_pose = handle.request.pose
            handle.publish_feedback(feedback)
            if kind == "succeed":
                if elapsed >= seconds:
                    time.sleep(FEEDBACK_PERIOD)  # the feedback at the goal goes first
                    handle.succeed()
                    say("done", status="SUCCEEDED")
                    return NavigateToPose.Result()
            elif kind == "die" and elapsed >= seconds:
                say("die")
                os._exit(3)
            elif kind == "jump" and elapsed >= seconds and not jumped:
                jumped = True
                self.zero += JUMP_BACK
                say("jump", back=JUMP_BACK)
            time.sleep(FEEDBACK_PERIOD)
        return NavigateToPose.Result()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--script", default="")
    parser.add_argument("--then", type=parse, default=("succeed", 0.3))
    parser.add_argument("--clock", action="store_true")
    parser.add_argument("--cancel", choices=("answer", "ignore"), default="answer")
    args = parser.parse_args()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("scripted_nav2")
    stop = threading.Event()
    script = [parse(item) for item in args.script.split()]
    ScriptedNav2(node, script, args.then, args.clock, args.cancel, stop)
    executor = MultiThreadedExecutor(num_threads=8)
    executor.add_node(node)
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    threading.Thread(target=executor.spin, daemon=True).start()
    say("ready")
    stop.wait()
    executor.shutdown(timeout_sec=1)


if __name__ == "__main__":
    main()
