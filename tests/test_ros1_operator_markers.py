"""Operator pause/resume/cancel on a navigator, and the RViz markers of a mission.

Both run in process: the operator layer has no ROS in it, and building marker messages
needs only the message classes (no master, no node).
"""

from __future__ import annotations

import math
import threading

import pytest

from navseq.executor.events import MissionFinished, WaypointFinished
from navseq.executor.runner import run_mission
from navseq.geometry import Pose2D
from navseq.mission import Mission, Waypoint
from navseq.navigators.base import Goal, GoalDone, GoalStatus
from navseq.navigators.scripted import Hang, ScriptedNavigator
from navseq.ros.operator import NodeShutdown, OperatorCancel, OperatorNavigator


def request_and_poll(operator: OperatorNavigator, kind: str) -> tuple[bool, str, list]:
    """Ask from another thread, as a ROS service would, while the executor thread polls."""
    answers: list[tuple[bool, str]] = []
    asker = threading.Thread(target=lambda: answers.append(operator.request(kind)))
    asker.start()
    events: list = []
    while asker.is_alive():
        events += operator.poll()
        asker.join(0.001)
    return (*answers[0], events)


def test_pause_cancels_freezes_the_clock_and_resume_resends_the_same_goal():
    inner = ScriptedNavigator([Hang(), Hang()], speed=0.1)
    operator = OperatorNavigator(inner)
    goal = Goal(7, Pose2D(5.0, 0.0, 0.0))
    operator.send_goal(goal)
    operator.spin(1.0)
    operator.poll()

    ok, _, _ = request_and_poll(operator, "pause")
    assert ok and operator.paused
    assert [goal_id for _, goal_id in inner.cancels] == [7]
    frozen = operator.now()
    operator.spin(30.0)
    hidden = operator.poll()
    assert operator.now() == frozen  # no goal timeout runs out while paused
    assert not [e for e in hidden if isinstance(e, GoalDone)]  # our cancel, not a failure

    # A goal the executor sends while paused is held back until resume.
    later = Goal(8, Pose2D(6.0, 0.0, 0.0))
    operator.send_goal(later)
    assert [g.goal_id for g in inner.sent_goals] == [7]
    assert request_and_poll(operator, "pause")[0] is False  # already paused

    ok, _, _ = request_and_poll(operator, "resume")
    assert ok and not operator.paused
    assert [g.goal_id for g in inner.sent_goals] == [7, 8]
    operator.spin(2.0)
    assert operator.now() == pytest.approx(frozen + 2.0)


def test_cancel_request_ends_the_mission_from_poll():
    operator = OperatorNavigator(ScriptedNavigator([Hang()]))
    operator.send_goal(Goal(1, Pose2D(1.0, 0.0, 0.0)))
    with pytest.raises(OperatorCancel):
        request_and_poll(operator, "cancel")


def test_events_pass_through_when_not_paused():
    inner = ScriptedNavigator(speed=10.0)
    operator = OperatorNavigator(inner)
    operator.send_goal(Goal(1, Pose2D(1.0, 0.0, 0.0)))
    events = []
    for _ in range(40):
        operator.spin(0.1)
        events += operator.poll()
    assert [e.status for e in events if isinstance(e, GoalDone)] == [GoalStatus.SUCCEEDED]


def test_a_shutdown_ends_the_mission_as_interrupted_not_as_a_preempted_waypoint():
    """Like ``rosnode kill``: the goal is cancelled underneath, then the stop reason shows."""
    inner = ScriptedNavigator([Hang()])
    stop: list[str] = []

    def stop_reason() -> str | None:
        if inner.now() >= 2.0 and not stop:
            inner.cancel_goal()  # what the navigator's own shutdown hook does first
            stop.append("external shutdown request: killed")
        return stop[0] if stop else None

    seen: list = []
    mission = Mission([Waypoint(3.0, 0.0, yaw_rad=0.0), Waypoint(0.0, 0.0, yaw_rad=0.0)])
    operator = OperatorNavigator(inner, stop_reason=stop_reason)
    with pytest.raises(NodeShutdown, match="killed"):
        run_mission(mission, operator, [seen.append], tick=0.5)
    finished = [e for e in seen if isinstance(e, WaypointFinished)]
    assert [e.reason for e in finished] == [
        "interrupted: NodeShutdown: external shutdown request: killed"
    ]
    assert isinstance(seen[-1], MissionFinished) and not seen[-1].success
    assert seen[-1].reason.startswith("interrupted")


def test_markers_show_every_waypoint_with_heading_number_and_status_colour():
    pytest.importorskip("visualization_msgs.msg", reason="ROS 1 messages not installed")
    from navseq.ros.markers import STATUS_COLOURS, MarkerStatus, waypoint_markers

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


def test_the_odometry_pose_passes_through_when_the_inner_navigator_has_one():
    class WithOdometry(ScriptedNavigator):
        def odometry_pose(self) -> Pose2D | None:
            return Pose2D(0.5, 0.0, 0.1)

    assert OperatorNavigator(WithOdometry([Hang()])).odometry_pose() == Pose2D(0.5, 0.0, 0.1)

    class WithoutOdometry:  # only what the operator layer touches here
        pass

    # A navigator that has no odometry pose: None, no error.
    assert OperatorNavigator(WithoutOdometry()).odometry_pose() is None  # type: ignore[arg-type]
