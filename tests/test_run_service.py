"""The run service (``navseq.run``): one typed entry point that every face uses.

A :class:`RunRequest` refuses what cannot be right naming its field; :func:`prepare`
refuses a bad mission, map or navigator choice before anything moves or is written;
:meth:`Session.run` gives a :class:`RunOutcome` whose exit status is the one its report
states; several sessions run at once in one process; and argparse stays in the CLI.
"""

from __future__ import annotations

import ast
import json
import signal
import threading
from pathlib import Path
from typing import Any

import pytest

from cli_support import TURTLEBOT3_MAP, journal_records, write_mission
from navseq.errors import NavseqError
from navseq.executor import events as ev
from navseq.mission.model import Mission, Waypoint
from navseq.navigators.scripted import ScriptedNavigator
from navseq.navigators.settings import Ros1NavigatorSettings, ScriptedNavigatorSettings
from navseq.run import Outputs, RunRequest, UseNavigator, prepare

REPO = Path(__file__).resolve().parents[1]
SOURCE = REPO / "src" / "navseq"

SQUARE = """\
  - {name: a, x: 1.0, y: 0.0, yaw: 90}
  - {name: b, x: 1.0, y: 1.0, yaw: 180}
  - {name: c, x: 0.0, y: 1.0, yaw: -90}
"""


def scripted(script: str = "") -> ScriptedNavigatorSettings:
    return ScriptedNavigatorSettings(scripted_script=script)


# -- the request ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("fields", "field_name", "said"),
    [
        ({}, "mission", "no mission given"),
        ({"mission": Path("m.yaml"), "realtime": 0.0}, "realtime", "above 0"),
        ({"mission": Path("m.yaml"), "loops": 0}, "loops", ">= 1 or 'forever'"),
        ({"mission": Path("m.yaml"), "loops": True}, "loops", ">= 1 or 'forever'"),
        ({"mission": Path("m.yaml"), "tick": float("nan")}, "tick", "above 0"),
        ({"mission": Path("m.yaml"), "server_wait": -1.0}, "server_wait", "above 0"),
        ({"resume": Path("j.jsonl"), "outputs": None}, "outputs", "appends to its journal"),
        (
            {"mission": Mission((Waypoint(1.0, 0.0),))},
            "outputs",
            "give the mission as a file, or ask for no journal",
        ),
    ],
)
def test_a_request_that_cannot_be_right_is_refused_naming_its_field(
    fields: dict[str, Any], field_name: str, said: str
) -> None:
    with pytest.raises(NavseqError) as refused:
        RunRequest(**fields)
    assert refused.value.source == f"RunRequest.{field_name}"
    assert said in refused.value.message


def test_a_loaded_mission_runs_without_files_and_a_request_is_frozen() -> None:
    request = RunRequest(Mission((Waypoint(1.0, 0.0),)), outputs=None)
    with pytest.raises(AttributeError):
        request.realtime = 2.0  # type: ignore[misc]


# -- prepare ----------------------------------------------------------------------------


def test_prepare_refuses_bad_input_before_anything_is_written(tmp_path: Path) -> None:
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    cases: list[tuple[RunRequest, str, str]] = [
        (RunRequest(tmp_path / "nowhere.yaml"), "MISSION", "no such file"),
        (RunRequest(mission, map=tmp_path / "no-map.yaml"), "--map", "no such file"),
        (
            RunRequest(mission, navigator=Ros1NavigatorSettings(), realtime=2.0),
            "--realtime",
            "paces the embedded simulator",
        ),
        (
            RunRequest(mission, navigator=object()),  # type: ignore[arg-type]
            "RunRequest.navigator",
            "no navigator kind's settings",
        ),
        (RunRequest(mission, first=7), None, "waypoint"),
        (RunRequest(mission), None, "the simulator needs a map"),
    ]
    for request, source, said in cases:
        with pytest.raises(NavseqError) as refused:
            prepare(request)
        if source is not None:
            assert refused.value.source == source, refused.value
        assert said in str(refused.value)
    assert not out.exists()
    assert sorted(path.name for path in tmp_path.iterdir()) == ["square.yaml"]


def test_a_start_pose_is_refused_for_a_robot_that_is_where_it_is(tmp_path: Path) -> None:
    from navseq.geometry import Pose2D

    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    request = RunRequest(mission, navigator=Ros1NavigatorSettings(), start=Pose2D(0, 0, 0))
    with pytest.raises(NavseqError, match="the robot is where it is") as refused:
        prepare(request)
    assert refused.value.source == "--start"


# -- the outcome ------------------------------------------------------------------------


def test_outcome_all_reached_is_exit_0_with_the_files_it_names(tmp_path: Path) -> None:
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    session = prepare(RunRequest(mission, navigator=scripted(), outputs=Outputs(out)))
    outcome = session.run()
    assert outcome.exit_status == 0 and outcome.result.success and outcome.error is None
    with pytest.raises(RuntimeError, match="runs once"):
        session.run()
    assert outcome.folder == out and outcome.not_written == {}
    assert outcome.report_path == out / "report.json"
    assert outcome.picture_path == out / "mission.png" and outcome.picture_path.exists()
    assert outcome.journal_path == out / "journal.jsonl"
    report = json.loads(outcome.report_path.read_text())
    assert report["exit_code"] == 0 and report["files"]["picture"] == str(out / "mission.png")


def test_outcome_not_all_reached_is_exit_1_and_the_report_says_so(tmp_path: Path) -> None:
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    outputs = Outputs(tmp_path / "out", picture=False)
    outcome = prepare(RunRequest(mission, navigator=scripted("succeed,aborted"), outputs=outputs))
    ran = outcome.run()
    assert ran.exit_status == 1 and not ran.result.success
    assert ran.picture_path is None and ran.report_path is not None
    assert json.loads(ran.report_path.read_text())["exit_code"] == 1


def test_outcome_of_a_sink_that_fails_is_exit_2_with_the_report_written(tmp_path: Path) -> None:
    mission = write_mission(tmp_path / "square.yaml", SQUARE)

    def failing_sink(event: ev.MissionEvent) -> None:
        if isinstance(event, ev.WaypointFinished):
            raise NavseqError("cannot write it: the disk is full", source="sink")

    session = prepare(RunRequest(mission, navigator=scripted(), outputs=Outputs(tmp_path / "o")))
    outcome = session.run([failing_sink])
    assert outcome.exit_status == 2 and outcome.error is outcome.stopped_by is not None
    assert "the disk is full" in str(outcome.error)
    assert outcome.report_path is not None
    assert json.loads(outcome.report_path.read_text())["exit_code"] == 2


def test_outcome_of_an_interrupted_run_is_128_plus_the_signal_and_the_report_says_so(
    tmp_path: Path,
) -> None:
    from navseq.signals import Terminated

    mission = write_mission(tmp_path / "square.yaml", SQUARE)

    signalled: list[str] = []

    def terminated_after_the_first(event: ev.MissionEvent) -> None:
        if isinstance(event, ev.WaypointFinished) and not signalled:
            signalled.append("SIGTERM")
            raise Terminated("SIGTERM")  # as the guard's handler raises it

    session = prepare(RunRequest(mission, navigator=scripted(), outputs=Outputs(tmp_path / "o")))
    outcome = session.run([terminated_after_the_first])
    assert (outcome.exit_status, outcome.interrupted, outcome.error) == (143, "SIGTERM", None)
    assert outcome.report_path is not None
    report = json.loads(outcome.report_path.read_text())
    assert report["exit_code"] == 143 and report["totals"]["reached"] == 1


def test_a_face_s_own_navigator_runs_without_files_and_without_signal_handlers(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What a ROS node does: its navigator, its listeners, no journal, report or picture."""
    monkeypatch.chdir(tmp_path)
    mission = Mission((Waypoint(1.0, 0.0, name="a"), Waypoint(1.0, 1.0, name="b")))
    navigator = ScriptedNavigator()
    handlers: list[Any] = []
    before = signal.getsignal(signal.SIGINT)

    def listener(event: ev.MissionEvent) -> None:
        handlers.append(signal.getsignal(signal.SIGINT))

    request = RunRequest(mission, navigator=UseNavigator(navigator, {"kind": "node"}), outputs=None)
    outcome = prepare(request).run([listener])
    assert outcome.exit_status == 0 and [v.name for v in outcome.result.visits] == ["a", "b"]
    assert outcome.folder is None and outcome.report_path is None
    assert list(tmp_path.iterdir()) == []  # nothing written anywhere
    assert handlers and all(handler is before for handler in handlers)
    assert len(navigator.sent_goals) == 2  # driven through the face's navigator


def test_a_node_may_ask_for_the_report_and_picture_of_its_own_navigator_s_run(
    tmp_path: Path,
) -> None:
    """No journal (the mission came from parameters, not a file), but report and picture."""
    mission = Mission((Waypoint(1.0, 0.0, name="a"),), source="param ~p_seq")
    request = RunRequest(
        mission,
        navigator=UseNavigator(ScriptedNavigator(), {"kind": "ros1", "action": "move_base"}),
        outputs=Outputs(tmp_path / "out", journal=False),
    )
    outcome = prepare(request).run()
    assert outcome.exit_status == 0 and outcome.journal_path is None
    assert sorted(path.name for path in (tmp_path / "out").iterdir()) == [
        "mission.png",
        "report.json",
    ]
    assert outcome.report_path is not None
    report = json.loads(outcome.report_path.read_text())
    assert report["navigator"] == {"kind": "ros1", "action": "move_base"}
    assert "journal" not in report["files"]


# -- resume -----------------------------------------------------------------------------


def test_a_resume_request_continues_with_the_journaled_settings(tmp_path: Path) -> None:
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    out = tmp_path / "out"
    first = prepare(
        RunRequest(mission, navigator=scripted("succeed,aborted"), outputs=Outputs(out), loops=2)
    ).run()
    assert first.exit_status == 1
    journal = out / "journal.jsonl"
    changed = prepare(RunRequest(resume=journal, navigator=scripted(), loops=1))
    assert changed.notes == ["resuming with --loops 1 instead of the journal's 2"]
    with pytest.raises(NavseqError, match="continues the part of the mission") as refused:
        prepare(RunRequest(resume=journal, navigator=scripted(), first=2))
    assert refused.value.source == "--resume"
    session = prepare(RunRequest(resume=journal, navigator=scripted()))
    assert session.mission.loops == 2 and session.navigator_info["kind"] == "scripted"
    assert session.notes == []
    resumed = session.run()
    assert resumed.exit_status == 0 and resumed.journal_path == journal


# -- several sessions at once -----------------------------------------------------------


def test_two_sim_sessions_run_at_once_in_two_threads_and_keep_to_their_own(
    tmp_path: Path,
) -> None:
    header = f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n"
    south = write_mission(
        tmp_path / "south.yaml",
        "  - {name: s1, x: 0.5, y: -1.6, yaw: 0}\n  - {name: s2, x: 1.6, y: 0.5, yaw: 90}\n",
        header,
    )
    north = write_mission(
        tmp_path / "north.yaml",
        "  - {name: n1, x: -0.5, y: 1.6, yaw: 180}\n"
        "  - {name: n2, x: -1.6, y: -0.5, yaw: -90}\n"
        "  - {name: n3, x: 0.5, y: -1.6, yaw: 0}\n",
        header,
    )
    sessions = {
        name: prepare(RunRequest(path, outputs=Outputs(tmp_path / f"out-{name}")))
        for name, path in (("south", south), ("north", north))
    }
    heard: dict[str, list[str]] = {"south": [], "north": []}
    outcomes: dict[str, Any] = {}
    both_running = threading.Barrier(2, timeout=60)

    def run(name: str) -> None:
        def listener(event: ev.MissionEvent) -> None:
            if isinstance(event, ev.MissionStarted):
                both_running.wait()  # neither finishes before the other has started
            if isinstance(event, ev.WaypointFinished):
                heard[name].append(sessions[name].mission.waypoints[event.index].name or "")

        outcomes[name] = sessions[name].run([listener])

    threads = [threading.Thread(target=run, args=(name,)) for name in sessions]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(120)
    assert heard == {"south": ["s1", "s2"], "north": ["n1", "n2", "n3"]}
    for name, mission in (("south", south), ("north", north)):
        outcome = outcomes[name]
        assert outcome.exit_status == 0 and outcome.folder == tmp_path / f"out-{name}"
        report = json.loads(outcome.report_path.read_text())
        assert [visit["name"] for visit in report["visits"]] == heard[name]
        header_record = journal_records(outcome.journal_path)[0]
        assert header_record["mission_source"] == str(mission.resolve())
        finished = [
            record
            for record in journal_records(outcome.journal_path)
            if record.get("type") == "WaypointFinished"
        ]
        assert len(finished) == len(heard[name])


# -- argparse stays in the CLI ----------------------------------------------------------

#: Where argparse may be used: the CLI, and the ROS packages' own command lines that
#: predate the run service (``navseq record`` and the ROS 2 simulator node's ``main``).
ARGPARSE_ALLOWED = (
    "commands/",
    "cli.py",
    "ros2/sim_node.py",
)


def _argparse_uses(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name == "argparse" for a in node.names):
            found.append(f"{path}:{node.lineno}: import argparse")
        elif isinstance(node, ast.ImportFrom) and node.module == "argparse":
            found.append(f"{path}:{node.lineno}: from argparse import")
        elif isinstance(node, ast.Attribute) and node.attr == "Namespace":
            found.append(f"{path}:{node.lineno}: a Namespace")
    return found


def test_nothing_below_the_cli_sees_argparse() -> None:
    uses = []
    for path in sorted(SOURCE.rglob("*.py")):
        relative = path.relative_to(SOURCE).as_posix()
        if not relative.startswith(ARGPARSE_ALLOWED):
            uses += _argparse_uses(path)
    assert uses == []


def test_the_argparse_check_finds_a_namespace(tmp_path: Path) -> None:
    sample = tmp_path / "sample.py"
    sample.write_text("import argparse as ap\ndef f(args: ap.Namespace) -> None: ...\n")
    assert [use.split(": ", 1)[1] for use in _argparse_uses(sample)] == [
        "import argparse",
        "a Namespace",
    ]


def test_the_run_service_keeps_no_mutable_state_at_module_level() -> None:
    """Sessions share nothing: no module of navseq.run holds a list, dict or set of its own."""
    mutable = (ast.List, ast.Dict, ast.Set, ast.ListComp, ast.DictComp, ast.SetComp)
    found = []
    for path in sorted((SOURCE / "run").glob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
            if isinstance(value, mutable) and not _is_all(node):
                found.append(f"{path.name}:{node.lineno}")
    assert found == []


def _is_all(node: ast.stmt) -> bool:
    targets = node.targets if isinstance(node, ast.Assign) else []
    return any(isinstance(target, ast.Name) and target.id == "__all__" for target in targets)
