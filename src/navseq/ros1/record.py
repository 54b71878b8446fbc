"""Record a mission by pointing: every pose that arrives on a topic becomes a waypoint.

Click RViz's "2D Nav Goal" (``/move_base_simple/goal``, geometry_msgs/PoseStamped) or
"2D Pose Estimate" (``/initialpose``, geometry_msgs/PoseWithCovarianceStamped) where the
robot should go, or drive the robot there and call the ``~record`` service (with
``from_tf``) to take its current TF pose. Positions are recorded to the millimetre and
yaws to the tenth of a degree. After **every** waypoint the whole mission is
written again (atomically: temporary file + rename), so Ctrl-C, a crash or a power cut
never loses what was recorded, and the file is always a valid navseq mission.

An existing file is never replaced unless ``overwrite`` is asked for; the file is only
created once the first waypoint arrives (a mission cannot be empty).

:func:`record_main` is what ``navseq record`` (:mod:`navseq.commands.record`) and the
``record_node`` ROS node (:func:`main`) run; rospy is imported only when recording starts.
"""

from __future__ import annotations

import math
import signal
import sys
import threading
import time
from pathlib import Path
from types import FrameType
from typing import Any

from navseq.errors import NavseqError, error_text
from navseq.geometry import Pose2D
from navseq.text import printable

DEFAULT_TOPIC = "/move_base_simple/goal"  # RViz's "2D Nav Goal"
NODE_NAME = "navseq_record"


def rounded_pose(pose: Pose2D) -> Pose2D:
    """A recorded pose to the millimetre and the tenth of a degree.

    TF and clicked poses carry noise far below what a robot reaches
    (``x: -1.8739253890256067``); the file should read like one a person wrote.
    """
    yaw = math.radians(round(math.degrees(pose.yaw), 1))
    return Pose2D(round(pose.x, 3) + 0.0, round(pose.y, 3) + 0.0, yaw + 0.0)  # no -0.0


class WaypointRecorder:
    """Appends poses to a mission and rewrites ``out`` after each one. Thread-safe."""

    def __init__(self, out: Path, *, overwrite: bool = False):
        self.out = out
        self._may_replace = overwrite
        self._lock = threading.Lock()
        self._waypoints: list[Any] = []
        self._frame: str | None = None
        if out.exists() and not overwrite:
            raise NavseqError(
                "exists already; not overwriting it (choose another file, or ask to overwrite)",
                source=str(out),
            )
        if out.is_dir() or not out.parent.is_dir():
            raise NavseqError("is not a file path in an existing folder", source=str(out))

    def __len__(self) -> int:
        return len(self._waypoints)

    def add(self, pose: Pose2D, frame: str, z: float = 0.0) -> int:
        """Record one waypoint and write the file; returns the waypoint count.

        Poses in a frame other than the first one's are refused (NavseqError): a
        mission has one frame, and silently mixing them would send the robot astray.
        """
        from navseq.mission import Mission, Waypoint, write_mission

        frame = frame or "map"
        with self._lock:
            if self._frame is not None and frame != self._frame:
                raise NavseqError(
                    f"pose in frame '{frame}' ignored: this mission is in '{self._frame}'",
                    source=str(self.out),
                    subject=f"waypoint {len(self._waypoints) + 1}",
                )
            self._frame = frame
            self._waypoints.append(Waypoint(x=pose.x, y=pose.y, yaw_rad=pose.yaw, z=z))
            mission = Mission(waypoints=tuple(self._waypoints), frame=frame, source=str(self.out))
            # The first write may replace a user's file only when asked; later ones
            # replace the file we wrote ourselves.
            write_mission(mission, self.out, overwrite=self._may_replace)
            self._may_replace = True
            return len(self._waypoints)


def record_main(
    out: Path,
    topic: str = DEFAULT_TOPIC,
    *,
    overwrite: bool = False,
    from_tf: bool = False,
    base_frame: str = "base_footprint",
    frame: str = "map",
) -> int:
    """Record waypoints from ``topic`` into ``out`` until interrupted; the exit status.

    The message type follows the topic: PoseWithCovarianceStamped for a topic named
    ``initialpose``, PoseStamped otherwise. With ``from_tf``, the service ``~record``
    (std_srvs/Trigger) also records the robot's current pose (TF ``frame`` ->
    ``base_frame``). Returns 0 after SIGINT/SIGTERM or a ROS shutdown, 2 for bad
    arguments (an existing file without ``overwrite``, no ROS master).
    """
    try:
        recorder = WaypointRecorder(Path(out), overwrite=overwrite)
    except NavseqError as error:
        print(f"navseq record: {error_text(error)}", file=sys.stderr)
        return 2

    import rospy
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
    from std_srvs.srv import Trigger, TriggerResponse

    from navseq.ros1.conversions import pose2d_from_pose, pose2d_from_transform
    from navseq.ros1.navigator import ensure_node

    try:
        ensure_node(NODE_NAME)
    except NavseqError as error:
        print(f"navseq record: {error_text(error)}", file=sys.stderr)
        return 2

    def record(pose: Pose2D, pose_frame: str, z: float, origin: str) -> str:
        pose, z = rounded_pose(pose), round(z, 3)
        try:
            count = recorder.add(pose, pose_frame, z)
        except NavseqError as error:
            rospy.logwarn("navseq record: %s", error)
            return str(error)
        message = (
            f"waypoint {count}: x={pose.x:.3f} y={pose.y:.3f} "
            f"yaw={math.degrees(pose.yaw):.1f} deg ({origin}) -> {recorder.out}"
        )
        rospy.loginfo("navseq record: %s", message)
        return message

    def on_pose(message: Any) -> None:
        pose = message.pose.pose if hasattr(message.pose, "covariance") else message.pose
        record(pose2d_from_pose(pose), message.header.frame_id, pose.position.z, topic)

    message_type = (
        PoseWithCovarianceStamped if topic.rstrip("/").endswith("initialpose") else (PoseStamped)
    )
    rospy.Subscriber(topic, message_type, on_pose, queue_size=10)

    if from_tf:
        import tf2_ros

        buffer = tf2_ros.Buffer()
        tf2_ros.TransformListener(buffer)

        def on_record(_request: Any) -> TriggerResponse:
            try:
                transform = buffer.lookup_transform(
                    frame, base_frame, rospy.Time(0), rospy.Duration(1.0)
                )
            except Exception as error:  # tf2's exceptions share no useful base
                return TriggerResponse(False, f"no TF {frame} -> {base_frame}: {error}")
            text = record(pose2d_from_transform(transform), frame, 0.0, "TF")
            return TriggerResponse(text.startswith("waypoint"), text)

        rospy.Service("~record", Trigger, on_record)

    rospy.loginfo(
        "navseq record: recording %s%s into %s; Ctrl-C to stop",
        topic,
        " and ~record (TF)" if from_tf else "",
        recorder.out,
    )
    print("navseq record: ready", flush=True)

    def stop(signum: int, frame_: FrameType | None) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        while not rospy.is_shutdown():
            time.sleep(0.1)
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
    count = len(recorder)
    print(
        f"navseq record: {count} waypoint{'s' if count != 1 else ''} "
        + (f"saved in {printable(str(recorder.out))}" if count else "recorded; no file written"),
        flush=True,
    )
    rospy.signal_shutdown("recording finished")
    return 0


# -- `rosrun navseq record_node` --------------------------------------------------------


def main() -> None:
    """ROS node: ``~out`` (required), ``~topic``, ``~overwrite``, ``~from_tf``, ``~base_frame``."""
    import rospy

    from navseq.ros1.navigator import ensure_node
    from navseq.ros1.params import bool_param

    try:
        ensure_node(NODE_NAME, anonymous=False)
        out = rospy.get_param("~out", "")
        if not out:
            raise NavseqError("give the mission file to write", source="param ~out")
        # roslaunch passes <param value="false"/> as a string: bool("false") would be True.
        overwrite = bool_param("overwrite", False)
        from_tf = bool_param("from_tf", False)
    except NavseqError as error:
        print(f"navseq record: {error_text(error)}", file=sys.stderr)
        sys.exit(2)
    sys.exit(
        record_main(
            Path(out),
            rospy.get_param("~topic", DEFAULT_TOPIC),
            overwrite=overwrite,
            from_tf=from_tf,
            base_frame=rospy.get_param("~base_frame", "base_footprint"),
            frame=rospy.get_param("~frame", "map"),
        )
    )


if __name__ == "__main__":
    main()
