"""Real ROS 2 for tests: the environment a ROS 2 process needs, and isolated runs.

ROS 2 is found in ``$NAVSEQ_ROS2_PREFIX``, else ``/opt/ros2min`` (where
``scripts/install-ros2-min.sh`` unpacks the test machine's minimal Jazzy), else an
already sourced ROS 2 (``$AMENT_PREFIX_PATH``). Tests never import rclpy in the pytest
process: ``LD_LIBRARY_PATH`` must be set before a process starts, and rclpy, like rospy,
keeps global state. Every ROS 2 client and server runs as a subprocess started with
:func:`ros2_environment`, which gives the run its own ``ROS_DOMAIN_ID`` (leased: see
:func:`private_domain_id`) and keeps DDS discovery on the loopback.
"""

from __future__ import annotations

import fcntl
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
from collections import OrderedDict
from collections.abc import Mapping
from pathlib import Path
from typing import IO

DEFAULT_PREFIX = Path("/opt/ros2min")
PYTHON_DIR = f"python{sys.version_info.major}.{sys.version_info.minor}"

# Domain IDs 1-101: with CycloneDDS's port mapping, higher IDs reach Linux's ephemeral
# ports (0 is everyone's default domain).
DOMAIN_IDS = range(1, 102)
DOMAIN_LOCKS = Path(tempfile.gettempdir()) / "navseq-ros2-domains"
# How many domains one test process keeps leased: tests in a process run one after
# another, so only the newest few can still have processes up (a module's shared sim
# node); older leases go back to the pool for the other xdist workers and test runs.
LEASES_PER_PROCESS = 12
_leases: OrderedDict[int, IO[str]] = OrderedDict()


def private_domain_id() -> int:
    """A ROS_DOMAIN_ID that no other test process on this machine holds right now.

    xdist workers and other test runs pick at the same time: a random pick could give two
    live tests one domain, and each would see the other's nodes and goals. Each domain
    is leased by an exclusive lock on its file in ``DOMAIN_LOCKS``, held until this
    process has leased ``LEASES_PER_PROCESS`` newer ones or exits (the kernel drops the
    lock of a crashed process). Were every domain held, this process's oldest lease is
    reused.
    """
    DOMAIN_LOCKS.mkdir(exist_ok=True)
    for domain in random.sample(DOMAIN_IDS, len(DOMAIN_IDS)):
        if domain in _leases:
            continue
        try:
            handle = open(DOMAIN_LOCKS / f"{domain}.lock", "a")  # noqa: SIM115 (held open)
        except OSError:  # another user's lock file
            continue
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        _leases[domain] = handle
        while len(_leases) > LEASES_PER_PROCESS:
            _, oldest = _leases.popitem(last=False)
            oldest.close()  # closing the file drops its lock
        return domain
    if _leases:
        domain, handle = _leases.popitem(last=False)
        _leases[domain] = handle
        return domain
    return random.choice(DOMAIN_IDS)


def ros2_prefix() -> Path | None:
    """The install prefix of a usable ROS 2 (one that has rclpy), or None."""
    candidates = [os.environ.get("NAVSEQ_ROS2_PREFIX", ""), str(DEFAULT_PREFIX)]
    candidates += os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
    for candidate in candidates:
        if (
            candidate
            and (Path(candidate) / "lib" / PYTHON_DIR / "site-packages" / "rclpy").is_dir()
        ):
            return Path(candidate)
    return None


def ros2_environment(
    prefix: Path, domain_id: int | None = None, base: Mapping[str, str] | None = None
) -> dict[str, str]:
    """The environment of a ROS 2 process: the prefix's paths first, a private domain."""
    env = dict(os.environ if base is None else base)

    def first(variable: str, path: Path) -> None:
        rest = [part for part in env.get(variable, "").split(os.pathsep) if part]
        env[variable] = os.pathsep.join([str(path), *rest])

    first("AMENT_PREFIX_PATH", prefix)
    first("PYTHONPATH", prefix / "lib" / PYTHON_DIR / "site-packages")
    # Debian 12 has unrelated ROS 2 libraries with another ABI: this tree's lib first.
    first("LD_LIBRARY_PATH", prefix / "lib")
    first("PATH", prefix / "bin")
    env["ROS_DOMAIN_ID"] = str(private_domain_id() if domain_id is None else domain_id)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.pop("ROS_LOCALHOST_ONLY", None)  # deprecated in Jazzy: every process would warn
    env["RMW_IMPLEMENTATION"] = "rmw_cyclonedds_cpp"
    return env


def ros2_available() -> tuple[bool, str]:
    """Whether rclpy and nav2_msgs import in a ROS 2 process here, and why not."""
    prefix = ros2_prefix()
    if prefix is None:
        return False, (
            "no ROS 2 found (set NAVSEQ_ROS2_PREFIX, source ROS 2, or run "
            "scripts/install-ros2-min.sh)"
        )
    probe = subprocess.run(
        [sys.executable, "-c", "import rclpy, nav2_msgs.action"],
        env=ros2_environment(prefix),
        capture_output=True,
        text=True,
        timeout=60,
    )
    if probe.returncode != 0:
        return False, f"rclpy does not import from {prefix}: {probe.stderr.strip()[-300:]}"
    return True, ""


class SimNode:
    """A running ``python -m navseq.ros2.sim_node ARGS`` (the simulated robot and Nav2's
    interfaces); its stdout is read as it comes, and it is ready when it says so."""

    def __init__(self, env: dict[str, str], *args: str) -> None:
        self.env = env
        self.process = subprocess.Popen(
            [sys.executable, "-m", "navseq.ros2.sim_node", *args],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.stdout: list[str] = []
        self.ready = threading.Event()
        threading.Thread(target=self._read, daemon=True).start()
        if not self.ready.wait(60):
            self.process.kill()
            _, err = self.process.communicate()
            raise AssertionError(f"sim node not ready: {self.stdout} {err}")

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.stdout.append(line)
            if "ready" in line:
                self.ready.set()

    def stop(self, signum: int = signal.SIGINT) -> str:
        """Stop it (``signum``, then a kill after 20 s); its stderr, the node's log.
        ``process.returncode`` is its exit status."""
        if self.process.poll() is None:
            self.process.send_signal(signum)
        try:
            self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        assert self.process.stderr is not None
        return self.process.stderr.read()
