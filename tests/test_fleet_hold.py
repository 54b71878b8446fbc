"""A robot the fleet holds back keeps its goal's timeouts for its own driving (issue 21).

Two robots swap the ends of a corridor one robot wide: the second waits in its room,
sent aside, while the first drives through — about 35 s, longer than the missions'
``goal_timeout`` (25 s) and far longer than their ``stall_timeout`` (8 s). Time held
(waiting, giving way) does not count against either, so both reach their goals, and
the result and the events say how long each was held. The same on the embedded
simulator's right of way and with navseq's fleet coordinator (ROS stacks' stand-in).
"""

from __future__ import annotations

import math

import pytest

from navseq.executor.events import MissionEvent, WaypointHeld, WaypointReleased
from navseq.geometry import Pose2D
from navseq.mission.model import Policy
from test_fleet_coordinator import all_reached, run_fleet
from test_right_of_way import corridor_between_rooms

GOAL_TIMEOUT = 25.0
STALL_TIMEOUT = 8.0


@pytest.mark.parametrize("rule", ["simulator", "coordinator"])
def test_a_robot_giving_way_longer_than_its_goal_timeout_still_reaches_its_goal(rule: str):
    west, east = Pose2D(2.6, 1.2, 0.0), Pose2D(4.8, 1.2, math.pi)
    heard: dict[str, list[MissionEvent]] = {"a": [], "b": []}
    outcome = run_fleet(
        corridor_between_rooms(),
        [("a", west, [Pose2D(4.8, 1.2, 0.0)]), ("b", east, [Pose2D(2.6, 1.2, math.pi)])],
        coordinate=rule == "coordinator",
        right_of_way=rule == "simulator",
        policy=Policy(goal_timeout_s=GOAL_TIMEOUT, stall_timeout_s=STALL_TIMEOUT),
        listeners={name: [events.append] for name, events in heard.items()},
    )
    assert all_reached(outcome), outcome.statuses
    assert outcome.overlaps == 0
    [visit] = outcome.results["b"].visits
    # b's leg took longer than its goal timeout: the time held is what was not counted.
    assert visit.duration_s > GOAL_TIMEOUT
    assert visit.duration_s - visit.held_s < GOAL_TIMEOUT
    assert [a.reason for a in visit.attempt_results] == [""]  # one attempt, no timeout
    holds = [e for e in heard["b"] if isinstance(e, WaypointHeld)]
    releases = [e for e in heard["b"] if isinstance(e, WaypointReleased)]
    assert holds and len(releases) == len(holds)
    assert "a" in holds[0].reason  # "giving way to a", "held back for a" ...
    assert sum(e.held_for for e in releases) == pytest.approx(visit.held_s)
