"""opennav_docking's interface on the ROS 2 simulator node: ``dock_robot`` and
``undock_robot`` (``nav2_msgs/action/DockRobot`` / ``UndockRobot``: Jazzy's nav2_msgs
carry them, there is no separate opennav_docking_msgs), ``docking_server/reload_database``
(``nav2_msgs/srv/ReloadDockDatabase``) and the dock plugin's ``dock_pose`` and
``staging_pose`` topics (``geometry_msgs/PoseStamped``, published when a docking starts).
While a docking perceives and approaches its dock, every feedback period: the
simulated detector's ``detected_dock_pose`` (in ``base_link``) and the dock plugin's
``filtered_dock_pose`` (in ``odom``), and while the docking controller drives (docking
or undocking) its projected ``docking_trajectory`` (``nav_msgs/Path`` in ``base_link``);
see :mod:`navseq.ros2.docking`.

The rules are :class:`navseq.ros2.docking.DockingServer`'s (the stand-in steps it with
the robot); this module translates goals, feedback (``state``, ``docking_time``,
``num_retries``, every 0.1 s of wall time) and results (``success``, ``error_code``,
``num_retries``; Nav2 logs the reason and leaves ``error_msg`` empty, so does this).
A dock pose in a frame the node cannot transform ends with ``UNKNOWN`` (Nav2's
transform error).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from pathlib import Path as FilePath
from typing import Any

from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import DockRobot, UndockRobot
from nav2_msgs.srv import ReloadDockDatabase
from nav_msgs.msg import Path
from rclpy.node import Node

from navseq.errors import NavseqError, error_text
from navseq.geometry import Pose2D
from navseq.ros2.docking import DockError, DockingGoal, DockingServer
from navseq.ros2.lifecycle import Nav2Lifecycle
from navseq.ros2.messages import duration_msg, finish_goal, pose_stamped
from navseq.ros2.standin import Nav2StandIn, Outcome
from navseq.sim.docks import Dock, read_docks_file

FEEDBACK_PERIOD = 0.1  # s of wall time between two feedback messages

InMap = Callable[[PoseStamped], Pose2D | str]


class DockingActions:
    """The docking server's actions, service and topics on ``node``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        lifecycle: Nav2Lifecycle,
        *,
        docks: Sequence[Dock],
        in_map: InMap,
        stamp: Callable[[], Any],
        frame: str,
        base_frame: str = "base_link",
        odom_frame: str = "odom",
    ) -> None:
        self._standin = standin
        self._base_frame = base_frame
        self._odom_frame = odom_frame
        self._lock = lock
        self._in_map = in_map
        self._stamp = stamp
        self._frame = frame
        self._log = node.get_logger()
        self.server = DockingServer(standin, docks)
        standin.drivers.append(self.server)
        self._dock_pose_pub = node.create_publisher(PoseStamped, "dock_pose", 1)
        self._staging_pose_pub = node.create_publisher(PoseStamped, "staging_pose", 1)
        self._detected_pub = node.create_publisher(PoseStamped, "detected_dock_pose", 1)
        self._filtered_pub = node.create_publisher(PoseStamped, "filtered_dock_pose", 1)
        self._trajectory_pub = node.create_publisher(Path, "docking_trajectory", 1)
        self.servers = lifecycle.action_servers(
            node,
            group,
            self._log.info,
            [
                (DockRobot, "dock_robot", self._execute_dock),
                (UndockRobot, "undock_robot", self._execute_undock),
            ],
        )
        node.create_service(
            ReloadDockDatabase,
            "docking_server/reload_database",
            self._reload,
            callback_group=group,
        )
        self._log.info(
            f"docking_server: {len(docks)} dock(s)"
            + (f": {', '.join(dock.name for dock in docks)}" if docks else "")
        )

    def _execute_dock(self, handle: Any) -> Any:
        request = handle.request
        with self._lock:
            now = self._standin.time
            if request.use_dock_id:
                self._log.info(f"Attempting to dock robot at {request.dock_id}.")
                goal = self.server.dock(
                    now,
                    dock_id=request.dock_id,
                    navigate_to_staging=bool(request.navigate_to_staging_pose),
                    max_staging_time=float(request.max_staging_time),
                )
            else:
                pose = self._in_map(request.dock_pose)
                if isinstance(pose, str):
                    goal = DockingGoal(undock=False, started=now)
                    goal.log = f"Transform error: {pose}"
                    goal.end(Outcome.ABORTED, DockError.UNKNOWN, success=False)
                else:
                    self._log.info(
                        f"Attempting to dock robot at position ({pose.x:.2f}, {pose.y:.2f})."
                    )
                    goal = self.server.dock(
                        now,
                        dock_id=None,
                        dock_pose=pose,
                        dock_type=request.dock_type,
                        navigate_to_staging=bool(request.navigate_to_staging_pose),
                        max_staging_time=float(request.max_staging_time),
                    )
            if goal.dock is not None:
                stamp = self._stamp()
                self._dock_pose_pub.publish(pose_stamped(goal.dock.pose, self._frame, stamp))
                staging = self.server.staging_pose(goal.dock.pose)
                self._staging_pose_pub.publish(pose_stamped(staging, self._frame, stamp))
        sent = 0
        while True:
            ended = goal.done.wait(FEEDBACK_PERIOD)
            if not ended and handle.is_cancel_requested:
                self._log.warning("Goal was cancelled. Cancelling dock_robot action")
                with self._lock:
                    self.server.cancel(goal)
                ended = True
            # One message per state entered (Nav2 publishes at each), then the current
            # state every period.
            with self._lock:
                states = goal.states[sent:] or ([] if ended else [goal.state])
                sent = len(goal.states)
                elapsed = duration_msg(self._standin.time - goal.started)
            for state in states:
                handle.publish_feedback(
                    DockRobot.Feedback(state=int(state), docking_time=elapsed, num_retries=0)
                )
            if not ended:
                self._publish_sensing()
            if ended:
                break
        result = DockRobot.Result()
        result.num_retries = 0
        return self._finish(handle, goal, result)

    def _execute_undock(self, handle: Any) -> Any:
        request = handle.request
        with self._lock:
            goal = self.server.undock(
                self._standin.time,
                dock_type=request.dock_type,
                max_time=float(request.max_undocking_time),
            )
        self._log.info("Attempting to undock robot.")
        while not goal.done.wait(FEEDBACK_PERIOD):
            if handle.is_cancel_requested:
                self._log.warning("Goal was cancelled. Cancelling undock_robot action")
                with self._lock:
                    self.server.cancel(goal)
                break
            self._publish_sensing()
        return self._finish(handle, goal, UndockRobot.Result())

    def _publish_sensing(self) -> None:
        """The detector's sighting, the filtered dock pose and the controller's
        trajectory, for what the docking does now."""
        with self._lock:
            world, localization = self._standin.world, self._standin.localization
            robot = world.robot.pose
            sighting = self.server.sighting(self._standin.time, robot, localization.odom_pose)
            trajectory = self.server.trajectory(robot)
        stamp = self._stamp()
        if sighting is not None:
            self._detected_pub.publish(pose_stamped(sighting.detected, self._base_frame, stamp))
            self._filtered_pub.publish(pose_stamped(sighting.filtered, self._odom_frame, stamp))
        if trajectory is not None:
            path = Path()
            path.header.frame_id = self._base_frame
            path.header.stamp = stamp
            path.poses = [pose_stamped(pose, self._base_frame, stamp) for pose in trajectory]
            self._trajectory_pub.publish(path)

    def _finish(self, handle: Any, goal: DockingGoal, result: Any) -> Any:
        result.success = goal.success
        result.error_code = int(goal.error_code)
        if goal.log:
            failed = goal.error_code != DockError.NONE
            (self._log.error if failed else self._log.info)(goal.log)
        assert goal.outcome is not None
        finish_goal(handle, goal.outcome.value)
        return result

    def _reload(self, request: Any, response: Any) -> Any:
        """Replace the docks with the file's (Nav2 refuses while docking)."""
        with self._lock:
            busy = self.server.active is not None
        if busy:
            self._log.error("Cannot reload database while docking!")
            response.success = False
            return response
        try:
            docks = read_docks_file(FilePath(request.filepath))
        except NavseqError as error:
            self._log.error(f"docking_server: {error_text(error)}")
            response.success = False
            return response
        with self._lock:
            self.server.docks = {dock.name: dock for dock in docks}
        self._log.info(f"Dock database reloaded from file {request.filepath}.")
        response.success = True
        return response


__all__ = ["DockingActions"]
