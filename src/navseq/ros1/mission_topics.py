"""A mission's progress on ROS topics: waypoint markers for RViz and a JSON status.

Used by the navseq node (topics ``~waypoints`` and ``~status``) and by
``navseq run --navigator ros1`` (``/navseq/waypoints`` and ``/navseq/status``, under the
robot namespace if one is given), so RViz shows the same markers whichever runs the
mission. Both topics are latched: RViz shows them whenever it connects.
"""

from __future__ import annotations

import rosgraph.names
import rospy
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from navseq.mission.model import Mission
from navseq.ros1.markers import marker_message
from navseq.sinks.mission_status import MarkerStatus, StatusPublisher

RUN_TOPICS_NS = "navseq"  # where `navseq run` publishes, like the node named navseq


class MissionTopics(StatusPublisher):
    """A mission listener publishing ``<ns>/status`` (JSON) and ``<ns>/waypoints`` (markers).

    ``namespace`` is ``~`` for a node's private topics, or a name such as ``/navseq``.
    What is shown is :class:`~navseq.sinks.mission_status.MissionStatus`'s (shared with
    ROS 2); ``active_waypoint`` and ``over`` are its.
    """

    def __init__(self, mission: Mission, namespace: str = "~"):
        super().__init__(mission)
        self.mission = mission
        prefix = "~" if namespace == "~" else namespace.rstrip("/") + "/"
        self._status_pub = rospy.Publisher(f"{prefix}status", String, queue_size=10, latch=True)
        self._marker_pub = rospy.Publisher(
            f"{prefix}waypoints", MarkerArray, queue_size=2, latch=True
        )
        self.publish_all()

    @property
    def statuses(self) -> dict[int, MarkerStatus]:
        return self.state.statuses

    @property
    def active_waypoint(self) -> int | None:
        """0-based index of the visit underway, None between visits."""
        return self.state.active_waypoint

    @property
    def over(self) -> str | None:
        """Set once the mission is over for good; the services then refuse with it."""
        return self.state.over

    @over.setter
    def over(self, why: str | None) -> None:
        self.state.over = why

    @property
    def topics(self) -> tuple[str, str]:
        """The resolved names of the marker and status topics."""
        return self._marker_pub.resolved_name, self._status_pub.resolved_name

    def publish_markers(self) -> None:
        stamp = rospy.Time(0)
        specs = self.state.markers()
        self._marker_pub.publish(MarkerArray(markers=[marker_message(s, stamp) for s in specs]))

    def publish_status_text(self, text: str) -> None:
        self._status_pub.publish(String(data=text))


def run_topics_namespace(robot_ns: str) -> str:
    """Where ``navseq run`` publishes: ``/navseq``, or ``/robot1/navseq`` with ``--ns robot1``."""
    return (
        rosgraph.names.ns_join("/" + robot_ns.strip("/"), RUN_TOPICS_NS)
        if robot_ns.strip("/")
        else "/" + RUN_TOPICS_NS
    )
