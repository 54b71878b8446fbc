"""run_mission end to end against the scripted navigation stack (in process)."""

from __future__ import annotations

import signal

import pytest

from helpers_executor import line_mission
from navseq.errors import NavseqError
from navseq.executor import MissionControl, MissionInterrupted, run_mission
from navseq.executor.events import (
    AttemptFailed,
    MissionEvent,
    MissionFinished,
    WaypointOutcome,
    WaypointStarted,
)
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction
from navseq.navigators.scripted import (
    Finish,
    Hang,
    LoseServer,
    ScriptedNavigator,
    Stall,
    Succeed,
)

REACHED = WaypointOutcome.REACHED


def run(mission, navigator, **kwargs):  # type: ignore[no-untyped-def]
    events: list[MissionEvent] = []
    result = run_mission(mission, navigator, [events.append], **kwargs)
    return result, events


def test_mission_completes_and_robot_ends_at_the_last_waypoint() -> None:
    nav = ScriptedNavigator()
    result, events = run(line_mission(3), nav)
    assert result.success and result.exit_code == 0
    assert [v.outcome for v in result.visits] == [REACHED] * 3
    assert nav.robot_pose() == Pose2D(3.0, 0.0, 0.0)
    assert result.distance_driven == pytest.approx(3.0)
    assert result.duration == pytest.approx(nav.now())
    assert [g.pose.x for g in nav.sent_goals] == [1.0, 2.0, 3.0]
    assert nav.cancels == []
    assert isinstance(events[-1], MissionFinished) and events[-1].success


@pytest.mark.parametrize("status", ["ABORTED", "REJECTED", "PREEMPTED", "RECALLED"])
def test_each_failure_status_is_retried_then_skipped(status: str) -> None:
    nav = ScriptedNavigator([Finish(status, after=0.5), Finish(status, after=0.5)])
    mission = line_mission(2, retries=1, on_failure=FailureAction.SKIP)
    result, events = run(mission, nav)
    assert [v.outcome for v in result.visits] == [WaypointOutcome.SKIPPED, REACHED]
    assert result.visits[0].attempts == 2 and result.visits[0].reason == status
    assert [e.reason for e in events if isinstance(e, AttemptFailed)] == [status] * 2
    assert not result.success


def test_hanging_goal_times_out_is_cancelled_and_retried() -> None:
    nav = ScriptedNavigator([Hang()])
    result, _ = run(line_mission(1, goal_timeout_s=5.0, retries=1), nav)
    assert result.success and result.visits[0].attempts == 2
    assert len(nav.cancels) == 1
    cancel_time, cancelled_goal = nav.cancels[0]
    assert cancel_time == pytest.approx(5.0, abs=0.11)
    assert cancelled_goal == nav.sent_goals[0].goal_id
    assert nav.send_times[1] - cancel_time == pytest.approx(1.0, abs=0.11)  # back-off


def test_stalled_robot_is_cancelled_with_reason_stalled() -> None:
    mission = line_mission(1, stall_timeout_s=2.0, retries=1, clear_costmaps_on_retry=True)
    nav = ScriptedNavigator([Stall(after=0.3)], speed=0.5)
    result, events = run(mission, nav)
    failures = [e for e in events if isinstance(e, AttemptFailed)]
    assert [f.reason for f in failures] == ["stalled"]
    assert failures[0].t == pytest.approx(0.3 + 2.0, abs=0.15)
    assert len(nav.cancels) == 1 and len(nav.costmap_clears) == 1
    assert nav.costmap_clears[0] <= nav.send_times[1]
    assert result.success


def test_slow_turn_at_the_goal_is_not_a_stall() -> None:
    # 3 rad at 0.1 rad/s takes 30 s, ten times the stall timeout.
    mission = line_mission(1, stall_timeout_s=3.0)
    mission = mission.__class__(
        waypoints=(mission.waypoints[0].__class__(1.0, 0.0, yaw_rad=3.0),),
        defaults=mission.defaults,
    )
    nav = ScriptedNavigator(turn_rate=0.1)
    result, events = run(mission, nav)
    assert not [e for e in events if isinstance(e, AttemptFailed)]
    assert result.success and nav.now() > 30.0


@pytest.mark.parametrize("as_goal_status", [False, True])
def test_server_lost_and_back_in_time_completes(as_goal_status: bool) -> None:
    nav = ScriptedNavigator([Succeed(), LoseServer(after=0.5, duration=5.0, as_goal_status=True)])
    if not as_goal_status:
        nav.script[1] = LoseServer(after=0.5, duration=5.0)
    result, events = run(line_mission(3, server_timeout=10.0), nav)
    assert result.success
    assert [v.attempts for v in result.visits] == [1, 1, 1]
    started = [e for e in events if isinstance(e, WaypointStarted)]
    assert [(s.index, s.attempt) for s in started] == [(0, 1), (1, 1), (1, 1), (2, 1)]
    assert [g.pose.x for g in nav.sent_goals] == [1.0, 2.0, 2.0, 3.0]


def test_server_lost_for_good_stops_the_mission() -> None:
    nav = ScriptedNavigator([Succeed(), LoseServer(after=0.5, duration=None)])
    result, _ = run(line_mission(3, server_timeout=10.0, retries=3), nav)
    assert not result.success and result.reason == "navigation server lost"
    assert [v.outcome for v in result.visits] == [
        REACHED,
        WaypointOutcome.FAILED,
        WaypointOutcome.NOT_RUN,
    ]
    assert nav.now() == pytest.approx(1.0 + 0.5 + 10.0, abs=0.25)


def test_pass_through_never_cancels_and_keeps_the_robot_rolling() -> None:
    mission = line_mission(4, pass_through_m=0.25)
    nav = ScriptedNavigator()
    result, _ = run(mission, nav)
    assert result.success
    assert nav.cancels == []
    assert [v.passed_through for v in result.visits] == [True, True, True, False]
    # Each next goal went out before the robot got to the previous waypoint.
    for sent_at, goal in zip(nav.send_times[1:], nav.sent_goals[:-1], strict=True):
        assert sent_at < goal.pose.x / nav.speed
    assert nav.robot_pose() == Pose2D(4.0, 0.0, 0.0)


def test_dwell_holds_before_the_next_goal() -> None:
    nav = ScriptedNavigator()
    result, _ = run(line_mission(2, dwell_s=4.0), nav)
    assert result.success
    assert nav.send_times[1] == pytest.approx(1.0 + 4.0, abs=0.25)


def test_loops_visit_every_waypoint_each_loop() -> None:
    nav = ScriptedNavigator()
    result, _ = run(line_mission(2, loops=3), nav)
    assert result.success and result.loops_completed == 3
    assert [g.pose.x for g in nav.sent_goals] == [1.0, 2.0] * 3


def test_missing_server_is_a_clear_error() -> None:
    nav = ScriptedNavigator(server_available=False)
    with pytest.raises(NavseqError, match="no navigation server answered within 2 s"):
        run_mission(line_mission(1), nav, server_wait=2.0)
    assert nav.sent_goals == []


def test_ctrl_c_while_waiting_for_the_server_is_an_interrupt_too() -> None:
    class SlowServer(ScriptedNavigator):
        def wait_for_server(self, timeout: float) -> bool:
            raise KeyboardInterrupt

    nav = SlowServer()
    with pytest.raises(MissionInterrupted) as caught:
        run_mission(line_mission(2), nav)
    assert caught.value.exit_code == 130 and nav.sent_goals == []
    assert [v.outcome for v in caught.value.result.visits] == [WaypointOutcome.NOT_RUN] * 2


class _InterruptedNavigator(ScriptedNavigator):
    """Raises ``error`` from spin once its clock passes ``at``: a signal mid-mission."""

    def __init__(self, error: BaseException, at: float):
        super().__init__()
        self.error, self.at = error, at

    def spin(self, seconds: float) -> None:
        super().spin(seconds)
        if self.now() >= self.at:
            raise self.error


def test_keyboard_interrupt_cancels_first_and_raises_mission_interrupted() -> None:
    nav = _InterruptedNavigator(KeyboardInterrupt(), at=1.5)
    events: list[MissionEvent] = []
    with pytest.raises(MissionInterrupted) as caught:
        run_mission(line_mission(3), nav, [events.append])
    assert caught.value.exit_code == 130 and caught.value.signal_name == "SIGINT"
    assert nav.cancels and nav.cancels[0][1] == nav.sent_goals[-1].goal_id
    finished = events[-1]
    assert isinstance(finished, MissionFinished)
    assert finished.reason == "interrupted: SIGINT" and not finished.success
    outcomes = [v.outcome for v in caught.value.result.visits]
    assert outcomes == [REACHED, WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN]


def test_exception_cancels_the_goal_and_is_reraised() -> None:
    nav = ScriptedNavigator()
    seen: list[MissionEvent] = []

    def broken_sink(event: MissionEvent) -> None:
        seen.append(event)
        if isinstance(event, WaypointStarted) and event.index == 1:
            raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        run_mission(line_mission(3), nav, [broken_sink])
    assert len(nav.cancels) == 1
    assert isinstance(seen[-1], MissionFinished)
    assert seen[-1].reason == "interrupted: OSError: disk full"


def test_skip_requested_through_mission_control() -> None:
    control = MissionControl()

    class OperatorAtTwoSeconds(ScriptedNavigator):
        def spin(self, seconds: float) -> None:
            super().spin(seconds)
            if abs(self.now() - 2.0) < 1e-6:
                control.request_skip("operator skip")

    nav = OperatorAtTwoSeconds([Succeed(), Hang()])
    result = run_mission(line_mission(3), nav, control=control)
    assert [v.outcome for v in result.visits] == [REACHED, WaypointOutcome.SKIPPED, REACHED]
    assert result.visits[1].reason == "operator skip"
    assert nav.cancels == []  # the next goal replaced the skipped one
    assert [g.pose.x for g in nav.sent_goals] == [1.0, 2.0, 3.0]


def test_sigterm_handler_is_restored_after_the_run() -> None:
    before = signal.getsignal(signal.SIGTERM)
    run_mission(line_mission(1), ScriptedNavigator())
    assert signal.getsignal(signal.SIGTERM) is before


def test_sigint_is_caught_during_the_run_even_when_ignored_before_and_restored_after() -> None:
    import os

    import pytest

    from navseq.executor.runner import MissionInterrupted

    cancels: list[bool] = []

    class Interrupted(ScriptedNavigator):
        def spin(self, seconds: float) -> None:
            os.kill(os.getpid(), signal.SIGINT)  # as `kill -INT` from a script would
            super().spin(seconds)

        def cancel_goal(self) -> None:
            cancels.append(True)
            super().cancel_goal()

    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with pytest.raises(MissionInterrupted) as stopped:
            run_mission(line_mission(1), Interrupted())
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, previous)
    assert stopped.value.exit_code == 130 and cancels


class _SignalledWhileSending(ScriptedNavigator):
    """A navigator whose second send is hit by ``signum`` halfway: after the goal went
    out to the server, before the navigator recorded it (the window a real action
    client has between sending and storing the goal's handle)."""

    def __init__(self, signum: int) -> None:
        super().__init__()
        self.signum = signum

    def send_goal(self, goal):  # type: ignore[no-untyped-def]
        if len(self.sent_goals) == 1:
            self.sent_goals.append(goal)  # on its way ...
            signal.raise_signal(self.signum)
            self.sent_goals.pop()  # ... and recorded below as any send is
        super().send_goal(goal)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_in_the_middle_of_a_send_still_cancels_that_goal(signum: int) -> None:
    nav = _SignalledWhileSending(signum)
    with pytest.raises(MissionInterrupted) as raised:
        run_mission(line_mission(3), nav, tick=0.1)
    assert raised.value.signal_name == signal.Signals(signum).name
    assert len(nav.sent_goals) == 2
    assert nav.cancels and nav.cancels[0][1] == nav.sent_goals[-1].goal_id
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # handlers put back


def test_a_clock_that_jumped_back_gives_no_negative_waypoint_time() -> None:
    from navseq.executor.result import WaypointOutcome
    from navseq.executor.visit import Visit

    visit = Visit.of(line_mission(2), 0, 0)
    visit.first_sent_at = 120.0  # sent on the old simulator's clock ...
    result = visit.finish(3.0, WaypointOutcome.SKIPPED, "skipped", passed_through=False)
    assert result.duration == 0.0  # ... ended on the restarted one's
