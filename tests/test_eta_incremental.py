"""The expected duration after an edit (navseq.eta.incremental): the very figures a
full prediction gives, for any edits, planned and paced visits, one loop or many."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.commands.common import choose_robot, costmap_for_map
from navseq.eta.incremental import IncrementalPrediction
from navseq.eta.memo import RememberedDrives
from navseq.eta.predict import predict_mission
from navseq.mission.loader import mission_from_yaml_text
from navseq.mission.model import Mission
from navseq.route.legs import LegPlanner
from navseq.studio.documents import draft_text

REPO = Path(__file__).resolve().parents[1]
MAP = REPO / "maps/turtlebot3_world.yaml"
# Free spots of the arena, one in a pillar, one outside the map, one outside its wall.
SPOTS = [
    (-2.0, -0.5),
    (-0.55, -1.75),
    (1.75, -0.55),
    (0.55, 0.55),
    (0.0, 1.75),
    (-1.75, 0.55),
    (-0.55, -0.55),
    (0.78, -1.07),
    (1.1, 1.1),
    (9.0, 9.0),
    (-2.6, 0.0),
]


def mission_of(waypoints: list[dict[str, Any]], loops: Any, start: bool) -> Mission:
    document: dict[str, Any] = {"navseq": 1, "map": str(MAP), "waypoints": waypoints}
    if loops != 1:
        document["loops"] = loops
    if start:
        document["start"] = {"x": -2.0, "y": -0.5, "yaw": 0}
    mission = mission_from_yaml_text(draft_text(document).text, "test", REPO)
    assert mission is not None
    return mission


@pytest.fixture(scope="module")
def planner() -> LegPlanner:
    robot = choose_robot(None, mission_of([{"x": 0.0, "y": 1.75}], 1, False))
    return LegPlanner(costmap_for_map(MAP, robot))


waypoint = st.builds(
    lambda spot, yaw, extra: {"x": spot[0], "y": spot[1], "yaw": yaw, **extra},
    st.sampled_from(SPOTS),
    st.sampled_from([0, 90, -135]),
    st.sampled_from([{}, {"dwell": 2}, {"pass_through": 0.3}, {"tasks": [{"wait": 1.5}]}]),
)


@settings(max_examples=40, deadline=None)
@given(
    first=st.lists(waypoint, min_size=1, max_size=9),
    loops=st.sampled_from([1, 2, 3, "forever"]),
    start=st.booleans(),
    planned_share=st.floats(0, 1),
    edits=st.lists(st.lists(st.tuples(st.integers(0, 8), waypoint), min_size=1, max_size=3)),
)
def test_a_prediction_after_edits_is_the_full_prediction(
    planner: LegPlanner,
    first: list[dict[str, Any]],
    loops: Any,
    start: bool,
    planned_share: float,
    edits: list[list[tuple[int, dict[str, Any]]]],
) -> None:
    waypoints = list(first)
    mission = mission_of(waypoints, loops, start)
    robot = choose_robot(None, mission)
    drives = RememberedDrives.on(planner, robot)
    # Some visits planned, the rest paced (a huge mission's), at any split.
    planned = round(planned_share * len(waypoints))
    prediction = IncrementalPrediction(mission, planner, drives, planned_visits=planned)
    for changes in edits:
        moved = set()
        for index, changed in changes:
            index %= len(waypoints)
            waypoints[index] = changed
            moved.add(index)
        mission = mission_of(waypoints, loops, start)
        prediction = prediction.after_edit(mission, moved)
        full = predict_mission(
            mission,
            planner,
            drives.model,
            mission.start,
            speed_cap=drives.speed_cap,
            planned_visits=planned,
            drive=drives,
        )
        assert same_seconds(prediction.expected_s, full.expected_s)
        assert same_seconds(prediction.upper_s, full.upper_s)
        assert same_seconds(prediction.loop_expected_s, full.loop_expected_s)


def same_seconds(got: float | None, wanted: float | None) -> bool:
    """The same seconds (or both none); summed in another order the last bit may differ
    (Python 3.12's sum() of floats is compensated), far below the tenths anyone is shown."""
    if got is None or wanted is None:
        return got is wanted
    return got == pytest.approx(wanted, rel=1e-12, abs=1e-9)


def test_a_paced_waypoint_moved_works_out_its_two_visits_only(planner: LegPlanner) -> None:
    waypoints = [{"x": x, "y": y, "yaw": 0} for x, y in SPOTS[:8] * 5]  # 40 waypoints
    mission = mission_of(waypoints, 1, True)
    drives = RememberedDrives.on(planner, choose_robot(None, mission))
    prediction = IncrementalPrediction(mission, planner, drives, planned_visits=10)
    waypoints[30] = {"x": 1.1, "y": 1.1, "yaw": 0}
    edited = prediction.after_edit(mission_of(waypoints, 1, True), {30})
    assert edited.visits_worked_out == 2  # its own and the next one's straight metres
    assert edited.expected_s != prediction.expected_s
