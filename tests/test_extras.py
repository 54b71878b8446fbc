"""The optional extras: navseq[studio] (starlette, uvicorn), navseq[plan] (OR-tools) and
navseq[record] (mcap and its ROS support).

Each test runs navseq in a fresh Python whose import of the extras' modules fails, as
on a machine where navseq was installed without them (a ROS node's install): what
needs an extra says which ``pip install`` brings it, exit 2, no traceback; everything
else works as before.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
MISSION = "examples/turtlebot3_world.yaml"

WITHOUT_PRELUDE = textwrap.dedent(
    """
    import importlib.abc, sys

    BLOCKED = tuple(sys.argv.pop(1).split(","))

    class NotInstalled(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None

    sys.meta_path.insert(0, NotInstalled())
    """
)
CLI = "import sys\nfrom navseq.cli import main\nsys.exit(main(sys.argv[1:]))\n"
STUDIO = ("starlette", "uvicorn")
PLAN = ("ortools",)
RECORD = ("mcap", "mcap_ros2", "mcap_ros1")
EVERY_EXTRA = STUDIO + PLAN + RECORD


def run_without(
    blocked: tuple[str, ...], code: str, *args: str, cwd: Path = REPO
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", WITHOUT_PRELUDE + textwrap.dedent(code), ",".join(blocked), *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )


def assert_one_clear_message(done: subprocess.CompletedProcess[str], extra: str) -> None:
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert f"pip install 'navseq[{extra}]'" in lines[0]


def test_navseq_studio_without_its_extra_names_it() -> None:
    done = run_without(EVERY_EXTRA, CLI, "studio", MISSION, "--no-browser")
    assert_one_clear_message(done, "studio")
    assert "starlette and uvicorn, which are not installed" in done.stderr
    assert done.stdout == ""  # no URL: nothing listens


def test_navseq_studio_names_the_one_module_missing() -> None:
    done = run_without(("uvicorn",), CLI, "studio", MISSION, "--no-browser")
    assert_one_clear_message(done, "studio")
    assert "needs uvicorn, which is not installed" in done.stderr


def test_the_shortest_order_without_or_tools_names_the_plan_extra(tmp_path: Path) -> None:
    out = tmp_path / "ordered.yaml"
    done = run_without(PLAN, CLI, "plan", MISSION, "--order", "shortest", "--out", str(out))
    assert_one_clear_message(done, "plan")
    assert done.stderr.startswith("navseq plan: --order shortest needs ortools")
    assert not out.exists()


def test_navseq_plan_in_the_files_order_needs_no_or_tools() -> None:
    done = run_without(EVERY_EXTRA, CLI, "plan", MISSION, "--json")
    assert done.returncode == 0, done.stderr
    route = json.loads(done.stdout)
    assert route["every_leg_has_a_path"] and route["order"] == list(range(1, 8))


def test_order_waypoints_without_or_tools_raises_the_same_clear_error() -> None:
    done = run_without(
        PLAN,
        """
        import navseq
        from navseq.extras import MissingExtra
        mission = navseq.load_mission("examples/turtlebot3_world.yaml")
        try:
            navseq.order_waypoints(mission)
        except MissingExtra as error:
            print(error.extra, "|", error)
        """,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == (
        "plan | the shortest order needs ortools, which is not installed: "
        "pip install 'navseq[plan]'"
    )


def test_the_studios_order_without_or_tools_answers_with_the_extra(tmp_path: Path) -> None:
    done = run_without(
        PLAN,
        """
        import json, sys
        from pathlib import Path
        from starlette.testclient import TestClient
        from navseq.studio.app import StudioConfig, create_app
        from navseq.studio.security import FileRoots

        mission = Path("examples/turtlebot3_world.yaml").resolve()
        roots = FileRoots([mission.parent, Path("maps").resolve()], mission.parent)
        config = StudioConfig(token="t", roots=roots, mission_path=mission,
                              out_base=Path(sys.argv[1]))
        client = TestClient(
            create_app(config), base_url="http://127.0.0.1", headers={"x-navseq-token": "t"}
        )
        document = client.get("/api/mission").json()["mission"]
        answer = client.post("/api/order", json={"mission": document})
        print(json.dumps({"status": answer.status_code, "body": answer.json()}))
        """,
        str(tmp_path / "out"),
    )
    assert done.returncode == 0, done.stderr
    answer = json.loads(done.stdout)
    assert answer["status"] == 501
    assert answer["body"] == {
        "error": "the shortest order needs ortools, which is not installed: "
        "pip install 'navseq[plan]'"
    }


def test_the_core_commands_load_no_extra() -> None:
    done = run_without(
        EVERY_EXTRA,
        """
        import importlib, json, sys
        import navseq
        for name in ("navseq.cli", "navseq.api", "navseq.commands.run",
                     "navseq.commands.validate", "navseq.commands.convert",
                     "navseq.commands.sim", "navseq.commands.report", "navseq.commands.plan",
                     "navseq.commands.studio", "navseq.route.order"):
            importlib.import_module(name)
        print(json.dumps(sorted(m for m in sys.modules if m.split(".")[0] in BLOCKED)))
        """,
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == []


@pytest.mark.slow
def test_run_validate_convert_and_report_work_without_any_extra(tmp_path: Path) -> None:
    def navseq(*args: str) -> subprocess.CompletedProcess[str]:
        return run_without(EVERY_EXTRA, CLI, *args)

    validated = navseq("validate", MISSION, "--map", "maps/turtlebot3_world.yaml")
    assert validated.returncode == 0, validated.stderr
    converted = navseq(
        "convert", "examples/tutorial_move_base_seq.launch", str(tmp_path / "m.yaml")
    )
    assert converted.returncode == 0, converted.stderr
    out = tmp_path / "out"
    ran = navseq("run", MISSION, "--out", str(out), "--json")
    assert ran.returncode == 0, ran.stderr
    assert json.loads((out / "report.json").read_text())["success"] is True
    (out / "report.json").unlink()
    reported = navseq("report", str(out))
    assert reported.returncode == 0, reported.stderr
    assert json.loads((out / "report.json").read_text())["success"] is True
    assert navseq("sim", "--help").returncode == 0


def test_recording_without_mcap_names_the_record_extra_before_the_robot_moves(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    done = run_without(RECORD, CLI, "run", MISSION, "--record", "--out", str(out))
    assert_one_clear_message(done, "record")
    assert "recording the run (--record) needs mcap and mcap_ros2 and mcap_ros1" in done.stderr
    assert not out.exists()  # nothing written, nothing driven
