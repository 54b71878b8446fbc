"""The planner, smoother and controller servers' actions on the ROS 2 simulator node.

What a Nav2 client that plans, smooths and follows paths itself asks (nav2_simple_commander's
``getPath``, ``getPathThroughPoses``, ``smoothPath``, ``followPath``; a behaviour tree's
``ComputePathToPose`` / ``FollowPath`` nodes), with nav2_bringup's plugin ids:

- ``compute_path_to_pose`` and ``compute_path_through_poses`` (planner ``GridBased``):
  the simulator's planner from the robot (or ``start`` with ``use_start``) through each
  goal in turn; the planner's error codes (2xx, and 3xx through poses, in the same order;
  ``NO_VIAPOINTS_GIVEN`` without goals, ``TF_ERROR`` for a pose in a frame the node
  does not know, ``INVALID_PLANNER`` for another planner id);
- ``smooth_path`` (smoother ``simple_smoother``): :mod:`navseq.sim.smoother`; the
  smoothed path also on ``plan_smoothed`` (``nav_msgs/Path``, depth 1, as Nav2's
  smoother server publishes it: once smoothed, before the collision check);
  ``was_completed`` false when it did not settle (the path comes back unchanged);
  ``SMOOTHED_PATH_IN_COLLISION`` when ``check_for_collisions`` finds the robot's
  footprint on an obstacle along it; ``INVALID_PATH`` for an empty path;
- ``follow_path`` (controller ``FollowPath``, goal checker ``general_goal_checker``,
  progress checker ``progress_checker``): the simulator's controller drives the path as
  given, without re-planning; feedback ``distance_to_goal`` and ``speed``; the
  controller's codes (``NO_VALID_CONTROL`` when the robot cannot go on,
  ``INVALID_PATH`` for an empty path, ``INVALID_CONTROLLER`` for unknown ids). It takes
  the controller from a running navigation goal, which ends ABORTED.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import ComputePathThroughPoses, ComputePathToPose, FollowPath, SmoothPath
from nav_msgs.msg import Path
from rclpy.node import Node

from navseq.geometry import Pose2D
from navseq.ros2.lifecycle import Nav2Lifecycle
from navseq.ros2.messages import duration_msg, finish_goal, path_msg, pose_stamped, seconds_of
from navseq.ros2.standin import Ending, Nav2StandIn, Outcome
from navseq.sim.planner import Plan
from navseq.sim.smoother import headings, smooth_path

#: nav2_bringup's plugin ids: a goal naming another one is refused as Nav2 refuses it.
PLANNER_IDS = ("", "GridBased")
SMOOTHER_IDS = ("", "simple_smoother")
CONTROLLER_IDS = ("", "FollowPath")
GOAL_CHECKER_IDS = ("", "general_goal_checker")
PROGRESS_CHECKER_IDS = ("", "progress_checker")
FEEDBACK_PERIOD = 0.1  # s of wall time between two follow_path feedback messages

#: Where a pose's frame leads: the pose in the map frame, or why it cannot be used.
InMap = Callable[[PoseStamped], Pose2D | str]


class PathActions:
    """The four actions on ``node``, acting on ``standin`` under ``lock``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        in_map: InMap,
        stamp: Callable[[], Any],
        frame: str,
        lifecycle: Nav2Lifecycle,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._in_map = in_map
        self._stamp = stamp
        self._frame = frame
        self._log = node.get_logger()
        self._smoothed_pub = node.create_publisher(Path, "plan_smoothed", 1)
        handlers: list[tuple[Any, str, Callable[[Any], Any]]] = [
            (ComputePathToPose, "compute_path_to_pose", self._compute_path),
            (ComputePathThroughPoses, "compute_path_through_poses", self._compute_through),
            (SmoothPath, "smooth_path", self._smooth),
            (FollowPath, "follow_path", self._follow),
        ]
        self.servers = lifecycle.action_servers(node, group, self._log.info, handlers)

    # -- planner_server --------------------------------------------------------------

    def _compute_path(self, handle: Any) -> Any:
        request = handle.request
        return self._plan(handle, ComputePathToPose.Result(), request, [request.goal], offset=0)

    def _compute_through(self, handle: Any) -> Any:
        request = handle.request
        result = ComputePathThroughPoses.Result()
        if not request.goals:
            result.error_code = ComputePathThroughPoses.Result.NO_VIAPOINTS_GIVEN
            result.error_msg = "no goals given"
            handle.abort()
            return result
        return self._plan(handle, result, request, list(request.goals), offset=100)

    def _plan(
        self, handle: Any, result: Any, request: Any, goals: Sequence[PoseStamped], offset: int
    ) -> Any:
        """Plan through ``goals``; ``offset`` turns the planner's 2xx codes into the
        action's own (3xx through poses)."""
        started = time.monotonic()
        codes = type(result)
        if request.planner_id not in PLANNER_IDS:
            result.error_code = codes.INVALID_PLANNER
            result.error_msg = f"planner id {request.planner_id!r} is not one of {PLANNER_IDS[1:]}"
            handle.abort()
            return result
        with self._lock:
            plan, goal, failure = self._plan_through(request, goals)
        result.planning_time = duration_msg(time.monotonic() - started)
        if failure is not None:
            code, text = failure
            result.error_code = code + offset if code else codes.TF_ERROR
            result.error_msg = text
            handle.abort()
            return result
        assert plan is not None and goal is not None
        result.path = path_msg(plan, goal, self._frame, self._stamp())
        handle.succeed()
        return result

    def _plan_through(
        self, request: Any, goals: Sequence[PoseStamped]
    ) -> tuple[Plan | None, Pose2D | None, tuple[int, str] | None]:
        """One plan through every goal (call with the lock); a failure is (planner code,
        text), code 0 meaning a pose the node cannot transform."""
        start = self._in_map(request.start) if request.use_start else self._robot()
        if isinstance(start, str):
            return None, None, (0, f"start: {start}")
        pieces: list[Plan] = []
        goal: Pose2D | None = None
        for index, raw in enumerate(goals):
            goal_or_why = self._in_map(raw)
            if isinstance(goal_or_why, str):
                return (
                    None,
                    None,
                    (0, f"goal {index}: {goal_or_why}" if len(goals) > 1 else goal_or_why),
                )
            goal = goal_or_why
            plan = self._standin.world.server.make_plan(start, goal)
            if plan is None:
                return None, None, self._standin.no_plan_reason(start, goal)
            pieces.append(plan)
            start = goal
        return _joined(pieces), goal, None

    def _robot(self) -> Pose2D:
        # Where the robot believes it is, as Nav2's planner takes the start from TF.
        return self._standin.localization.believed_pose

    # -- smoother_server -------------------------------------------------------------

    def _smooth(self, handle: Any) -> Any:
        request = handle.request
        result = SmoothPath.Result()
        started = time.monotonic()
        if request.smoother_id not in SMOOTHER_IDS:
            result.error_code = SmoothPath.Result.INVALID_SMOOTHER
            result.error_msg = (
                f"smoother id {request.smoother_id!r} is not one of {SMOOTHER_IDS[1:]}"
            )
            handle.abort()
            return result
        with self._lock:
            poses = self._path_in_map(request.path)
        if isinstance(poses, str) or not poses:
            result.error_code = SmoothPath.Result.INVALID_PATH
            result.error_msg = poses if isinstance(poses, str) else "the path has no poses"
            handle.abort()
            return result
        points = np.array([(pose.x, pose.y) for pose in poses])
        smoothed = smooth_path(points)
        yaws = headings(smoothed.points, poses[-1].yaw)
        result.smoothing_duration = duration_msg(time.monotonic() - started)
        result.was_completed = smoothed.completed
        stamp = self._stamp()
        result.path.header.frame_id = self._frame
        result.path.header.stamp = stamp
        smoothed_poses = [
            Pose2D(float(x), float(y), float(yaw))
            for (x, y), yaw in zip(smoothed.points, yaws, strict=True)
        ]
        result.path.poses = [pose_stamped(pose, self._frame, stamp) for pose in smoothed_poses]
        allowed = seconds_of(request.max_smoothing_duration)
        timed_out = allowed > 0 and seconds_of(result.smoothing_duration) > allowed
        if not timed_out:  # Nav2's smoother throws on a timeout, before publishing
            self._smoothed_pub.publish(result.path)
        if request.check_for_collisions:
            with self._lock:
                collides = self._standin.world.body.collides
                hit = next((pose for pose in smoothed_poses if collides(pose)), None)
            if hit is not None:
                result.error_code = SmoothPath.Result.SMOOTHED_PATH_IN_COLLISION
                result.error_msg = f"the smoothed path collides at ({hit.x:.2f}, {hit.y:.2f})"
                handle.abort()
                return result
        if timed_out:
            result.error_code = SmoothPath.Result.TIMEOUT
            result.error_msg = "smoothing took longer than max_smoothing_duration"
            handle.abort()
            return result
        handle.succeed()
        return result

    def _path_in_map(self, path: Any) -> list[Pose2D] | str:
        """The path's poses in the map frame (each in the path's frame unless it names
        its own), or why not (call with the lock)."""
        found: list[Pose2D] = []
        for index, pose in enumerate(path.poses):
            if not pose.header.frame_id:
                pose.header.frame_id = path.header.frame_id
            planar = self._in_map(pose)
            if isinstance(planar, str):
                return f"pose {index}: {planar}"
            found.append(planar)
        return found

    # -- controller_server -----------------------------------------------------------

    def _follow(self, handle: Any) -> Any:
        request = handle.request
        result = FollowPath.Result()
        unknown = _unknown_id(request)
        if unknown is not None:
            result.error_code = FollowPath.Result.INVALID_CONTROLLER
            result.error_msg = unknown
            handle.abort()
            return result
        with self._lock:
            poses = self._path_in_map(request.path)
            if isinstance(poses, str):
                task = None
                ending = Ending(Outcome.ABORTED, FollowPath.Result.TF_ERROR, poses)
            else:
                points = np.array([(pose.x, pose.y) for pose in poses]).reshape(-1, 2)
                goal = poses[-1] if poses else self._robot()
                task = self._standin.follow_path(points, goal)
        if task is not None:
            self._log.info(f"follow_path: {len(points)} poses")
            feedback = FollowPath.Feedback()
            while not task.done.wait(FEEDBACK_PERIOD):
                if handle.is_cancel_requested:
                    with self._lock:
                        self._standin.cancel(task)
                    break
                with self._lock:
                    numbers = self._standin.feedback(task)
                    speed = self._standin.world.robot.v
                feedback.distance_to_goal = float(numbers.distance_remaining)
                feedback.speed = float(speed)
                handle.publish_feedback(feedback)
            assert task.ending is not None
            ending = task.ending
        result.error_code = int(ending.error_code)
        result.error_msg = ending.error_msg
        if finish_goal(handle, ending.outcome.value) == "ABORTED":
            self._log.info(f"follow_path: ABORTED {ending.error_msg}")
        return result


def _unknown_id(request: Any) -> str | None:
    """Why a ``follow_path`` goal names a plugin the controller server does not have."""
    for value, known, what in (
        (request.controller_id, CONTROLLER_IDS, "controller"),
        (request.goal_checker_id, GOAL_CHECKER_IDS, "goal checker"),
        (request.progress_checker_id, PROGRESS_CHECKER_IDS, "progress checker"),
    ):
        if value not in known:
            return f"{what} id {value!r} is not one of {known[1:]}"
    return None


def _joined(pieces: Sequence[Plan]) -> Plan:
    """Plans end to end as one (each piece starts where the last one ended)."""
    points = np.vstack([pieces[0].points, *(piece.points[1:] for piece in pieces[1:])])
    return Plan(
        points=points,
        length=float(sum(piece.length for piece in pieces)),
        cost=float(sum(piece.cost for piece in pieces)),
    )


__all__ = ["PathActions"]
