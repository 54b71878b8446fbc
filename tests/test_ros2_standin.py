"""Nav2's navigator rules in navseq.ros2.standin, in process (no ROS 2 needed)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import pytest

from navseq.commands.sim_options import add_arguments, config_from_args
from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.ros2.standin import (
    NAV2_PLANNER_TOLERANCE,
    ErrorCode,
    Nav2StandIn,
    Navigator,
    NavTask,
    Outcome,
    WaypointRun,
    plan_poses,
)
from navseq.sim.occupancy import load_map
from navseq.sim.options import SimConfig
from navseq.sim.world import SimWorld

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
START = Pose2D(-2.0, -0.5, 0.0)
IN_A_PILLAR = Pose2D(-1.1, 0.0)  # the west pillar's centre: free cells within 0.5 m
# Beyond the arena's south-west wall, farther than the planner's 0.5 m from free space.
DEEP_IN_A_WALL = Pose2D(-2.3, -2.3)


@pytest.fixture(scope="module")
def grid():
    return load_map(MAP)


@pytest.fixture
def standin(grid) -> Nav2StandIn:
    return Nav2StandIn(SimWorld(grid, START))


def run_until_done(standin: Nav2StandIn, goal: NavTask | WaypointRun, seconds: float = 120.0):
    for _ in range(round(seconds / standin.world.dt)):
        if goal.ending is not None:
            return goal.ending
        standin.step()
    raise AssertionError(f"not done after {seconds} simulated seconds")


def test_a_reached_goal_succeeds_and_the_robot_stands(standin: Nav2StandIn):
    task = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.0, -0.5, 0.0)])
    assert run_until_done(standin, task).outcome is Outcome.SUCCEEDED
    assert task.done.is_set()
    assert standin.world.robot.pose.distance_to(Pose2D(-1.0, -0.5)) < 0.1
    for _ in range(10):
        standin.step()
    assert standin.world.robot.v == 0.0 and standin.active is None


def test_a_new_goal_preempts_the_running_one_which_ends_aborted(standin: Nav2StandIn):
    first = standin.navigate(Navigator.TO_POSE, [Pose2D(2.0, 0.5)])
    for _ in range(20):
        standin.step()
    second = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.5, -0.5)])
    assert first.ending is not None
    assert (first.ending.outcome, first.ending.error_code) == (Outcome.ABORTED, ErrorCode.NONE)
    assert run_until_done(standin, second).outcome is Outcome.SUCCEEDED


def test_the_other_navigator_is_refused_while_one_runs(standin: Nav2StandIn):
    running = standin.navigate(Navigator.THROUGH_POSES, [Pose2D(-1.5, -0.5), Pose2D(2.0, 0.5)])
    refused = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.0, -0.5)])
    assert refused.ending is not None and refused.ending.outcome is Outcome.ABORTED
    assert "another navigator" in refused.ending.error_msg
    assert running.ending is None and standin.active is running


@pytest.mark.parametrize("goal", [IN_A_PILLAR, Pose2D(-1.1, 0.1, 0.0)], ids=["centre", "wall"])
def test_a_goal_in_a_pillar_is_driven_to_the_nearest_free_cell_and_succeeds(
    standin: Nav2StandIn, goal: Pose2D
):
    # Nav2 Jazzy (NavFn, tolerance 0.5 m): SUCCEEDED 0.52 m and 0.44 m from such goals.
    server = standin.world.server
    assert server.params.planner_tolerance == NAV2_PLANNER_TOLERANCE == 0.5
    assert not server.costmap.is_free(goal.x, goal.y)
    end = server.goal_point(goal)
    assert end is not None and math.dist(end, (goal.x, goal.y)) <= 0.5
    task = standin.navigate(Navigator.TO_POSE, [goal])
    ending = run_until_done(standin, task)
    assert (ending.outcome, ending.error_code, ending.error_msg) == (Outcome.SUCCEEDED, 0, "")
    robot = standin.world.robot.pose
    # The goal checker is satisfied at the plan's end, not at the goal.
    assert math.dist((robot.x, robot.y), end) <= server.params.xy_tolerance + 0.01
    assert 0.1 < robot.distance_to(goal) <= 0.5 + server.params.xy_tolerance


def test_a_goal_deep_in_a_wall_aborts_with_goal_occupied_at_once(standin: Nav2StandIn):
    assert standin.world.server.goal_point(DEEP_IN_A_WALL) is None
    task = standin.navigate(Navigator.TO_POSE, [DEEP_IN_A_WALL])
    ending = run_until_done(standin, task)
    assert (ending.outcome, ending.error_code) == (Outcome.ABORTED, ErrorCode.GOAL_OCCUPIED)
    assert "no free cell within 0.5 m" in ending.error_msg
    assert standin.time < 0.2
    code, _ = standin.no_plan_reason(standin.world.robot.pose, DEEP_IN_A_WALL)
    assert code == ErrorCode.GOAL_OCCUPIED


def test_without_a_planner_tolerance_a_goal_in_a_pillar_aborts_as_before(grid):
    standin = Nav2StandIn(SimWorld(grid, START), planner_tolerance=0.0)
    task = standin.navigate(Navigator.TO_POSE, [IN_A_PILLAR])
    ending = run_until_done(standin, task)
    assert (ending.outcome, ending.error_code) == (Outcome.ABORTED, ErrorCode.GOAL_OCCUPIED)


def test_cancel_ends_canceled_and_the_robot_brakes_at_once(standin: Nav2StandIn):
    task = standin.navigate(Navigator.TO_POSE, [Pose2D(2.0, 0.5)])
    for _ in range(60):
        standin.step()
    assert standin.world.robot.v > 0.1
    standin.cancel(task)
    assert task.ending is not None and task.ending.outcome is Outcome.CANCELED
    for _ in range(4):  # 0.2 s: the burger brakes at 2.5 m/s²
        standin.step()
    assert standin.world.robot.v == 0.0


def test_through_poses_rolls_past_the_first_pose_without_stopping(standin: Nav2StandIn):
    passing, last = Pose2D(-1.0, -0.5, 0.0), Pose2D(-0.5, -1.7, 0.0)
    task = standin.navigate(Navigator.THROUGH_POSES, [passing, last])
    cruise = standin.world.server.params.limits.max_v
    slowest_near_pass = cruise
    remaining = []
    while task.ending is None:
        standin.step()
        robot = standin.world.robot
        if robot.pose.distance_to(passing) < 0.3:
            slowest_near_pass = min(slowest_near_pass, robot.v)
        if task.ending is None:
            remaining.append(standin.feedback(task).poses_remaining)
        assert standin.time < 120
    assert task.ending.outcome is Outcome.SUCCEEDED
    assert slowest_near_pass > cruise / 2
    assert remaining[0] == 2 and remaining[-1] == 1
    assert standin.world.robot.pose.distance_to(last) < 0.1


def test_feedback_counts_time_and_distance_like_nav2(standin: Nav2StandIn):
    task = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.0, -0.5, 0.0)])
    first = standin.feedback(task)
    assert first.distance_remaining == pytest.approx(1.0, abs=0.05)
    assert first.estimated_time_remaining == 0.0  # standing still: Nav2 gives no ETA
    for _ in range(40):
        standin.step()
    later = standin.feedback(task)
    assert later.navigation_time == pytest.approx(2.0)
    assert later.distance_remaining < first.distance_remaining
    speed = standin.world.robot.v
    assert later.estimated_time_remaining == pytest.approx(later.distance_remaining / speed)


def test_follow_waypoints_stops_at_a_missed_one_by_default(standin: Nav2StandIn):
    run = standin.follow([Pose2D(-1.5, -0.5), DEEP_IN_A_WALL, Pose2D(-1.0, -0.5)])
    ending = run_until_done(standin, run)
    assert ending.outcome is Outcome.ABORTED
    assert [(m.index, m.error_code) for m in run.missed] == [(1, ErrorCode.GOAL_OCCUPIED)]
    assert run.current == 1


def test_follow_waypoints_goes_on_without_stop_on_failure(standin: Nav2StandIn):
    run = standin.follow(
        [Pose2D(-1.5, -0.5), DEEP_IN_A_WALL, Pose2D(-1.0, -0.5)], stop_on_failure=False
    )
    assert run_until_done(standin, run).outcome is Outcome.SUCCEEDED
    assert [m.index for m in run.missed] == [1]
    assert standin.world.robot.pose.distance_to(Pose2D(-1.0, -0.5)) < 0.1


def test_someone_elses_navigate_goal_makes_the_follower_miss_its_waypoint(standin: Nav2StandIn):
    run = standin.follow([Pose2D(2.0, 0.5), Pose2D(-1.0, -0.5)])
    for _ in range(10):
        standin.step()
    standin.navigate(Navigator.TO_POSE, [Pose2D(-1.5, -0.5)])
    standin.step()
    assert run.ending is not None and run.ending.outcome is Outcome.ABORTED
    assert [m.index for m in run.missed] == [0]


def test_loops_repeat_the_waypoints(standin: Nav2StandIn):
    run = standin.follow([Pose2D(-1.5, -0.5), Pose2D(-1.0, -0.5)], loops=1)
    seen = []
    while run.ending is None:
        standin.step()
        if not seen or seen[-1] != run.current:
            seen.append(run.current)
    assert run.ending.outcome is Outcome.SUCCEEDED
    assert seen == [0, 1, 0, 1]


def test_a_bad_goal_index_aborts_the_follower(standin: Nav2StandIn):
    run = standin.follow([Pose2D(-1.5, -0.5)], start_index=3)
    assert run.ending is not None and run.ending.outcome is Outcome.ABORTED


def test_teleport_into_a_pillar_is_refused(standin: Nav2StandIn):
    assert standin.teleport(IN_A_PILLAR) is not None
    assert standin.teleport(Pose2D(-1.5, -0.5, 1.0)) is None
    assert standin.world.robot.pose == Pose2D(-1.5, -0.5, 1.0)


def test_teleop_drives_only_while_no_goal_runs(standin: Nav2StandIn):
    assert standin.command(0.1, 0.0)
    for _ in range(10):
        standin.step()
    assert standin.world.robot.pose.x > START.x + 0.03
    standin.navigate(Navigator.TO_POSE, [Pose2D(-1.0, -0.5)])
    standin.step()
    assert not standin.command(0.0, 1.0)


def test_plan_poses_face_the_next_point_and_end_with_the_goal_yaw():
    poses = plan_poses([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], Pose2D(1.0, 1.0, 3.0))
    assert [round(p.yaw, 3) for p in poses] == [0.0, 1.571, 3.0]


# -- Nav2's re-plan period on preemption (replan_period) ---------------------------------

OLD_GOAL, NEW_GOAL = Pose2D(-1.0, -0.5, 0.0), Pose2D(-0.5, -1.7, 0.0)


def preempt_near_the_old_goal(standin: Nav2StandIn, within: float = 0.4) -> tuple[NavTask, NavTask]:
    """A goal to OLD_GOAL, then, once the robot is ``within`` of it, one to NEW_GOAL (what
    navseq's pass-through does): the two tasks."""
    old = standin.navigate(Navigator.TO_POSE, [OLD_GOAL])
    while standin.world.robot.pose.distance_to(OLD_GOAL) > within:
        standin.step()
        assert standin.time < 30
    return old, standin.navigate(Navigator.TO_POSE, [NEW_GOAL])


def test_with_a_replan_period_a_goal_preempting_near_the_old_goals_end_succeeds_there(grid):
    # A period longer than the drive: the tick comes after the robot has reached OLD_GOAL.
    standin = Nav2StandIn(SimWorld(grid, START), replan_period=10.0)
    old, new = preempt_near_the_old_goal(standin)
    assert old.ending is not None
    assert (old.ending.outcome, old.ending.error_code) == (Outcome.ABORTED, ErrorCode.NONE)
    sent = standin.time
    assert standin.world.server.goal == OLD_GOAL  # the old path is still followed
    # Until the re-plan, Nav2's feedback measures the old path, not the way to NEW_GOAL.
    feedback = standin.feedback(new)
    assert feedback.distance_remaining < 0.45
    assert standin.world.robot.pose.distance_to(NEW_GOAL) > 1.2
    ending = run_until_done(standin, new)
    assert (ending.outcome, ending.error_code, ending.error_msg) == (
        Outcome.SUCCEEDED,
        ErrorCode.NONE,
        "",
    )
    assert new.succeeded_on_old_path
    assert standin.time - sent < 3.0  # well before the tick
    robot = standin.world.robot.pose
    assert robot.distance_to(OLD_GOAL) < 0.1 and robot.distance_to(NEW_GOAL) > 1.2
    for _ in range(10):
        standin.step()
    assert standin.active is None and standin.world.robot.v == 0.0


def test_without_a_replan_period_the_preempting_goal_is_driven_to_its_own_pose(
    standin: Nav2StandIn,
):
    old, new = preempt_near_the_old_goal(standin)
    assert old.ending is not None and old.ending.outcome is Outcome.ABORTED
    assert standin.world.server.goal == NEW_GOAL
    assert run_until_done(standin, new).outcome is Outcome.SUCCEEDED
    assert not new.succeeded_on_old_path
    assert standin.world.robot.pose.distance_to(NEW_GOAL) < 0.1


def test_the_re_plan_tick_comes_a_whole_period_after_the_trees_last_plan(grid):
    # Nav2's 1 Hz: the goal that started the tree planned at 0 s; a preemption at 2.5 s
    # is planned at the 3 s tick, with the old path driven until then.
    standin = Nav2StandIn(SimWorld(grid, START), replan_period=1.0)
    standin.navigate(Navigator.TO_POSE, [Pose2D(2.0, 0.5)])
    while standin.time < 2.5 - 1e-9:
        standin.step()
    new = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.5, -0.5, 0.0)])
    seen = []
    while standin.time < 3.2:
        seen.append((round(standin.time, 2), standin.world.server.goal))
        standin.step()
    switched = next(t for t, goal in seen if goal == Pose2D(-1.5, -0.5, 0.0))
    assert switched == pytest.approx(3.05)  # planned in the step from 3.0 s on
    # A tick far enough from the old goal's end: the new goal is reached, truly.
    assert run_until_done(standin, new).outcome is Outcome.SUCCEEDED
    assert not new.succeeded_on_old_path
    assert standin.world.robot.pose.distance_to(Pose2D(-1.5, -0.5)) < 0.1


def test_a_goal_that_starts_the_tree_is_planned_at_once_even_with_a_replan_period(grid):
    standin = Nav2StandIn(SimWorld(grid, START), replan_period=10.0)
    task = standin.navigate(Navigator.TO_POSE, [OLD_GOAL])
    assert standin.world.server.goal == OLD_GOAL
    assert run_until_done(standin, task).outcome is Outcome.SUCCEEDED
    standin.step()
    # The tree ended with it: the next goal starts a new one, planned at once too.
    again = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.5, -0.5, 0.0)])
    assert standin.world.server.goal == Pose2D(-1.5, -0.5, 0.0)
    assert run_until_done(standin, again).outcome is Outcome.SUCCEEDED
    assert not again.succeeded_on_old_path


def test_a_cancel_before_the_re_plan_tick_stops_the_robot_and_ends_canceled(grid):
    standin = Nav2StandIn(SimWorld(grid, START), replan_period=10.0)
    _old, new = preempt_near_the_old_goal(standin, within=0.6)
    standin.cancel(new)
    assert new.ending is not None and new.ending.outcome is Outcome.CANCELED
    for _ in range(10):
        standin.step()
    assert standin.world.robot.v == 0.0 and standin.active is None
    assert standin.world.robot.pose.distance_to(OLD_GOAL) > 0.3  # it did not drive on


def sim_config(*argv: str, ros1: bool = False) -> SimConfig:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return config_from_args(parser.parse_args(["--map", str(MAP), *argv]), ros1=ros1)


def test_the_replan_period_option_is_off_by_default_and_checked():
    assert sim_config().replan_period == 0.0
    assert sim_config("--replan-period", "1").replan_period == 1.0
    assert sim_config("--replan-period", "0", ros1=True).replan_period == 0.0
    for argv, ros1, message in (
        (("--replan-period", "-1"), False, "must be >= 0 s, got -1"),
        (("--replan-period", "nan"), False, "must be >= 0 s"),
        (("--replan-period", "1"), True, "use it with --ros2"),
    ):
        with pytest.raises(NavseqError) as caught:
            sim_config(*argv, ros1=ros1)
        assert "--replan-period" in str(caught.value) and message in str(caught.value)
