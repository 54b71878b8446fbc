"""The fleet coordinator for ROS stacks (navseq.fleet.coordinator), ROS-free: robots whose
navigation servers know no right of way (the embedded simulator's fleet with the rule
off, as a Nav2 or move_base stack per robot), each mission run by its own executor in a
thread, the coordinator looking after every step. Without it the same conflicts end
ABORTED "blocked by another robot"; with it every waypoint is reached and no footprints
ever overlap. The same coordinator on the ROS 2 stand-in: tests/test_fleet_ros.py."""

from __future__ import annotations

import itertools
import math
import threading
from dataclasses import dataclass, field

import pytest

from navseq.executor.events import MissionEvent, WaypointFinished
from navseq.executor.result import MissionResult
from navseq.executor.runner import run_mission
from navseq.fleet.coordinator import (
    CoordinatedNavigator,
    CoordinatedRobot,
    FleetCoordinator,
    Mode,
)
from navseq.fleet.lockstep import FleetClock, MemberNavigator
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Policy, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.navigators.base import Goal, GoalAccepted, GoalDone, GoalHeld, GoalReleased
from navseq.signals import SignalGuard
from navseq.sim.fleet_world import FleetRobot, FleetWorld
from navseq.sim.footprint import footprints_overlap
from test_right_of_way import corridor_between_rooms, junction, rooms_with_one_door


@dataclass
class Outcome:
    results: dict[str, MissionResult] = field(default_factory=dict)
    statuses: dict[str, list[str]] = field(default_factory=dict)  # per waypoint's end
    texts: dict[str, str] = field(default_factory=dict)  # each stack's last words at the end
    overlaps: int = 0
    coordinator: FleetCoordinator | None = None
    world: FleetWorld | None = None


def run_fleet(
    grid,
    robots: list[tuple[str, Pose2D, list[Pose2D]]],
    *,
    coordinate: bool = True,
    policy: Policy | None = None,
    right_of_way: bool = False,
    listeners: dict[str, list] | None = None,
) -> Outcome:
    """Each robot with goals runs them as a mission (one executor per thread, the
    mission's defaults ``policy``); robots without stay parked. Returns every mission's
    result and the stacks' statuses. ``right_of_way``: the simulator's own rule instead
    of the coordinator (pass ``coordinate=False`` with it); ``listeners``: more mission
    listeners per robot."""
    world = FleetWorld(grid, [FleetRobot(n, s) for n, s, _ in robots], right_of_way=right_of_way)
    busy = [name for name, _, goals in robots if goals]
    clock = FleetClock(world, busy)
    navigators = {
        name: CoordinatedNavigator(MemberNavigator(world, name, clock), name)
        for name, _, _ in robots
    }
    coordinator = FleetCoordinator(
        grid,
        [CoordinatedRobot(n, navigators[n], DEFAULT_PROFILE) for n, _, _ in robots],
        clock=lambda: world.now,
    )
    coordinator.follow(busy)
    outcome = Outcome(coordinator=coordinator, world=world)
    footprints = world.footprints

    def after_step() -> None:
        if coordinate:
            coordinator.look()
        poses = [w.robot.pose for w in world.worlds]
        for i, j in itertools.combinations(range(len(poses)), 2):
            outcome.overlaps += footprints_overlap(footprints[i], poses[i], footprints[j], poses[j])

    clock.on_step("~coordinator", after_step)

    def member(name: str, goals: list[Pose2D]) -> None:
        statuses = outcome.statuses.setdefault(name, [])

        def hear(event: MissionEvent) -> None:
            if isinstance(event, WaypointFinished):
                statuses.append(f"{event.outcome.value} {event.reason}")

        mission = Mission(
            tuple(Waypoint(g.x, g.y, yaw_rad=g.yaw) for g in goals), defaults=policy or Policy()
        )
        more = (listeners or {}).get(name, [])
        try:
            outcome.results[name] = run_mission(
                mission,
                navigators[name],
                [hear, *more],
                signals=SignalGuard(),
                robot=DEFAULT_PROFILE,
            )
        finally:
            coordinator.leave(name)
            clock.leave(name)

    threads = [
        threading.Thread(target=member, args=(name, goals), daemon=True)
        for name, _, goals in robots
        if goals
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=300)
        assert not thread.is_alive(), "a robot's mission is stuck"
    outcome.texts = {name: world.world(name).server.status_text for name, _, _ in robots}
    return outcome


def all_reached(outcome: Outcome) -> bool:
    return all(result.exit_code == 0 for result in outcome.results.values())


def test_two_robots_swap_the_ends_of_a_one_robot_corridor():
    west, east = Pose2D(2.6, 1.2, 0.0), Pose2D(4.8, 1.2, math.pi)
    outcome = run_fleet(
        corridor_between_rooms(),
        [("a", west, [Pose2D(4.8, 1.2, 0.0)]), ("b", east, [Pose2D(2.6, 1.2, math.pi)])],
    )
    assert all_reached(outcome), outcome.statuses
    assert outcome.overlaps == 0
    assert outcome.coordinator is not None and outcome.coordinator.sent_aside >= 1
    assert outcome.coordinator.held_back >= 1  # a waited while b backed out
    assert not any("blocked" in text for text in outcome.texts.values()), outcome.texts


def test_without_the_coordinator_the_same_swap_ends_aborted_blocked():
    west, east = Pose2D(2.6, 1.2, 0.0), Pose2D(4.8, 1.2, math.pi)
    outcome = run_fleet(
        corridor_between_rooms(),
        [("a", west, [Pose2D(4.8, 1.2, 0.0)]), ("b", east, [Pose2D(2.6, 1.2, math.pi)])],
        coordinate=False,
    )
    assert not all_reached(outcome)
    assert any("failed ABORTED" in found for found in outcome.statuses.values())
    assert any("blocked by another robot" in text for text in outcome.texts.values())


def test_an_idle_robot_parked_on_a_goal_moves_aside_and_stays_there():
    goal = Pose2D(3.7, 1.2, 0.0)  # in the middle of the corridor
    outcome = run_fleet(
        corridor_between_rooms(),
        [("busy", Pose2D(1.2, 1.2, 0.0), [goal, Pose2D(6.2, 1.2, 0.0)]), ("parked", goal, [])],
    )
    assert all_reached(outcome), outcome.statuses
    assert outcome.overlaps == 0
    assert outcome.world is not None
    parked = outcome.world.world("parked").robot.pose
    assert math.hypot(parked.x - goal.x, parked.y - goal.y) > 0.3  # it went out of the way


def test_two_robots_through_one_doorway_at_once():
    left, right = Pose2D(2.2, 1.7, 0.0), Pose2D(4.2, 1.7, math.pi)
    outcome = run_fleet(
        rooms_with_one_door(),
        [("l", left, [Pose2D(5.0, 1.7, 0.0)]), ("r", right, [Pose2D(1.4, 1.7, math.pi)])],
    )
    assert all_reached(outcome), outcome.statuses
    assert outcome.overlaps == 0


class Stack:
    """A navigator double that records what reaches the stack and hands back events."""

    def __init__(self) -> None:
        self.sent: list[Goal] = []
        self.cancels = 0
        self.events: list = []

    def now(self) -> float:
        return 0.0

    def send_goal(self, goal: Goal) -> None:
        self.sent.append(goal)

    def cancel_goal(self) -> None:
        self.cancels += 1

    def poll(self) -> list:
        events, self.events = self.events, []
        return events

    def robot_pose(self) -> Pose2D:
        return Pose2D(0.0, 0.0, 0.0)


def test_a_held_goal_waits_off_the_stack_and_the_executor_never_sees_the_way_aside():
    stack = Stack()
    navigator = CoordinatedNavigator(stack, "r")  # type: ignore[arg-type]
    goal = Goal(7, Pose2D(1.0, 0.0, 0.0))
    navigator.send_goal(goal)
    stack.events = [GoalAccepted(7)]
    assert navigator.poll() == [GoalAccepted(7)]
    navigator.hold("held back for q")
    assert navigator.mode == Mode.HELD and stack.cancels == 1
    stack.events = [GoalDone.failed(7, "CANCELED")]  # the hold's cancel: not the mission's
    # The executor hears that its goal is held (its clocks stand still), not the cancel.
    assert navigator.poll() == [GoalHeld(7, "held back for q")]
    navigator.aside(Pose2D(0.0, 1.0, 0.0), "giving way to q")
    aside = stack.sent[-1]
    assert aside.goal_id < 0
    stack.events = [GoalAccepted(aside.goal_id), GoalDone.succeeded(aside.goal_id)]
    assert navigator.poll() == [] and not navigator.aside_driving  # held already: once
    navigator.release()
    assert stack.sent[-1] == goal  # the mission's goal again, same id
    stack.events = [GoalAccepted(7), GoalDone.succeeded(7)]
    # Released, then the goal's own end; accepted once is enough.
    assert navigator.poll() == [GoalReleased(7), GoalDone.succeeded(7)]
    assert navigator.goal is None and not navigator.busy


def test_a_goal_sent_while_held_waits_for_the_release():
    stack = Stack()
    navigator = CoordinatedNavigator(stack, "r")  # type: ignore[arg-type]
    navigator.send_goal(Goal(1, Pose2D(1.0, 0.0, 0.0)))
    navigator.hold()
    navigator.send_goal(Goal(2, Pose2D(2.0, 0.0, 0.0)))
    assert [g.goal_id for g in stack.sent] == [1]
    assert navigator.poll() == [GoalHeld(1), GoalHeld(2)]  # the new goal is held too
    navigator.release()
    assert [g.goal_id for g in stack.sent] == [1, 2]
    assert navigator.poll() == [GoalReleased(2)]


@pytest.mark.parametrize("mode", ["hold", "aside"])
def test_the_executors_cancel_while_coordinated_leaves_nothing_to_resend(mode: str):
    stack = Stack()
    navigator = CoordinatedNavigator(stack, "r")  # type: ignore[arg-type]
    navigator.send_goal(Goal(1, Pose2D(1.0, 0.0, 0.0)))
    if mode == "hold":
        navigator.hold()
    else:
        navigator.aside(Pose2D(0.0, 1.0, 0.0))
    navigator.cancel_goal()
    sent = len(stack.sent)
    navigator.release()
    assert len(stack.sent) == sent  # nothing of the mission's is sent again


def test_four_robots_cross_a_junction_to_the_opposite_ends():
    ends = {
        "west": Pose2D(0.8, 3.5, 0.0),
        "east": Pose2D(6.2, 3.5, math.pi),
        "south": Pose2D(3.5, 0.8, math.pi / 2),
        "north": Pose2D(3.5, 6.2, -math.pi / 2),
    }
    opposite = {"west": "east", "east": "west", "south": "north", "north": "south"}
    outcome = run_fleet(
        junction(), [(name, ends[name], [ends[other]]) for name, other in opposite.items()]
    )
    assert all_reached(outcome), (outcome.statuses, outcome.texts)
    assert outcome.overlaps == 0
