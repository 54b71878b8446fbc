"""The RViz markers of a mission (in process: building marker messages needs only the
message classes, no master, no node). Operator pause/resume/cancel are executor inputs
now: tests/test_executor_operator.py."""

from __future__ import annotations

import math

import pytest

from navseq.mission import Mission, Waypoint


def test_markers_show_every_waypoint_with_heading_number_and_status_colour():
    pytest.importorskip("visualization_msgs.msg", reason="ROS 1 messages not installed")
    from navseq.ros1.markers import STATUS_COLOURS, MarkerStatus, waypoint_markers

    mission = Mission(
        waypoints=(
            Waypoint(1.0, 2.0, yaw_rad=math.pi / 2, name="dock"),
            Waypoint(-1.0, 0.5, yaw_rad=0.0),
            Waypoint(0.0, -1.5, yaw_rad=math.pi),
        ),
        frame="map",
    )
    array = waypoint_markers(mission, {0: MarkerStatus.REACHED, 1: MarkerStatus.ACTIVE})
    arrows = [m for m in array.markers if m.type == m.ARROW]
    labels = [m for m in array.markers if m.type == m.TEXT_VIEW_FACING]
    assert [m.id for m in arrows] == [0, 1, 2] and [m.id for m in labels] == [0, 1, 2]
    assert [m.text for m in labels] == ["1 dock", "2", "3"]
    assert all(m.header.frame_id == "map" for m in array.markers)
    first = arrows[0]
    assert (first.pose.position.x, first.pose.position.y) == (1.0, 2.0)
    yaw = 2 * math.atan2(first.pose.orientation.z, first.pose.orientation.w)
    assert yaw == pytest.approx(math.pi / 2)
    colours = [c for m in arrows for c in (m.color.r, m.color.g, m.color.b, m.color.a)]
    expected = [MarkerStatus.REACHED, MarkerStatus.ACTIVE, MarkerStatus.PENDING]
    assert colours == pytest.approx([c for s in expected for c in STATUS_COLOURS[s]])
