"""The studio's check after an edit (navseq.studio.edits): the same answer as a check of
the whole draft, for any sequence of edits, while only what moved is worked out again."""

from __future__ import annotations

import copy
import json
import os
import shutil
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from navseq.studio.app import Studio, StudioConfig
from navseq.studio.http import ApiError
from navseq.studio.security import FileRoots

REPO = Path(__file__).resolve().parents[1]
# Free spots of the TurtleBot3 arena around its pillars, in a tour.
TOUR = [
    (-2.0, -0.5),
    (-0.55, -1.75),
    (1.75, -0.55),
    (0.55, 0.55),
    (0.0, 1.75),
    (-1.75, 0.55),
    (-0.55, -0.55),
    (-0.55, 0.55),
    (0.55, -0.55),
    (0.78, -1.07),
]
# Where an edit may put a waypoint: free, in a pillar, near a wall, outside the map,
# cut off from the arena (outside its wall).
SPOTS = [*TOUR, (1.0, 0.0), (-1.1, -1.1), (0.0, 1.0), (9.0, 9.0), (-2.6, 0.0), (2.4, 2.4)]


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("edits")
    shutil.copytree(REPO / "maps", base / "maps")
    mission = {
        "navseq": 1,
        "map": "maps/turtlebot3_world.yaml",
        "start": {"x": -2.0, "y": -0.5, "yaw": 0},
        "waypoints": [{"x": x, "y": y, "yaw": 0} for x, y in TOUR[1:]],
    }
    (base / "mission.yaml").write_text(json.dumps(mission), encoding="utf-8")
    return base


def studio(workspace: Path) -> Studio:
    roots = FileRoots([workspace], workspace)
    return Studio(StudioConfig("t", roots, mission_path=workspace / "mission.yaml"))


def full_check(checker: Studio, document: dict[str, Any]) -> dict[str, Any]:
    """The draft checked whole: nothing kept from an earlier check of it (the answer's
    number left out: it counts the studio's checks)."""
    checker._last_check = None
    checker._answers.clear()
    return unnumbered(checker.check(document))


def unnumbered(answer: dict[str, Any]) -> dict[str, Any]:
    return {name: value for name, value in answer.items() if name != "check"}


class Page:
    """What the page holds of the last answer: it sends that answer's number as its
    base and patches its legs with the answer's changed ones. An edit of some waypoints
    of the draft it sent for that answer goes as those waypoints only (``changes``), as
    studio.js sends it; anything else, or a base the studio no longer holds (409), as
    the whole draft."""

    def __init__(self, checker: Studio) -> None:
        self.checker = checker
        self.base: int | None = None
        self.sent: dict[str, Any] | None = None  # the draft the server holds as base
        self.legs: list[dict[str, Any]] = []
        self.sent_legs = 0  # legs that came in answers, for the test of their count
        self.sent_changes = 0  # checks sent as their changes
        self.resent = 0  # changes refused (the base's draft was dropped), sent whole

    def changes(self, document: dict[str, Any]) -> list[list[Any]] | None:
        sent = self.sent
        if (
            sent is None
            or self.base is None
            or len(sent["waypoints"]) != len(document["waypoints"])
        ):
            return None
        if {**sent, "waypoints": None} != {**document, "waypoints": None}:
            return None
        changes = [
            [index, waypoint]
            for index, (was, waypoint) in enumerate(
                zip(sent["waypoints"], document["waypoints"], strict=True)
            )
            if was != waypoint
        ]
        return changes if len(changes) <= 64 else None

    def check(self, document: dict[str, Any]) -> dict[str, Any]:
        changes = self.changes(document)
        answer = None
        if changes is not None:
            try:
                answer = self.checker.check(None, self.base, copy.deepcopy(changes))
                self.sent_changes += 1
            except ApiError as error:
                assert error.status == 409 and error.body["conflict"] == "base"
                self.resent += 1
        if answer is None:
            answer = self.checker.check(copy.deepcopy(document), self.base)
        self.sent = copy.deepcopy(document)
        if "legs_changed" in answer:
            assert answer["base"] == self.base
            self.legs = list(self.legs)
            for position, leg in answer["legs_changed"]:
                self.legs[position] = leg
            self.sent_legs += len(answer["legs_changed"])
        else:
            self.legs = answer["legs"]
            self.sent_legs += len(self.legs)
        self.base = answer["check"]
        shown = {
            name: value for name, value in answer.items() if name not in ("base", "legs_changed")
        }
        return unnumbered({**shown, "legs": self.legs})


edit = st.tuples(
    st.integers(0, len(TOUR) - 2),  # which waypoint
    st.sampled_from(SPOTS),
    st.sampled_from([None, 0, 90, -135]),  # a new yaw, or the same
    st.sampled_from(
        [None, {"dwell": 2}, {"pass_through": 0.3}, {"dwell": -1}, {"name": "dock"}, {"y": "a"}]
    ),
)
# Besides moving waypoints: a setting changed, a waypoint added or removed (the whole
# draft sent), or the drafts the studio holds dropped (the changes refused, sent whole).
other = st.sampled_from([None, None, None, "loops", "add", "remove", "forget"])


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    edits=st.lists(st.tuples(st.lists(edit, min_size=0, max_size=3), other), min_size=1, max_size=5)
)
def test_a_check_after_edits_answers_as_a_check_of_the_whole_draft(
    workspace: Path,
    edits: list[tuple[list[tuple[int, tuple[float, float], int | None, Any]], str | None]],
) -> None:
    incremental, whole = studio(workspace), studio(workspace)
    page = Page(incremental)
    document = incremental.mission()["mission"]
    assert page.check(document) == full_check(whole, document)
    for changes, also in edits:
        document = copy.deepcopy(document)
        waypoints = document["waypoints"]
        for index, (x, y), yaw, extra in changes:
            waypoint = waypoints[index % len(waypoints)]
            waypoint.update(x=x, y=y)
            if yaw is not None:
                waypoint["yaw"] = yaw
            if extra is not None:
                waypoint.update(extra)
        if also == "loops":
            document["loops"] = 2 if document.get("loops") == 1 else 1
        elif also == "add":
            waypoints.append({"x": 0.55, "y": -0.55, "yaw": 0})
        elif also == "remove" and len(waypoints) > 2:
            waypoints.pop(1)
        elif also == "forget":
            incremental._held.clear()
        assert page.check(document) == full_check(whole, document)


def test_a_moved_waypoint_changes_its_legs_and_drives_again_no_visit_before_it(
    workspace: Path,
) -> None:
    checker = studio(workspace)
    document = checker.mission()["mission"]
    first = checker.check(document)
    drives = next(iter(checker._drives.values()))[1]
    assert not first["problems"]
    assert drives.driven == len(TOUR) - 1  # every visit driven on paper once
    document = copy.deepcopy(document)
    document["waypoints"][3].update(x=0.6, y=-1.7)
    answer = checker.check(document)
    changed = [
        k for k, (a, b) in enumerate(zip(first["legs"], answer["legs"], strict=True)) if a != b
    ]
    assert changed == [3, 4]  # the legs to and from it (leg 0 comes from the start)
    assert checker.edits_checked == 1
    # The three visits before it are recalled; from it on, each visit starts where the
    # robot stopped at the one before, which may move by a hair (it latches onto its goal).
    assert 2 <= drives.driven - (len(TOUR) - 1) <= len(TOUR) - 1 - 3
    assert unnumbered(answer) == full_check(studio(workspace), document)


def test_a_changed_setting_checks_the_whole_draft(workspace: Path) -> None:
    checker = studio(workspace)
    document = checker.mission()["mission"]
    checker.check(document)
    patrol = {**copy.deepcopy(document), "loops": 2}
    answer = checker.check(patrol)
    assert answer["legs"][-1]["loop"] is True  # the way back to the first waypoint
    assert checker.edits_checked == 0
    assert unnumbered(answer) == full_check(studio(workspace), patrol)


def test_a_map_file_changed_on_disk_checks_the_whole_draft(tmp_path: Path) -> None:
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    mission = {
        "navseq": 1,
        "map": "maps/turtlebot3_world.yaml",
        "waypoints": [{"x": x, "y": y, "yaw": 0} for x, y in TOUR],
    }
    (tmp_path / "mission.yaml").write_text(json.dumps(mission), encoding="utf-8")
    checker = studio(tmp_path)
    document = checker.mission()["mission"]
    checker.check(document)
    # The map saved again (map_server's YAML rewritten, say after mapping once more).
    map_yaml = tmp_path / "maps/turtlebot3_world.yaml"
    stat = map_yaml.stat()
    os.utime(map_yaml, ns=(stat.st_atime_ns, stat.st_mtime_ns + 5_000_000_000))
    document = copy.deepcopy(document)
    document["waypoints"][3].update(x=0.6, y=-1.7)
    assert unnumbered(checker.check(document)) == full_check(studio(tmp_path), document)
    assert checker.edits_checked == 0


def test_a_page_holding_the_last_answer_is_sent_only_the_legs_that_changed(
    workspace: Path,
) -> None:
    checker = studio(workspace)
    page = Page(checker)
    document = checker.mission()["mission"]
    page.check(document)
    assert page.sent_legs == len(TOUR) - 1  # the first answer: every leg
    document = copy.deepcopy(document)
    document["waypoints"][3].update(x=0.6, y=-1.7)
    answer = checker.check(document, page.base)
    assert "legs" not in answer
    assert [position for position, _ in answer["legs_changed"]] == [3, 4]
    # A base the studio no longer knows (or none): every leg.
    assert len(checker.check({**document, "loops": 2}, base=-1)["legs"]) == len(TOUR)


def test_a_drag_is_sent_as_the_waypoint_it_moved_and_answered_as_the_whole_draft(
    workspace: Path,
) -> None:
    checker = studio(workspace)
    page = Page(checker)
    document = checker.mission()["mission"]
    page.check(document)
    assert page.sent_changes == 0  # the first check: the whole draft
    document = copy.deepcopy(document)
    document["waypoints"][3].update(x=0.6, y=-1.7)
    assert page.changes(document) == [[3, document["waypoints"][3]]]
    answer = page.check(document)
    assert page.sent_changes == 1 and page.resent == 0
    assert checker.edits_checked == 1
    assert answer == full_check(studio(workspace), document)


def test_changes_to_a_draft_the_studio_no_longer_holds_are_refused_and_the_page_sends_it_whole(
    workspace: Path,
) -> None:
    from starlette.testclient import TestClient

    from navseq.studio.app import create_app

    checker = studio(workspace)
    client = TestClient(
        create_app(checker.config, checker),
        base_url="http://127.0.0.1:8765",
        headers={"x-navseq-token": "t"},
    )
    document = client.get("/api/mission").json()["mission"]
    first = client.post("/api/check", json={"mission": document}).json()
    moved = {**document["waypoints"][3], "x": 0.6, "y": -1.7}
    # Changes against an answer the studio holds: the draft is that answer's with them.
    answer = client.post("/api/check", json={"base": first["check"], "changes": [[3, moved]]})
    assert answer.status_code == 200
    assert [position for position, _ in answer.json()["legs_changed"]] == [3, 4]
    # A waypoint dropped where it was: that answer again, nothing worked out.
    again = client.post(
        "/api/check", json={"base": answer.json()["check"], "changes": [[3, moved]]}
    ).json()
    assert again["check"] == answer.json()["check"] and again["legs_changed"] == []
    # Against one it does not hold (dropped, or from before a restart): 409, nothing checked.
    for base in (first["check"] + 100, None):
        refused = client.post("/api/check", json={"base": base, "changes": [[3, moved]]})
        assert refused.status_code == 409
        assert refused.json()["conflict"] == "base"
    # studio.js then sends the whole draft, answered in full.
    document["waypoints"][3] = moved
    whole = client.post("/api/check", json={"mission": document}).json()
    assert unnumbered(whole) == json.loads(json.dumps(full_check(studio(workspace), document)))
    # Changes that do not fit the draft: one clear line, 400.
    for changes, said in [
        ([[99, moved]], "changes, item 1: no waypoint at index 99 (the draft has 9)"),
        ([[3, moved], [3]], "changes, item 2: not an [index, waypoint] pair"),
        ({"3": moved}, "changes: give a list of [index, waypoint] pairs"),
        ([["3", moved]], "changes, item 1: the index must be a whole number"),
    ]:
        bad = client.post("/api/check", json={"base": whole["check"], "changes": changes})
        assert bad.status_code == 400
        assert bad.json()["error"] == said
