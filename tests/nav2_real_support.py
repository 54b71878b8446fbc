"""The real Nav2 (Jazzy) on its loopback simulator, for tests and benchmarks.

``../shared/ros2/nav2-jazzy-*.tar.zst`` carries the real Nav2 servers (bt_navigator,
planner, controller with Regulated Pure Pursuit, behaviours, waypoint follower, ...) and
Nav2's ``nav2_loopback_sim``; ``scripts/install-nav2.sh`` unpacks it into ``/opt/nav2``
(``$NAVSEQ_NAV2_PREFIX``). :class:`RealNav2` launches ``tests/nav2/nav2_loopback.launch.py``
(nav2_bringup's default parameters, RPP controller, everything on the loopback sim's
``/clock``) on a map, on a private ``ROS_DOMAIN_ID`` with discovery on the loopback, puts
the robot at a start pose and stops every process it started.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from ros2_support import ros2_environment

NAV2_DIR = Path(__file__).resolve().parent / "nav2"
DEFAULT_NAV2_PREFIX = Path("/opt/nav2")
READY_TIMEOUT = 120.0  # s: the bringup is active about 10 s after launch on 2 cores


def nav2_prefix() -> Path | None:
    """The unpacked real Nav2 tree, or None."""
    for candidate in (os.environ.get("NAVSEQ_NAV2_PREFIX", ""), str(DEFAULT_NAV2_PREFIX)):
        if candidate and (Path(candidate) / "share" / "nav2_bt_navigator").is_dir():
            return Path(candidate)
    return None


def nav2_missing_reason() -> str | None:
    """Why the real-Nav2 tests cannot run here, or None."""
    if nav2_prefix() is None:
        return "no real Nav2 tree (scripts/install-nav2.sh unpacks ../shared/ros2's)"
    return None


class RealNav2:
    """A running real Nav2 bringup; ``env`` is the environment of its clients."""

    def __init__(self, map_yaml: Path, log_dir: Path, *launch_args: str) -> None:
        prefix = nav2_prefix()
        assert prefix is not None, nav2_missing_reason()
        self.env = ros2_environment(prefix)
        self.env["RCUTILS_COLORIZED_OUTPUT"] = "0"
        log_dir.mkdir(parents=True, exist_ok=True)
        # ros2 launch writes every node's parameters to a temporary file it never removes.
        self.env["TMPDIR"] = str(log_dir)
        self.log_path = log_dir / "nav2-launch.log"
        self._log = self.log_path.open("w")
        self.process = subprocess.Popen(
            [
                "ros2",
                "launch",
                str(NAV2_DIR / "nav2_loopback.launch.py"),
                f"map:={map_yaml}",
                *launch_args,  # e.g. keepout_mask:=..., speed_mask:=...
            ],
            env=self.env,
            stdout=self._log,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # one process group: stop() ends every node
        )

    def place(self, x: float, y: float, yaw_deg: float, timeout: float = READY_TIMEOUT) -> None:
        """Put the robot at (x, y, yaw) and wait until Nav2 takes goals."""
        script = NAV2_DIR / "nav2_ready.py"
        result = subprocess.run(
            [sys.executable, str(script), *map(str, (x, y, yaw_deg)), "--timeout", str(timeout)],
            env=self.env,
            capture_output=True,
            text=True,
            timeout=timeout + 30,
        )
        if result.returncode != 0:
            raise AssertionError(
                f"Nav2 not ready: {result.stderr[-2000:]}\nlaunch log: {self.log_tail()}"
            )
        # Let the robot stand still a moment so the controller's odometry is settled.
        time.sleep(0.5)

    def log_tail(self, chars: int = 3000) -> str:
        self._log.flush()
        return self.log_path.read_text(errors="replace")[-chars:]

    def stop(self) -> None:
        """SIGINT to the whole launch, then SIGTERM and SIGKILL if it lingers."""
        for signum, wait in ((signal.SIGINT, 10), (signal.SIGTERM, 5), (signal.SIGKILL, 5)):
            if self.process.poll() is not None:
                break
            try:
                os.killpg(self.process.pid, signum)
            except ProcessLookupError:
                break
            try:
                self.process.wait(timeout=wait)
            except subprocess.TimeoutExpired:
                continue
        # Nodes that outlived the launch process in its group.
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.process.pid, signal.SIGKILL)
        self._log.close()

    def __enter__(self) -> RealNav2:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
