"""RViz markers for a mission: one arrow and one number per waypoint, coloured by status.

The marker array is rebuilt from scratch on every change (a mission has tens of
waypoints, not thousands) and published latched, so RViz shows it whenever it connects.
Every marker is in namespace ``navseq_waypoints`` (arrows) or ``navseq_labels`` (text),
with the waypoint index as id, so a rebuilt array replaces the previous one in place.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping

import rospy
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from navseq.mission.model import Mission
from navseq.ros1.conversions import pose_from_pose2d

ARROW_NS = "navseq_waypoints"
LABEL_NS = "navseq_labels"


class MarkerStatus(str, enum.Enum):
    PENDING = "pending"  # not tried yet (in this loop)
    ACTIVE = "active"  # the robot is on its way there
    REACHED = "reached"
    SKIPPED = "skipped"
    FAILED = "failed"


# RGBA: grey for what is to come, blue for the current goal, green / orange / red for
# outcomes — the colours roboticists expect from traffic lights.
STATUS_COLOURS: dict[MarkerStatus, tuple[float, float, float, float]] = {
    MarkerStatus.PENDING: (0.6, 0.6, 0.6, 0.9),
    MarkerStatus.ACTIVE: (0.1, 0.45, 1.0, 1.0),
    MarkerStatus.REACHED: (0.1, 0.75, 0.2, 1.0),
    MarkerStatus.SKIPPED: (1.0, 0.6, 0.0, 1.0),
    MarkerStatus.FAILED: (0.9, 0.1, 0.1, 1.0),
}


def _colour(status: MarkerStatus) -> ColorRGBA:
    r, g, b, a = STATUS_COLOURS[status]
    return ColorRGBA(r=r, g=g, b=b, a=a)


def waypoint_markers(
    mission: Mission,
    statuses: Mapping[int, MarkerStatus],
    *,
    stamp: rospy.Time | None = None,
    arrow_length: float = 0.35,
    text_height: float = 0.18,
) -> MarkerArray:
    """Markers for every waypoint of ``mission``; ``statuses`` maps index -> status.

    Waypoints missing from ``statuses`` are PENDING. Labels read ``3`` or ``3 dock``
    (1-based, like navseq's messages) and float above the arrow.
    """
    array = MarkerArray()
    stamp = stamp if stamp is not None else rospy.Time(0)
    for index, waypoint in enumerate(mission.waypoints):
        status = statuses.get(index, MarkerStatus.PENDING)
        arrow = Marker()
        arrow.header.frame_id = mission.frame
        arrow.header.stamp = stamp
        arrow.ns = ARROW_NS
        arrow.id = index
        arrow.type = Marker.ARROW
        arrow.action = Marker.ADD
        arrow.pose = pose_from_pose2d(waypoint.pose, waypoint.z)
        arrow.scale.x = arrow_length
        arrow.scale.y = arrow_length * 0.2
        arrow.scale.z = arrow_length * 0.2
        arrow.color = _colour(status)
        array.markers.append(arrow)

        label = Marker()
        label.header = arrow.header
        label.ns = LABEL_NS
        label.id = index
        label.type = Marker.TEXT_VIEW_FACING
        label.action = Marker.ADD
        label.pose.position.x = waypoint.x
        label.pose.position.y = waypoint.y
        label.pose.position.z = waypoint.z + 0.25
        label.pose.orientation.w = 1.0
        label.scale.z = text_height
        label.color = _colour(status)
        label.text = str(index + 1) + (f" {waypoint.name}" if waypoint.name else "")
        array.markers.append(label)
    return array
