"""The ROS-free core both ROS navigators and nodes use: its rules, without any ROS.

The ROS 1 and ROS 2 faces are checked against real ROS in test_ros_behaviour.py; here
each rule is driven directly, with a fake clock and fake server, so every branch is
reached deterministically.
"""

from __future__ import annotations

from typing import Any

import pytest

from navseq.errors import NavseqError
from navseq.executor.control import MissionControl
from navseq.mission.model import Mission, Waypoint
from navseq.navigators.base import GoalDone, GoalOutcome, ServerBack, ServerLost
from navseq.roscore.clock import ClockWatch, spin_on_ros_time, wait_for_valid_time
from navseq.roscore.navigator import NavigatorCore, rejected
from navseq.roscore.operator import OperatorDesk
from navseq.roscore.server import ServerWatch
from navseq.sinks.mission_status import MissionStatus


class FakeClient:
    """A client library whose clock and server the test moves by hand."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.time = 0.0
        self.present = True
        self.ready = True
        self.cancels = 0
        self.warnings: list[str] = []

    def now(self) -> float:
        if self.times:
            self.time = self.times.pop(0)
        return self.time

    def clock_wakes(self) -> bool:
        return True

    def check_running(self) -> None:
        pass

    def server_present(self) -> bool:
        return self.present

    def server_ready(self) -> bool:
        return self.ready

    def cancel_goal(self) -> None:
        self.cancels += 1

    def warn(self, text: str) -> None:
        self.warnings.append(text)


def core(client: FakeClient, **kwargs: Any) -> NavigatorCore:
    return NavigatorCore(client, "/move_base", lost_after=0.0, **kwargs)


def test_time_jumping_back_during_a_goal_fails_it_and_cancels_it():
    client = FakeClient()
    navigator = core(client)
    with navigator.book.lock:
        navigator.book.start(7)
    client.times = [100.0, 100.5, 10.0]
    navigator.spin(5.0, navigator.has_news)
    (done,) = navigator.inbox.drain()
    assert isinstance(done, GoalDone) and done.goal_id == 7
    assert done.outcome is GoalOutcome.FAILED and done.status == "CLOCK_JUMPED_BACK"
    assert done.text.startswith("ROS time jumped back 90.5 s")
    assert client.cancels == 1 and client.warnings == [done.text]
    assert navigator.book.goal_id is None  # its late result is not the new goal's


def test_a_jump_between_two_spins_is_seen_too():
    client = FakeClient()
    navigator = core(client)
    client.times = [100.0, 101.0]
    navigator.spin(1.0, navigator.has_news)
    with navigator.book.lock:
        navigator.book.start(3)
    client.times = [20.0]  # the executor's own work ran while the simulator restarted
    navigator.spin(1.0, navigator.has_news)
    assert [type(e) for e in navigator.inbox.drain()] == [GoalDone]


def test_a_goal_sent_after_the_jump_stands():
    """The server went away with its simulator and came back on a clock started anew:
    the goal resent then is on the new clock, and the jump fails nothing."""
    client = FakeClient()
    navigator = core(client)
    client.times = [100.0, 101.0]
    navigator.spin(1.0, navigator.has_news)
    client.times = [5.0]
    navigator.sending_goal()
    with navigator.book.lock:
        navigator.book.start(8)
    client.times = [5.1, 6.2]
    navigator.spin(1.0, navigator.has_news)
    assert navigator.inbox.drain() == [] and navigator.book.goal_id == 8
    assert client.warnings == ["ROS time jumped back 96.0 s"] and client.cancels == 0


def test_time_jumping_back_with_no_goal_out_fails_nothing():
    client = FakeClient()
    navigator = core(client)
    client.times = [100.0, 10.0]
    navigator.spin(5.0, navigator.has_news)
    assert navigator.inbox.drain() == [] and client.cancels == 0
    assert client.warnings == ["ROS time jumped back 90.0 s"]


def test_a_spin_before_the_clock_starts_waits_from_when_it_does():
    watch = ClockWatch()
    times = [0.0, 0.0, 50.0, 50.5, 51.0]
    waits: list[float] = []
    jump = spin_on_ros_time(
        1.0,
        watch,
        lambda: times.pop(0),
        lambda: False,
        waits.append,
        lambda: None,
        clock_wakes=True,
    )
    assert jump is None and times == []  # ended at 51.0, one second after the start


def test_no_valid_time_in_time_is_an_error_naming_clock():
    with pytest.raises(NavseqError, match=r"ROS time is still 0 after 0\.05 s") as error:
        wait_for_valid_time(lambda: 0.0, lambda: None, 0.05, "do something")
    assert error.value.source == "/clock"
    assert "do something" in str(error.value)


def test_a_lost_server_drops_the_goal_and_comes_back_when_ready():
    client = FakeClient()
    navigator = core(client)
    navigator.watch.found()
    with navigator.book.lock:
        navigator.book.start(4)
    client.present = client.ready = False
    (lost,) = navigator.check_server("no status for 2 s")
    assert lost == ServerLost("the action server /move_base is gone (no status for 2 s)")
    assert navigator.book.goal_id is None
    assert navigator.check_server("x") == []  # said once
    client.present = client.ready = True
    assert navigator.check_server("x") == [ServerBack()]


def test_a_server_must_stay_away_lost_after_seconds_to_be_lost():
    now = [0.0]
    present = [False]
    watch = ServerWatch(lambda: present[0], lambda: present[0], 0.3, clock=lambda: now[0])
    watch.found()
    assert watch.check() is None  # gone since 0.0
    now[0] = 0.2
    assert watch.check() is None
    now[0] = 0.35
    assert watch.check() == "lost"


def test_a_rejection_says_the_servers_words_else_the_likely_cause():
    assert rejected(1, "busy", "is it up?").text == "the server rejected the goal: busy"
    assert rejected(1, "", "is it up?").text == "the server rejected the goal: is it up?"
    assert rejected(1, "", "x").status == "REJECTED"


def test_a_cancel_never_answered_is_waited_for_boundedly_then_said():
    client = FakeClient()
    navigator = core(client, cancel_wait=0.05)
    with navigator.book.lock:
        navigator.book.start(5)
        assert navigator.book.ask_cancel() == (True, None)
    assert navigator.cancel_and_wait() is False
    assert client.warnings == [
        "/move_base did not answer the cancel of the active goal within 0.05 s: "
        "the robot may still be driving to it"
    ]


def test_an_answered_cancel_is_not_warned_about():
    client = FakeClient()
    navigator = core(client, cancel_wait=0.05)
    with navigator.book.lock:
        navigator.book.start(5)
        navigator.book.ask_cancel()
    navigator.book.cancel_answered.set()
    assert navigator.cancel_and_wait() is True and client.warnings == []


def test_late_callbacks_of_a_replaced_goal_do_not_count():
    client = FakeClient()
    book = core(client).book
    with book.lock:
        first = book.start(1)
        second = book.start(1)  # the same goal again (pause / resume)
    assert not book.is_current(first, 1) and book.is_current(second, 1)


def operator_desk() -> tuple[OperatorDesk, MissionStatus, MissionControl]:
    mission = Mission(waypoints=(Waypoint(1.0, 0.0, yaw_deg=0),))
    state = MissionStatus(mission)
    control = MissionControl()
    return OperatorDesk(control, state, lambda kind: f"~{kind}"), state, control


def test_the_services_refuse_once_the_mission_is_over():
    desk, state, _control = operator_desk()
    state.over = "the mission has ended (succeeded)"
    assert desk.answer_blocking("pause") == (
        False,
        "nothing to pause: the mission has ended (succeeded)",
    )


def test_skip_needs_a_waypoint_underway():
    desk, state, control = operator_desk()
    assert desk.answer_blocking("skip") == (False, "no waypoint is underway")
    state.active_waypoint = 0
    assert desk.answer_blocking("skip") == (
        True,
        "waypoint 1 skipped; going on with the next one",
    )
    (request,) = control.take_requests()
    assert request.kind == "skip" and request.reason == "skipped by the operator (~skip)"
