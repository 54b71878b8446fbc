"""Nav2's assisted teleop on the simulated robot, without ROS: the operator's command
slowed before an obstacle (Nav2's projection), ended by the operator or the time
allowance. The ROS 2 action is tested in tests/test_ros2_behaviors.py."""

from __future__ import annotations

from navseq.geometry import Pose2D
from navseq.sim.assisted_teleop import assisted_command
from navseq.sim.behaviors import BehaviorServer, Outcome

WALL_X = 1.0


def wall(pose: Pose2D) -> bool:
    return pose.x >= WALL_X


def drive(server: BehaviorServer, seconds: float, start: float = 0.0) -> list[tuple[float, float]]:
    """Step the server ``seconds`` at 20 Hz with a robot that obeys; the poses' x and v."""
    x, now, seen = start, 0.0, []
    while now < seconds and server.running:
        v, _w = server.step(now, Pose2D(x, 0.0, 0.0), wall)
        x += v * 0.05
        now += 0.05
        seen.append((x, v))
    return seen


def test_in_open_space_the_command_passes_unchanged() -> None:
    assert assisted_command(Pose2D(-5.0, 0.0, 0.0), (0.2, 0.3), wall) == (0.2, 0.3)


def test_the_command_shrinks_as_the_obstacle_nears_and_is_zero_within_one_step() -> None:
    speeds = [assisted_command(Pose2D(x, 0.0, 0.0), (0.5, 0.0), wall)[0] for x in (0.6, 0.8, 0.96)]
    assert speeds[0] > speeds[1] > speeds[2] == 0.0
    # 0.4 m ahead at 0.5 m/s (0.05 m a step): collides at 0.8 s of the 1 s projection.
    assert abs(speeds[0] - 0.4) < 1e-9


def test_the_robot_comes_to_rest_before_the_wall_and_succeeds_when_preempted() -> None:
    server = BehaviorServer()
    goal = server.assisted_teleop(0.0, time_allowance=0.0)
    server.teleop(0.5, 0.0)
    seen = drive(server, 20.0)
    assert max(x for x, _v in seen) < WALL_X
    assert seen[-1][1] < 0.01  # it stands
    assert goal.ending is None  # no allowance: it runs until told
    server.preempt_teleop()
    server.step(20.0, Pose2D(seen[-1][0], 0.0, 0.0), wall)
    assert goal.ending is not None and goal.ending.outcome is Outcome.SUCCEEDED
    assert server.teleop_twist == (0.0, 0.0)  # forgotten when the goal ends


def test_a_time_allowance_that_runs_out_ends_it_with_timeout() -> None:
    server = BehaviorServer()
    goal = server.assisted_teleop(0.0, time_allowance=1.0)
    server.teleop(0.1, 0.0)
    drive(server, 5.0, start=-5.0)
    assert goal.ending is not None
    assert (goal.ending.outcome, goal.ending.error) == (Outcome.ABORTED, "TIMEOUT")
    assert 1.0 <= goal.ending.elapsed < 1.2


def test_a_preempt_before_the_goal_is_forgotten() -> None:
    server = BehaviorServer()
    server.preempt_teleop()
    goal = server.assisted_teleop(0.0, time_allowance=0.0)
    drive(server, 1.0, start=-5.0)
    assert goal.ending is None
