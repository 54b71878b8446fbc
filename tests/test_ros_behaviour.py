"""The same situation gets the same behaviour on ROS 1 and ROS 2.

Each case runs twice, against a scripted move_base (real actionlib, a real rosmaster)
and a scripted Nav2 (real rclpy), with ``navseq run --navigator ros1`` / ``nav2``, and
checks what a user sees: the exit status, the attempt's status and text in the report,
the events ``--json`` prints and the log lines. The rules themselves live once, in
``navseq.roscore``.
"""

from __future__ import annotations

from pathlib import Path

from cli_support import printed_events, wait_for, write_mission
from ros_behaviour_support import ScriptedStack, report_of, stack

__all__ = ["stack"]  # the fixture, ROS 1 and ROS 2

RUN_TIMEOUT = 120.0
WAYPOINT = "  - {name: a, x: 1.0, y: 0.0, yaw: 0}\n"


def mission(tmp_path: Path, defaults: str) -> Path:
    return write_mission(tmp_path / "m.yaml", WAYPOINT, f"defaults: {{{defaults}}}\n")


def run_to_end(stack: ScriptedStack, tmp_path: Path, defaults: str) -> tuple[int, Path]:
    out = tmp_path / "out"
    stack.start_navseq(mission(tmp_path, defaults), out)
    return stack.finish(RUN_TIMEOUT), out


def attempts(out: Path) -> list[tuple[str, str]]:
    (visit,) = report_of(out)["visits"]
    return [(attempt["status"], attempt["text"]) for attempt in visit["attempts"]]


def test_time_jumping_back_fails_the_attempt_and_the_retry_runs_on_the_new_clock(
    stack: ScriptedStack, tmp_path: Path
):
    # The server's /clock goes back 90 s one second into the first goal: a simulator reset.
    stack.start_server("jump:1.0", clock=True)
    code, out = run_to_end(stack, tmp_path, "retries: 1, on_failure: stop, goal_timeout: 60")
    output = stack.output()
    assert code == 0, output[-4000:]
    (jumped, retried) = attempts(out)
    assert jumped[0] == "CLOCK_JUMPED_BACK"
    assert jumped[1].startswith("ROS time jumped back 90.") or jumped[1].startswith(
        "ROS time jumped back 89."
    ), jumped
    assert retried[0] == "SUCCEEDED"
    assert "ROS time jumped back" in output and "the goal is cancelled" in output
    assert "cancel" in stack.server_events()  # the jumped goal does not drive on
    assert "Traceback" not in output


def test_a_server_that_vanishes_mid_goal_is_waited_for_then_the_mission_fails(
    stack: ScriptedStack, tmp_path: Path
):
    stack.start_server("die:1.0")
    code, out = run_to_end(stack, tmp_path, "goal_timeout: 60")
    output = stack.output()
    assert code == 1, output[-4000:]
    changes = printed_events(output, "ServerStatusChanged")
    assert [change["available"] for change in changes] == [False]
    assert changes[0]["reason"].startswith("the action server /")
    assert " is gone (" in changes[0]["reason"]
    (visit,) = report_of(out)["visits"]
    assert visit["outcome"] == "failed"
    assert "server" in visit["reason"]
    assert "Traceback" not in output


def test_a_rejected_goal_is_a_failed_attempt_named_rejected(stack: ScriptedStack, tmp_path: Path):
    stack.start_server("reject:0.1")
    code, out = run_to_end(stack, tmp_path, "retries: 0, on_failure: stop, goal_timeout: 60")
    output = stack.output()
    assert code == 1, output[-4000:]
    ((status, text),) = attempts(out)
    assert status == "REJECTED"
    assert text.startswith("the server rejected the goal: ")
    assert "Traceback" not in output


def test_a_cancel_never_answered_is_waited_for_boundedly_then_said(
    stack: ScriptedStack, tmp_path: Path
):
    stack.start_server("hang", cancel="ignore")
    stack.start_navseq(mission(tmp_path, "goal_timeout: 600"), tmp_path / "out")
    # The server took the goal and navseq heard of it (the feedback's progress).
    wait_for(
        lambda: (
            "goal" in stack.server_events() and printed_events(stack.output(), "WaypointProgress")
        ),
        RUN_TIMEOUT,
        "the goal under way",
    )
    stack.interrupt()
    code = stack.finish(RUN_TIMEOUT)
    output = stack.output()
    assert code == 130, output[-4000:]
    assert "cancel_ignored" in stack.server_events()
    assert "did not answer the cancel of the active goal within 2 s" in output, output[-4000:]
    assert "the robot may still be driving to it" in output
    assert "Traceback" not in output
