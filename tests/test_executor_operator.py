"""Operator requests as executor inputs: pause, resume, cancel (and skip while paused).

A pause stops the robot (the goal is cancelled) and holds every deadline; resume sends
the goal again and the deadlines move on by the time paused. The same requests reach a
running mission from other threads through MissionControl, as the ROS node's services
and the CLI's signals file them.
"""

from __future__ import annotations

import threading

import pytest

from helpers_executor import Harness, line_mission
from navseq.executor import CancelGoal, ExecutorState, MissionControl, SendGoal, run_mission
from navseq.executor.control import StopRequested
from navseq.executor.events import (
    AttemptFailed,
    MissionFinished,
    MissionPaused,
    MissionResumed,
    WaypointFinished,
    WaypointOutcome,
)
from navseq.geometry import Pose2D
from navseq.mission import Mission, Waypoint
from navseq.mission.model import FailureAction
from navseq.navigators.scripted import Hang, ScriptedNavigator, Succeed

REACHED = WaypointOutcome.REACHED


def test_pause_cancels_the_goal_and_no_timeout_runs_out_while_paused() -> None:
    h = Harness(line_mission(2, goal_timeout_s=10.0))
    h.start(0.0)
    first = h.goal_id
    assert h._keep(h.executor.pause(4.0)) == [CancelGoal()]
    assert h.executor.state is ExecutorState.PAUSED and h.executor.current_goal is None
    assert h.of_type(MissionPaused) == [
        MissionPaused(t=4.0, index=0, reason="paused by operator", state="active")
    ]
    # The cancelled goal's end is ours, not the waypoint's; an hour passes paused.
    assert h.done("PREEMPTED", 4.1, goal_id=first) == []
    assert h.tick(3600.0) == []
    assert not h.of_type(AttemptFailed)

    resumed = h._keep(h.executor.resume(3604.0))
    assert [type(c) for c in resumed] == [SendGoal]
    assert resumed[0].goal.pose == Pose2D(1.0, 0.0, 0.0) and h.goal_id != first
    assert h.of_type(MissionResumed) == [MissionResumed(t=3604.0, index=0, paused_for=3600.0)]
    # 4 s of the 10 s timeout were used before the pause: it runs out 6 s after resume.
    assert h.tick(3609.9) == []
    assert h.tick(3610.0) == [CancelGoal()]
    assert h.of_type(AttemptFailed)[0].reason == "timeout"
    assert h.executor.result.visits[0].attempts == 1  # the resend was no new attempt


def test_the_stall_timeout_also_waits_for_the_resume() -> None:
    h = Harness(line_mission(1, stall_timeout_s=5.0))
    h.start(0.0)
    h.feedback(3.0, Pose2D(0.0, 0.0, 0.0))
    h.executor.pause(3.0)  # no progress since the goal went out: 3 of the 5 s are used
    h.executor.resume(100.0)
    assert h.tick(101.9, Pose2D(0.0, 0.0, 0.0)) == []
    assert h.tick(102.0, Pose2D(0.0, 0.0, 0.0)) == [CancelGoal()]
    assert h.of_type(AttemptFailed)[0].reason == "stalled"


def test_a_dwell_paused_halfway_ends_after_its_remaining_time() -> None:
    h = Harness(line_mission(2, dwell_s=10.0))
    h.start(0.0)
    h.succeed(2.0, Pose2D(1.0, 0.0, 0.0))
    assert h.executor.state is ExecutorState.DWELLING
    assert h.executor.pause(6.0) == []  # nothing is out to cancel
    assert h.tick(50.0) == []
    assert h.executor.resume(56.0) == []
    assert h.executor.state is ExecutorState.DWELLING
    assert h.tick(61.9) == []
    assert h.tick(62.0)[0].goal.pose.x == 2.0  # type: ignore[union-attr]


def test_a_retry_back_off_is_held_too() -> None:
    h = Harness(line_mission(1, retries=1))
    h.start(0.0)
    h.done("ABORTED", 1.0)
    h.executor.pause(1.5)
    assert h.tick(30.0) == []
    h.executor.resume(30.0)
    assert h.tick(30.4) == []
    assert [type(c) for c in h.tick(30.5)] == [SendGoal]


def test_pause_and_resume_twice_or_out_of_turn_do_nothing() -> None:
    h = Harness(line_mission(1))
    assert h.executor.pause(0.0) == []  # not started
    h.start(0.0)
    assert h.executor.resume(1.0) == []  # not paused
    h.executor.pause(1.0)
    assert h.executor.pause(2.0) == []
    assert len(h.of_type(MissionPaused)) == 1
    h.executor.resume(3.0)
    assert h.executor.resume(4.0) == []
    assert len(h.of_type(MissionResumed)) == 1


def test_skip_while_paused_goes_on_with_the_next_waypoint() -> None:
    h = Harness(line_mission(2))
    h.start(0.0)
    h.executor.pause(1.0)
    commands = h._keep(h.executor.skip(2.0, "not this one"))
    assert [type(c) for c in commands] == [SendGoal] and commands[0].goal.pose.x == 2.0  # type: ignore[union-attr]
    assert h.executor.state is ExecutorState.ACTIVE
    assert h.executor.result.visits[0].outcome is WaypointOutcome.SKIPPED


def test_cancel_ends_the_mission_as_the_operators_decision() -> None:
    h = Harness(line_mission(3))
    h.start(0.0)
    h.succeed(2.0)
    assert h.executor.cancel(3.0) == [CancelGoal()]
    result = h.executor.result
    assert h.executor.finished and not result.success and result.exit_code == 1
    assert result.reason == "cancelled by operator"
    assert [v.outcome for v in result.visits] == [
        REACHED,
        WaypointOutcome.FAILED,
        WaypointOutcome.NOT_RUN,
    ]
    assert h.of_type(MissionFinished)[-1].reason == "cancelled by operator"


def test_cancel_while_paused_ends_the_mission_too() -> None:
    h = Harness(line_mission(2, on_failure=FailureAction.SKIP))
    h.start(0.0)
    h.executor.pause(1.0)
    h.executor.cancel(2.0, "cancelled: battery low")
    assert h.executor.finished
    assert h.executor.result.visits[0].reason == "cancelled: battery low"


# ------------------------------------------------------------ through MissionControl


class _Operator(ScriptedNavigator):
    """A scripted stack whose clock calls ``at[t]()`` once it reaches ``t`` (an operator
    acting from another thread, as a ROS service handler would)."""

    def __init__(self, at: dict[float, object], *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.at = dict(at)
        self.answers: list[tuple[bool, str]] = []
        self.threads: list[threading.Thread] = []

    def spin(self, seconds: float) -> None:
        super().spin(seconds)
        for t in sorted(self.at):
            if self.now() >= t - 1e-9:
                action = self.at.pop(t)
                thread = threading.Thread(target=lambda a=action: self.answers.append(a()))
                thread.start()
                self.threads.append(thread)
                thread.join(0.05)  # let it file (and be answered) before the next look


def test_pause_resume_and_cancel_requests_from_another_thread() -> None:
    control = MissionControl()
    nav = _Operator(
        {
            1.0: lambda: control.request("pause"),
            1.5: lambda: control.request("pause"),
            20.0: lambda: control.request("resume"),
            20.5: lambda: control.request("cancel"),
        },
        [Hang(), Hang()],
        speed=0.1,
    )
    seen: list[object] = []
    result = run_mission(line_mission(2, goal_timeout_s=5.0), nav, [seen.append], control=control)
    for thread in nav.threads:
        thread.join(5.0)
    assert nav.answers == [
        (True, "paused; the active goal was cancelled"),
        (False, "already paused"),
        (True, "resumed"),
        (True, "mission cancelled; the active goal was cancelled"),
    ]
    # The 5 s goal timeout did not run out in the 19 s paused: the operator's cancel ended it.
    assert result.reason == "cancelled by operator"
    assert [e.reason for e in seen if isinstance(e, AttemptFailed)] == []
    assert [g.goal_id for g in nav.sent_goals] == [1, 2]  # resent on resume
    assert len(nav.cancels) == 2  # the pause's, then the cancel's
    # Once the run is over, a request is refused at once.
    assert control.request("pause") == (False, "nothing to pause: the mission has ended")


def test_unknown_request_is_refused() -> None:
    ok, message = MissionControl().request("dance")
    assert not ok and "unknown request" in message


def test_a_shutdown_ends_the_mission_as_interrupted_not_as_a_preempted_waypoint() -> None:
    """Like ``rosnode kill``: the goal is cancelled underneath, then the stop reason shows."""
    inner = ScriptedNavigator([Hang(), Succeed()])
    stop: list[str] = []

    def stop_reason() -> str | None:
        if inner.now() >= 2.0 and not stop:
            inner.cancel_goal()  # what the navigator's own shutdown hook does first
            stop.append("external shutdown request: killed")
        return stop[0] if stop else None

    seen: list[object] = []
    mission = Mission((Waypoint(3.0, 0.0, yaw_rad=0.0), Waypoint(0.0, 0.0, yaw_rad=0.0)))
    control = MissionControl(stop_reason=stop_reason)
    with pytest.raises(StopRequested, match="killed"):
        run_mission(mission, inner, [seen.append], tick=0.5, control=control)
    finished = [e for e in seen if isinstance(e, WaypointFinished)]
    assert [e.reason for e in finished] == ["interrupted (external shutdown request: killed)"]
    last = seen[-1]
    assert isinstance(last, MissionFinished) and not last.success
    assert last.reason.startswith("interrupted")
