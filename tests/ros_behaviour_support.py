"""One face for two ROS versions: a scripted server and ``navseq run`` against it.

:class:`Ros1Stack` runs ``ros_scripted_server.py`` (actionlib, on the test's private
rosmaster) and ``navseq run --navigator ros1``; :class:`Ros2Stack` runs
``ros2_scripted_server.py`` (rclpy, on a private ROS_DOMAIN_ID) and ``navseq run
--navigator nav2``. Both servers take the same ``--script`` behaviours, ``--clock``
and ``--cancel``, so a test written once against :class:`ScriptedStack` runs on
both and compares what a user sees: exit status, report, printed events, log lines.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Protocol

import pytest

from cli_support import NAVSEQ, wait_for
from ros2_support import ros2_environment, ros2_prefix
from ros_support import RosMaster, RosProcess

TESTS = Path(__file__).resolve().parent
ROS1_SERVER = TESTS / "ros_scripted_server.py"
ROS2_SERVER = TESTS / "ros2_scripted_server.py"
# The other side of a mission's ROS tasks (topics, a service): see the scripts.
ROS1_TASK_PEER = TESTS / "ros_task_peer.py"
ROS2_TASK_PEER = TESTS / "ros2_task_peer.py"
# A killed process leaves the DDS graph after its lease: 10 s by default in Cyclone DDS.
SHORT_LEASE = (
    "<CycloneDDS><Domain><Discovery><LeaseDuration>1s</LeaseDuration>"
    "</Discovery></Domain></CycloneDDS>"
)
SERVER_READY_WAIT = 60.0
RUN_ARGS = ("--no-preflight", "--json")


class ScriptedStack(Protocol):
    """A scripted navigation server and one ``navseq run`` against it."""

    name: str

    def start_server(self, script: str, *, clock: bool = False, cancel: str = "answer") -> None:
        """Start the server (``--script``, then ``succeed:0.5``); return once it is ready."""
        ...

    def start_navseq(self, mission: Path, out: Path, *extra: str) -> None:
        """``navseq run MISSION`` on this ROS, ``extra`` options added."""
        ...

    def start_task_peer(self, log: Path) -> None:
        """Start the task peer (``ros_task_peer.py`` / ``ros2_task_peer.py``) logging to
        ``log``; return once it is up."""
        ...

    def server_events(self) -> list[str]:
        """The events the server logged so far (goal, cancel, cancel_ignored, jump ...)."""
        ...

    def interrupt(self) -> None:
        """SIGINT to navseq, as Ctrl-C."""
        ...

    def finish(self, timeout: float) -> int:
        """Wait for navseq to exit; its exit status."""
        ...

    def output(self) -> str:
        """Everything navseq wrote so far (stdout and stderr)."""
        ...


class Ros1Stack:
    name = "ros1"

    def __init__(self, master: RosMaster, workdir: Path) -> None:
        self.master = master
        self.log = workdir / "server.jsonl"
        self.navseq: RosProcess | None = None

    def start_server(self, script: str, *, clock: bool = False, cancel: str = "answer") -> None:
        if clock:
            # Before any node starts: rospy reads it once, in init_node.
            self.master.set_param("/use_sim_time", True)
        args = ["--script", script, "--then", "succeed:0.5", "--log", str(self.log)]
        args += ["--cancel", cancel] + (["--clock"] if clock else [])
        server = self.master.start_python(ROS1_SERVER, *args)
        server.wait_for_output("scripted move_base ready", timeout=SERVER_READY_WAIT)

    def start_task_peer(self, log: Path) -> None:
        peer = self.master.start_python(ROS1_TASK_PEER, "--log", str(log))
        peer.wait_for_output("task peer ready", timeout=SERVER_READY_WAIT)

    def start_navseq(self, mission: Path, out: Path, *extra: str) -> None:
        self.navseq = self.master.start(
            [NAVSEQ, "run", mission, "--navigator", "ros1", *RUN_ARGS, "--out", out, *extra],
            cwd=out.parent,
            label="navseq",
        )

    def server_events(self) -> list[str]:
        if not self.log.exists():
            return []
        lines = self.log.read_text().splitlines()
        return [json.loads(line)["event"] for line in lines if line.strip()]

    def interrupt(self) -> None:
        assert self.navseq is not None
        self.navseq.send_signal(signal.SIGINT)

    def finish(self, timeout: float) -> int:
        assert self.navseq is not None
        return self.navseq.wait(timeout)

    def output(self) -> str:
        return "" if self.navseq is None else self.navseq.output()


class Ros2Stack:
    name = "ros2"

    def __init__(self, workdir: Path) -> None:
        prefix = ros2_prefix()
        assert prefix is not None
        self.env = {**ros2_environment(prefix), "CYCLONEDDS_URI": SHORT_LEASE}
        self.workdir = workdir
        self.server: subprocess.Popen[str] | None = None
        self._server_lines: list[str] = []
        self.navseq: subprocess.Popen[str] | None = None
        self.peer: subprocess.Popen[bytes] | None = None
        self._log = workdir / "navseq.log"

    def start_server(self, script: str, *, clock: bool = False, cancel: str = "answer") -> None:
        args = ["--script", script, "--then", "succeed:0.5", "--cancel", cancel]
        args += ["--clock"] if clock else []
        self.server = subprocess.Popen(
            [sys.executable, str(ROS2_SERVER), *args],
            env=self.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        threading.Thread(target=self._read_server, daemon=True).start()
        wait_for(lambda: "ready" in self.server_events(), SERVER_READY_WAIT, "the ROS 2 server")

    def start_task_peer(self, log: Path) -> None:
        self.peer = subprocess.Popen(
            [sys.executable, str(ROS2_TASK_PEER), "--log", str(log)],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

        def up() -> bool:
            return log.exists() and '"ready"' in log.read_text()

        wait_for(up, SERVER_READY_WAIT, "the ROS 2 task peer")

    def _read_server(self) -> None:
        assert self.server is not None and self.server.stdout is not None
        for line in self.server.stdout:
            self._server_lines.append(line)

    def start_navseq(self, mission: Path, out: Path, *extra: str) -> None:
        navigator = ("--navigator", "nav2", *RUN_ARGS)
        with self._log.open("w") as sink:
            self.navseq = subprocess.Popen(
                [NAVSEQ, "run", str(mission), *navigator, "--out", str(out), *extra],
                env=self.env,
                cwd=out.parent,
                stdout=sink,
                stderr=subprocess.STDOUT,
                text=True,
            )

    def server_events(self) -> list[str]:
        events = []
        for line in list(self._server_lines):
            if line.startswith("{"):
                events.append(json.loads(line)["event"])
        return events

    def interrupt(self) -> None:
        assert self.navseq is not None
        self.navseq.send_signal(signal.SIGINT)

    def finish(self, timeout: float) -> int:
        assert self.navseq is not None
        try:
            return self.navseq.wait(timeout)
        except subprocess.TimeoutExpired:
            raise TimeoutError(f"navseq still running:\n{self.output()[-4000:]}") from None

    def output(self) -> str:
        return self._log.read_text(errors="replace") if self._log.exists() else ""

    def stop(self) -> None:
        for process in (self.navseq, self.server, self.peer):
            if process is not None and process.poll() is None:
                process.send_signal(signal.SIGTERM)
                try:
                    process.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()


@pytest.fixture(
    params=[
        pytest.param("ros1", marks=pytest.mark.ros),
        pytest.param("ros2", marks=pytest.mark.ros2),
    ]
)
def stack(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[ScriptedStack]:
    """The same scripted server and ``navseq run``, on ROS 1 and on ROS 2."""
    if request.param == "ros1":
        master: RosMaster = request.getfixturevalue("ros_master")
        yield Ros1Stack(master, tmp_path)  # the master's fixture stops every process
        return
    ros2 = Ros2Stack(tmp_path)
    try:
        yield ros2
    finally:
        ros2.stop()


def report_of(out: Path) -> dict[str, Any]:
    return dict(json.loads((out / "report.json").read_text()))
