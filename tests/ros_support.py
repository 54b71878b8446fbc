"""Real ROS 1 for tests: a private rosmaster on a free loopback port, and node processes.

Tests that talk to ROS start their own ``rosmaster`` (never a shared one: ``roslaunch -p
PORT`` silently reuses a live master on that port, so every master gets a fresh port) and
run every ROS client — navseq's node, scripted servers, plain actionlib clients — as a
subprocess. rospy can call ``init_node`` only once per process, so in-process clients
would leak state from one test into the next.

Typical use (the ``ros_master`` fixture in ``conftest.py`` builds the :class:`RosMaster`)::

    def test_something(ros_master):
        server = ros_master.start_python(SCRIPTED_SERVER, "--name", "move_base")
        ros_master.wait_for_action_server("/move_base")
        client = ros_master.start(["navseq-something", "_p_seq:=[1,2,0]"])
        assert client.wait(timeout=30) == 0, client.output()

Everything started through a :class:`RosMaster` is stopped (SIGTERM by PID, then SIGKILL
after a bounded wait) when the fixture ends, and the master's port is free again.
"""

from __future__ import annotations

import contextlib
import http.client
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import xmlrpc.client
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

NodeTable = dict[str, list[str]]  # topic or service name -> names of the nodes behind it

REPO_ROOT = Path(__file__).resolve().parents[1]
TESTS_DIR = Path(__file__).resolve().parent
# The interpreter running the tests is the project's venv; node scripts that say
# `#!/usr/bin/env python3` find it first on PATH.
VENV_BIN = Path(sys.executable).parent


def rospy_available() -> tuple[bool, str]:
    """Whether Debian's ROS 1 Python packages and rosmaster are usable here, and why not."""
    try:
        import actionlib  # noqa: F401
        import rosgraph  # noqa: F401
        import rospy  # noqa: F401
    except ImportError as error:
        return False, f"ROS 1 Python packages not importable ({error}); see DEVELOPERS.md"
    if not _which("rosmaster"):
        return False, "rosmaster executable not found on PATH; see DEVELOPERS.md"
    return True, ""


def _which(program: str) -> str | None:
    for folder in [*os.environ.get("PATH", "").split(os.pathsep), "/usr/bin"]:
        candidate = Path(folder) / program
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return str(candidate)
    return None


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def port_is_free(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        try:
            sock.bind(("127.0.0.1", port))
        except OSError:
            return False
        return True


def wait_for(
    condition: Callable[[], Any],
    timeout: float,
    what: str,
    interval: float = 0.05,
) -> Any:
    """Poll ``condition`` until it returns something truthy; fail the test after ``timeout``.

    Returns the truthy value. ``what`` names the awaited thing in the failure message.
    """
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise TimeoutError(f"timed out after {timeout:.1f} s waiting for {what}")
        time.sleep(interval)


@dataclass
class RosProcess:
    """A process started with the master's environment; output goes to ``log_path``."""

    argv: list[str]
    popen: subprocess.Popen[bytes]
    log_path: Path

    @property
    def pid(self) -> int:
        return self.popen.pid

    def running(self) -> bool:
        return self.popen.poll() is None

    def output(self) -> str:
        """Everything the process wrote to stdout and stderr so far."""
        try:
            return self.log_path.read_text(errors="replace")
        except FileNotFoundError:
            return ""

    def wait(self, timeout: float) -> int:
        """Exit status; raises TimeoutError (with the output) if still running after timeout."""
        try:
            return self.popen.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise TimeoutError(
                f"{self.argv[0]} still running after {timeout:.1f} s; output:\n"
                + self.output()[-4000:]
            ) from None

    def send_signal(self, sig: int) -> None:
        if self.running():
            self.popen.send_signal(sig)

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 10.0) -> int:
        """Signal the process, wait up to ``timeout``, then SIGKILL its process group.

        The process leads its own process group (it was started in a new session), so the
        final SIGKILL also takes down children it spawned (roslaunch's nodes).
        """
        if self.running():
            with contextlib.suppress(ProcessLookupError):
                self.popen.send_signal(sig)
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.popen.wait(timeout=timeout)
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.popen.pid, signal.SIGKILL)
        return self.popen.wait(timeout=timeout)

    def wait_for_output(self, text: str, timeout: float) -> None:
        """Block until ``text`` appears in the output; fail with the output otherwise."""

        def seen() -> bool:
            if text in self.output():
                return True
            if not self.running():
                raise AssertionError(
                    f"{self.argv[0]} exited ({self.popen.returncode}) before printing "
                    f"{text!r}; output:\n{self.output()[-4000:]}"
                )
            return False

        try:
            wait_for(seen, timeout, f"{text!r} in the output of {self.argv[0]}")
        except TimeoutError as error:
            raise TimeoutError(f"{error}; output:\n{self.output()[-4000:]}") from None


@dataclass
class RosMaster:
    """A private rosmaster and the processes started against it."""

    port: int
    workdir: Path
    popen: subprocess.Popen[bytes] | None = None
    processes: list[RosProcess] = field(default_factory=list)

    @property
    def uri(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    @property
    def env(self) -> dict[str, str]:
        """Environment for anything that should talk to this master (and only to it)."""
        env = dict(os.environ)
        for leaked in ("ROS_NAMESPACE", "ROS_HOSTNAME"):
            env.pop(leaked, None)
        env.update(
            ROS_MASTER_URI=self.uri,
            ROS_IP="127.0.0.1",
            ROS_HOME=str(self.workdir / "ros_home"),
            ROS_LOG_DIR=str(self.workdir / "ros_log"),
            PATH=os.pathsep.join([str(VENV_BIN), env.get("PATH", "/usr/bin:/bin")]),
            PYTHONUNBUFFERED="1",
            PYTHONDONTWRITEBYTECODE="1",
        )
        # The repo is a catkin package: put it on ROS_PACKAGE_PATH for roslaunch/rosrun.
        package_path = [str(REPO_ROOT)]
        if os.environ.get("ROS_PACKAGE_PATH"):
            package_path.append(os.environ["ROS_PACKAGE_PATH"])
        env["ROS_PACKAGE_PATH"] = os.pathsep.join(package_path)
        return env

    # -- lifecycle -------------------------------------------------------------------

    def start_master(self, timeout: float = 15.0) -> None:
        log = self.workdir / "rosmaster.log"
        with open(log, "wb") as sink:
            self.popen = subprocess.Popen(
                ["rosmaster", "--core", "-p", str(self.port), "-w", "3"],
                env=self.env,
                stdout=sink,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                start_new_session=True,
            )

        def answers() -> bool:
            if self.popen is not None and self.popen.poll() is not None:
                raise RuntimeError(
                    f"rosmaster on port {self.port} exited with {self.popen.returncode}:\n"
                    + log.read_text(errors="replace")[-2000:]
                )
            return self.master_online()

        wait_for(answers, timeout, f"rosmaster at {self.uri}")

    def master_online(self) -> bool:
        try:
            code, _, _ = self._master().getPid("/ros_support")
        except (OSError, xmlrpc.client.Error):
            return False
        return code == 1

    def shutdown(self, timeout: float = 10.0) -> None:
        """Stop every started process (newest first), then the master; wait for the port."""
        for process in reversed(self.processes):
            process.stop(signal.SIGTERM, timeout=timeout)
        if self.popen is not None and self.popen.poll() is None:
            # rosmaster started in the background ignores SIGINT; SIGTERM ends it.
            self.popen.send_signal(signal.SIGTERM)
            try:
                self.popen.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait(timeout=timeout)
        self._stop_leftovers(timeout)
        with contextlib.suppress(TimeoutError):
            wait_for(lambda: port_is_free(self.port), timeout, f"port {self.port} to be free")

    def _leftovers(self) -> list[int]:
        """Processes still running with this master's log folder in their environment.

        roslaunch starts each node in a session of its own, so a roslaunch killed before
        its nodes were down (it gives a node 15 s after SIGINT; stop() gives roslaunch
        10 s) leaves them running, orphaned: a simulated move_base left so kept a core
        busy for the rest of a test run.
        """
        marker = f"ROS_LOG_DIR={self.workdir / 'ros_log'}".encode()
        found = []
        for entry in Path("/proc").iterdir():
            if not entry.name.isdigit() or int(entry.name) == os.getpid():
                continue
            try:
                environ = (entry / "environ").read_bytes()
            except OSError:  # gone meanwhile, or not ours to read
                continue
            if marker in environ.split(b"\0"):
                found.append(int(entry.name))
        return found

    def _stop_leftovers(self, timeout: float) -> None:
        for sig in (signal.SIGTERM, signal.SIGKILL):
            pids = self._leftovers()
            for pid in pids:
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.kill(pid, sig)
            if not pids:
                return
            with contextlib.suppress(TimeoutError):
                wait_for(lambda: not self._leftovers(), timeout / 2, "leftover ROS processes")

    # -- processes -------------------------------------------------------------------

    def start(
        self,
        argv: Sequence[str],
        *,
        env: Mapping[str, str] | None = None,
        cwd: Path | None = None,
        label: str | None = None,
    ) -> RosProcess:
        """Start ``argv`` with this master's environment (plus ``env``) in its own session."""
        argv = [str(part) for part in argv]
        name = label or Path(argv[0]).name
        log_path = self.workdir / f"{len(self.processes):02d}-{name}.log"
        full_env = self.env
        if env:
            full_env.update(env)
        with open(log_path, "wb") as sink:
            popen = subprocess.Popen(
                argv,
                env=full_env,
                cwd=str(cwd or REPO_ROOT),
                stdout=sink,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                start_new_session=True,
            )
        process = RosProcess(argv=argv, popen=popen, log_path=log_path)
        self.processes.append(process)
        return process

    def start_python(self, script: Path | str, *args: str, **kwargs: Any) -> RosProcess:
        """Run a Python script (or ``-m module``) with the venv's interpreter."""
        script = str(script)
        label = kwargs.pop("label", None) or Path(args[0] if script == "-m" else script).stem
        return self.start([sys.executable, script, *args], label=label, **kwargs)

    # -- master queries (XML-RPC; no rospy.init_node in the test process) ---------------

    def _master(self) -> xmlrpc.client.ServerProxy:
        return xmlrpc.client.ServerProxy(self.uri)

    def _call(self, method: str, *args: Any) -> Any:
        code, message, value = getattr(self._master(), method)("/ros_support", *args)
        if code != 1:
            raise RuntimeError(f"master {method}{args}: {message}")
        return value

    def set_param(self, name: str, value: Any) -> None:
        self._call("setParam", name, value)

    def get_param(self, name: str, default: Any = None) -> Any:
        code, _, value = self._master().getParam("/ros_support", name)
        return value if code == 1 else default

    def has_param(self, name: str) -> bool:
        return bool(self._call("hasParam", name))

    def system_state(self) -> tuple[NodeTable, NodeTable, NodeTable]:
        """(publishers, subscribers, services): each maps a name to the nodes behind it."""
        publishers, subscribers, services = self._call("getSystemState")
        return (
            {name: nodes for name, nodes in publishers},
            {name: nodes for name, nodes in subscribers},
            {name: nodes for name, nodes in services},
        )

    def node_names(self) -> set[str]:
        names: set[str] = set()
        for table in self.system_state():
            for nodes in table.values():
                names.update(nodes)
        return names

    def wait_for_publisher(self, topic: str, timeout: float = 15.0) -> None:
        wait_for(lambda: self.system_state()[0].get(topic), timeout, f"a publisher of {topic}")

    def wait_for_subscriber(self, topic: str, timeout: float = 15.0) -> None:
        wait_for(lambda: self.system_state()[1].get(topic), timeout, f"a subscriber of {topic}")

    def wait_for_service(self, service: str, timeout: float = 15.0) -> None:
        wait_for(lambda: self.system_state()[2].get(service), timeout, f"service {service}")

    def wait_for_node(self, node: str, timeout: float = 15.0) -> None:
        wait_for(lambda: node in self.node_names(), timeout, f"node {node}")

    def wait_for_action_server(self, action: str, timeout: float = 15.0) -> None:
        """An actionlib server registers: publishes ``<action>/status``, subscribes ``/goal``."""
        action = action.rstrip("/")

        def ready() -> bool:
            publishers, subscribers, _ = self.system_state()
            return bool(publishers.get(f"{action}/status")) and bool(
                subscribers.get(f"{action}/goal")
            )

        wait_for(ready, timeout, f"action server {action}")

    def kill_node(self, node: str) -> None:
        """What ``rosnode kill`` does: ask the node over XML-RPC to shut down."""
        uri = self._call("lookupNode", node)
        # A node may close its XML-RPC server while handling the request (rosnode
        # ignores this too); tests assert what the node did, not this reply.
        with contextlib.suppress(OSError, xmlrpc.client.ProtocolError, http.client.HTTPException):
            xmlrpc.client.ServerProxy(uri).shutdown("/ros_support", "killed by the test")

    def call_service(
        self, service: str, srv_type: str = "std_srvs/Trigger", timeout: float = 20.0
    ) -> dict[str, Any]:
        """Call a service with an empty request from a subprocess; the response as a dict.

        (Debian ships no ``rosservice`` command, and rospy belongs in subprocesses.)
        """
        package, name = srv_type.split("/")
        code = (
            "import json, sys, rospy, importlib\n"
            f"srv = getattr(importlib.import_module('{package}.srv'), '{name}')\n"
            f"rospy.wait_for_service('{service}', timeout=10)\n"
            f"response = rospy.ServiceProxy('{service}', srv)()\n"
            "print('RESPONSE ' + json.dumps({k: getattr(response, k) "
            "for k in response.__slots__}), flush=True)\n"
        )
        caller = self.start([sys.executable, "-c", code], label="service-call")
        status = caller.wait(timeout)
        for line in caller.output().splitlines():
            if line.startswith("RESPONSE "):
                return dict(json.loads(line[len("RESPONSE ") :]))
        raise RuntimeError(f"calling {service} failed ({status}):\n{caller.output()[-3000:]}")

    def wait_for_action_server_gone(self, action: str, timeout: float = 15.0) -> None:
        action = action.rstrip("/")
        wait_for(
            lambda: not self.system_state()[0].get(f"{action}/status"),
            timeout,
            f"action server {action} to unregister",
        )


@contextlib.contextmanager
def running_master(workdir: Path | None = None, attempts: int = 3) -> Iterator[RosMaster]:
    """A fresh rosmaster on a free loopback port for the duration of the ``with`` block."""
    with contextlib.ExitStack() as stack:
        if workdir is None:
            workdir = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="navseq-ros-")))
        workdir.mkdir(parents=True, exist_ok=True)
        last_error: Exception | None = None
        for _ in range(attempts):
            # Another process may grab the port between free_port() and rosmaster's bind.
            master = RosMaster(port=free_port(), workdir=workdir)
            try:
                master.start_master()
            except (RuntimeError, TimeoutError) as error:
                last_error = error
                master.shutdown(timeout=5.0)
                continue
            try:
                yield master
            finally:
                master.shutdown()
            return
        raise RuntimeError(f"could not start rosmaster after {attempts} attempts: {last_error}")
