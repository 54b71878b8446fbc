"""RViz markers for a mission, as ROS 1 messages.

What the markers show (an arrow and a number per waypoint, coloured by status) is
decided once for both ROS in :mod:`navseq.sinks.mission_status`; this module only
builds ``visualization_msgs/MarkerArray`` from its :class:`MarkerSpec` list. The array
is rebuilt from scratch on every change (a mission has tens of waypoints, not
thousands) and published latched, so RViz shows it whenever it connects.
"""

from __future__ import annotations

from collections.abc import Mapping

import rospy
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.ros1.conversions import pose_from_pose2d
from navseq.sinks.mission_status import (
    ARROW_LENGTH,
    ARROW_NS,
    LABEL_NS,
    STATUS_COLOURS,
    TEXT_HEIGHT,
    MarkerKind,
    MarkerSpec,
    MarkerStatus,
    marker_specs,
)

__all__ = [
    "ARROW_NS",
    "LABEL_NS",
    "STATUS_COLOURS",
    "MarkerStatus",
    "marker_message",
    "waypoint_markers",
]

_KINDS = {MarkerKind.ARROW: Marker.ARROW, MarkerKind.LABEL: Marker.TEXT_VIEW_FACING}


def marker_message(spec: MarkerSpec, stamp: rospy.Time) -> Marker:
    """The ``visualization_msgs/Marker`` of one :class:`MarkerSpec`."""
    marker = Marker()
    marker.header.frame_id = spec.frame
    marker.header.stamp = stamp
    marker.ns = spec.namespace
    marker.id = spec.id
    marker.type = _KINDS[spec.kind]
    marker.action = Marker.ADD
    marker.pose = pose_from_pose2d(Pose2D(spec.x, spec.y, spec.yaw), spec.z)
    marker.scale.x, marker.scale.y, marker.scale.z = spec.scale
    r, g, b, a = spec.colour
    marker.color = ColorRGBA(r=r, g=g, b=b, a=a)
    marker.text = spec.text
    return marker


def waypoint_markers(
    mission: Mission,
    statuses: Mapping[int, MarkerStatus],
    *,
    stamp: rospy.Time | None = None,
    arrow_length: float = ARROW_LENGTH,
    text_height: float = TEXT_HEIGHT,
) -> MarkerArray:
    """Markers for every waypoint of ``mission``; ``statuses`` maps index -> status.

    Waypoints missing from ``statuses`` are PENDING (see
    :func:`navseq.sinks.mission_status.marker_specs`).
    """
    stamp = stamp if stamp is not None else rospy.Time(0)
    specs = marker_specs(mission, statuses, arrow_length=arrow_length, text_height=text_height)
    return MarkerArray(markers=[marker_message(spec, stamp) for spec in specs])
