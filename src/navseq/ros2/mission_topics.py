"""A mission's progress on ROS 2 topics: waypoint markers for RViz 2 and a JSON status.

The ROS 2 twin of :mod:`navseq.ros1.mission_topics`; what is shown is decided once for
both in :mod:`navseq.sinks.mission_status`. Both topics are *transient local* with a
depth of one — ROS 2's latching: RViz 2, or ``ros2 topic echo --qos-durability
transient_local``, gets the last markers and status whenever it subscribes.
"""

from __future__ import annotations

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import ColorRGBA, String
from visualization_msgs.msg import Marker, MarkerArray

from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.ros2.messages import pose_msg
from navseq.sinks.mission_status import MarkerKind, MarkerSpec, StatusPublisher

# ROS 2's "latched": the last message is kept for subscribers that come later.
LATCHED = QoSProfile(
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
_KINDS = {MarkerKind.ARROW: Marker.ARROW, MarkerKind.LABEL: Marker.TEXT_VIEW_FACING}


def marker_message(spec: MarkerSpec) -> Marker:
    """The ``visualization_msgs/msg/Marker`` of one :class:`MarkerSpec`.

    Stamp zero: "the latest transform", so RViz 2 shows markers published long ago.
    """
    marker = Marker()
    marker.header.frame_id = spec.frame
    marker.ns = spec.namespace
    marker.id = spec.id
    marker.type = _KINDS[spec.kind]
    marker.action = Marker.ADD
    marker.pose = pose_msg(Pose2D(spec.x, spec.y, spec.yaw))
    marker.pose.position.z = float(spec.z)
    marker.scale.x, marker.scale.y, marker.scale.z = (float(v) for v in spec.scale)
    r, g, b, a = spec.colour
    marker.color = ColorRGBA(r=r, g=g, b=b, a=a)
    marker.text = spec.text
    return marker


class MissionTopics(StatusPublisher):
    """A mission listener publishing ``~/waypoints`` (markers) and ``~/status`` (JSON).

    Publishing is thread-safe in rclpy: the run's thread publishes while the node's
    executor spins elsewhere.
    """

    def __init__(self, node: Node, mission: Mission, prefix: str = "~/") -> None:
        super().__init__(mission)
        self._marker_pub = node.create_publisher(MarkerArray, f"{prefix}waypoints", LATCHED)
        self._status_pub = node.create_publisher(String, f"{prefix}status", LATCHED)
        self.publish_all()

    @property
    def topics(self) -> tuple[str, str]:
        """The resolved names of the marker and status topics."""
        return self._marker_pub.topic_name, self._status_pub.topic_name

    def publish_markers(self) -> None:
        specs = self.state.markers()
        self._marker_pub.publish(MarkerArray(markers=[marker_message(s) for s in specs]))

    def publish_status_text(self, text: str) -> None:
        self._status_pub.publish(String(data=text))
