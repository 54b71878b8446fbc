"""``navseq sim --ros1``: the ROS 1 sim nodes (robot + move_base stand-in) as child processes.

What ``roslaunch navseq sim.launch`` does, from any shell where rospy imports and navseq
is installed (no catkin workspace, no ``$(find navseq)``):

- a ROS master: the one answering at ``ROS_MASTER_URI`` if any, otherwise one started
  here (``rosmaster --core -p PORT``, the URI's port) and stopped on exit;
- the private parameters of both nodes and ``/use_sim_time`` set on the master through
  XML-RPC (typed values: no YAML guessing of ``_param:=value`` arguments), then the two
  nodes, :mod:`navseq.ros1.sim_robot_node` and :mod:`navseq.ros1.sim_nav_node`, started
  as ``python -m`` children in the namespace ``--ns``, with the frame prefix and the
  ``map -> /map`` remap that ``launch/sim_robot.launch`` gives them;
- one line on stdout when the ``move_base`` action server is up; children's output on
  stderr, each line prefixed with the node's name (roslaunch's ``output="screen"``);
- SIGINT / SIGTERM: the nodes get SIGINT (rospy's clean shutdown), the master we
  started SIGTERM (a background rosmaster ignores SIGINT); exit 0. A node that dies
  ends the command: its name, exit status and last output, exit 1.

Children run in their own sessions (a terminal's Ctrl-C reaches only this process, which
stops them in order) and get SIGTERM from the kernel if this process dies without
cleaning up (``PR_SET_PDEATHSIG``), so no node or master is left behind.

Only :func:`run` and :func:`ros1_missing` touch ROS, and they import it themselves:
importing this module imports nothing from ROS (``navseq sim --ros1`` checks options
and says "ROS 1 is missing" on machines without it).
"""

from __future__ import annotations

import collections
import contextlib
import ctypes
import os
import signal
import subprocess
import sys
import threading
import time
import xmlrpc.client
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import IO, Any

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.costmap_filters import CostmapFilter, filters_summary
from navseq.sim.options import SimConfig

CALLER_ID = "/navseq_sim"
READY_TIMEOUT = 60.0  # s for both nodes to start (rospy imports are slow on a busy machine)
STOP_TIMEOUT = 10.0  # s a child gets to end after its signal, before SIGKILL
TAIL_LINES = 20  # lines of a dead child's output shown to the user
_PR_SET_PDEATHSIG = 1

ROS1_MISSING = (
    "ROS 1 is not importable here (no rospy / rosgraph / actionlib): source ROS 1 first, "
    "e.g. `source /opt/ros/noetic/setup.bash`, or use Debian's python3-rospy with a "
    "--system-site-packages venv, then run navseq sim --ros1 again"
)


def ros1_missing() -> str | None:
    """Why the ROS 1 sim cannot start here (None when rospy & co. import)."""
    try:
        import actionlib  # noqa: F401  (the move_base stand-in's action server)
        import rosgraph  # noqa: F401
        import rospy  # noqa: F401
    except ImportError as error:
        return str(error)
    return None


@dataclass(frozen=True)
class NodeSpec:
    """One sim node: its ROS name, module, and private parameters."""

    name: str  # base name: sim_robot, move_base
    module: str
    params: dict[str, Any]


def node_specs(config: SimConfig, start: Pose2D, robot: str) -> list[NodeSpec]:
    """The two nodes with the parameters ``launch/sim_robot.launch`` gives them."""
    prefix = config.frame_prefix
    map_yaml = str(config.map_yaml.resolve())
    # The other robots' base frames, as launch/multi_robot.launch names them.
    others = [f"{name}/base_footprint" for name in config.other_robots]
    return [
        NodeSpec(
            "sim_robot",
            "navseq.ros1.sim_robot_node",
            {
                "map": map_yaml,
                "robot": robot,
                "x": float(start.x),
                "y": float(start.y),
                "yaw": float(start.yaw),
                "speed": float(config.speed),
                "publish_clock": not config.follow_clock,
                "publish_map": True,
                "odom_frame": f"{prefix}odom",
                "base_frame": f"{prefix}base_footprint",
                "other_robots": others,
            },
        ),
        # Named move_base like the real one: clients find its parameters under move_base/.
        NodeSpec(
            "move_base",
            "navseq.ros1.sim_nav_node",
            {
                "map": map_yaml,
                "robot": robot,
                "base_frame": f"{prefix}base_footprint",
                "other_robots": others,
                "filters": [filter_param(spec) for spec in config.filters],
            },
        ),
    ]


def filter_param(spec: CostmapFilter) -> dict[str, Any]:
    """One costmap filter as an item of the move_base stand-in's ``~filters``."""
    return {
        "mask": str(spec.mask.resolve()),
        "type": int(spec.type),
        "base": float(spec.base),
        "multiplier": float(spec.multiplier),
    }


def robot_param_value(option: str | None) -> str:
    """``--robot`` as the nodes' ``~robot``: a name, or a file made absolute.

    The nodes run in this process's working directory, but an absolute path keeps the
    parameter meaningful to anyone reading it from the master later.
    """
    if option is None:
        from navseq.mission.robot import DEFAULT_PROFILE

        return DEFAULT_PROFILE.name
    from navseq.mission.robot import BUILTIN_PROFILES

    text = option.strip()
    return text if text in BUILTIN_PROFILES else str(Path(option).resolve())


def start_pose(config: SimConfig) -> Pose2D:
    """``--start``, else the ROS 2 sim's default: the roomy point nearest the map origin.

    A start on an obstacle is refused here, as bad input (exit 2), rather than by the
    robot node dying once everything has started.
    """
    from navseq.sim.base import SimulatedBase
    from navseq.sim.occupancy import load_map
    from navseq.sim.profile import SimSettings
    from navseq.sim.world import default_start

    grid = load_map(config.map_yaml)
    footprint = SimSettings.of(config.robot).footprint
    if config.start is None:
        return default_start(grid, footprint)
    start = config.start
    if SimulatedBase(start, grid, footprint=footprint).collides(start):
        raise NavseqError(
            f"({start.x:.2f}, {start.y:.2f}) puts the robot on an obstacle, unknown space "
            f"or off the map {config.map_yaml}",
            source="--start",
        )
    return start


# -- the master ---------------------------------------------------------------------------


class _TimeoutTransport(xmlrpc.client.Transport):
    """XML-RPC over HTTP that gives up after ``timeout`` s (a firewalled host never answers)."""

    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host: Any) -> Any:
        connection = super().make_connection(host)
        connection.timeout = self._timeout
        return connection


def _master(uri: str, timeout: float = 2.0) -> Any:
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout))


def answers(uri: str) -> bool:
    """Whether the master or node serving XML-RPC at ``uri`` answers (both offer getPid)."""
    try:
        code, _, _ = _master(uri).getPid(CALLER_ID)
    except (OSError, xmlrpc.client.Error):
        return False
    return bool(code == 1)


def _call(uri: str, method: str, *args: Any) -> Any:
    code, message, value = getattr(_master(uri, 10.0), method)(CALLER_ID, *args)
    if code != 1:
        raise NavseqError(f"{method} refused: {message}", source=f"ROS master {uri}")
    return value


def action_server_up(uri: str, action: str) -> bool:
    """An actionlib server is up once it publishes ``status`` and subscribes ``goal``."""
    try:
        publishers, subscribers, _ = _call(uri, "getSystemState")
    except (OSError, xmlrpc.client.Error, NavseqError):
        return False
    published = {name for name, nodes in publishers if nodes}
    subscribed = {name for name, nodes in subscribers if nodes}
    return f"{action}/status" in published and f"{action}/goal" in subscribed


def node_running(uri: str, node: str) -> bool:
    """Whether ``node`` is registered and answers (a killed node's stale entry does not)."""
    code, _, node_uri = _master(uri).lookupNode(CALLER_ID, node)
    return code == 1 and answers(node_uri)


# -- children -----------------------------------------------------------------------------


def _prctl() -> Any:
    """libc's prctl, looked up in the parent: the child between fork and exec only calls it."""
    try:
        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):  # not Linux: no parent-death signal, stop() still runs
        return None


_PRCTL = _prctl()


def _die_with_parent() -> None:
    """In the child before exec: SIGTERM when the parent dies, however it dies (Linux)."""
    if _PRCTL is not None:
        _PRCTL(_PR_SET_PDEATHSIG, signal.SIGTERM)


@dataclass
class Child:
    """A started process; a thread copies its output to our stderr and keeps the tail."""

    label: str
    popen: subprocess.Popen[bytes]
    echo: bool
    tail: collections.deque[str] = field(
        default_factory=lambda: collections.deque(maxlen=TAIL_LINES)
    )
    reader: threading.Thread | None = None

    @classmethod
    def start(cls, label: str, argv: Sequence[str], env: dict[str, str], *, echo: bool) -> Child:
        popen = subprocess.Popen(
            list(argv),
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            # Only a prctl call between fork and exec: safe with the reader threads running.
            preexec_fn=_die_with_parent,
        )
        child = cls(label, popen, echo)
        assert popen.stdout is not None
        child.reader = threading.Thread(
            target=child._copy, args=(popen.stdout,), name=f"navseq-sim-{label}", daemon=True
        )
        child.reader.start()
        return child

    def _copy(self, stream: IO[bytes]) -> None:
        for raw in iter(stream.readline, b""):
            line = raw.decode(errors="replace").rstrip()
            self.tail.append(line)
            if self.echo:
                print(f"[{self.label}] {line}", file=sys.stderr, flush=True)
        stream.close()

    def running(self) -> bool:
        return self.popen.poll() is None

    def signal(self, signum: int) -> None:
        if self.running():
            with contextlib.suppress(ProcessLookupError):
                self.popen.send_signal(signum)

    def reap(self) -> None:
        """Wait :data:`STOP_TIMEOUT` for it to end, then SIGKILL its whole session."""
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.popen.wait(timeout=STOP_TIMEOUT)
        if self.running():
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.popen.pid, signal.SIGKILL)
            self.popen.wait(timeout=STOP_TIMEOUT)
        if self.reader is not None:
            self.reader.join(timeout=2.0)

    def stop(self, signum: int) -> None:
        self.signal(signum)
        self.reap()

    def last_output(self) -> str:
        return "\n".join(f"  {line}" for line in self.tail) or "  (no output)"


# -- the command --------------------------------------------------------------------------


def _say(text: str) -> None:
    print(f"navseq sim: {text}", file=sys.stderr, flush=True)


def _start_master(uri: str, env: dict[str, str]) -> Child:
    import rosgraph.network

    try:
        host, port = rosgraph.network.parse_http_host_and_port(uri)
    except ValueError:
        raise NavseqError(
            f"{uri!r} is not a master URI like http://127.0.0.1:11311", source="ROS_MASTER_URI"
        ) from None
    if not rosgraph.network.is_local_address(host):
        raise NavseqError(
            f"no ROS master answers at {uri}, and {host} is not this machine: start "
            "roscore there, or point ROS_MASTER_URI here (e.g. http://127.0.0.1:11311)",
            source="ROS_MASTER_URI",
        )
    master = Child.start("rosmaster", ["rosmaster", "--core", "-p", str(port)], env, echo=False)
    deadline = time.monotonic() + 15.0
    while not answers(uri):
        if not master.running() or time.monotonic() > deadline:
            master.stop(signal.SIGTERM)
            raise NavseqError(
                f"could not start rosmaster on port {port} (exit {master.popen.returncode})",
                source="ROS_MASTER_URI",
                details=master.last_output(),
            )
        time.sleep(0.1)
    return master


def _set_params(uri: str, namespace: str, specs: list[NodeSpec], sim_time: bool) -> None:
    # At speed 1 the robot runs on the wall clock and publishes no /clock (sim.launch does
    # the same): clients that compute deadlines from time 0 before a first /clock are spared.
    _call(uri, "setParam", "/use_sim_time", sim_time)
    for spec in specs:
        for name, value in spec.params.items():
            _call(uri, "setParam", f"{namespace}/{spec.name}/{name}", value)


def _node_argv(spec: NodeSpec, namespace: str) -> list[str]:
    argv = [sys.executable, "-m", spec.module, f"__name:={spec.name}", "map:=/map"]
    return argv + ([f"__ns:={namespace}"] if namespace else [])


def run(config: SimConfig, start: Pose2D, robot_option: str | None) -> int:
    """Serve until SIGINT / SIGTERM (0); 1 when a node dies or never gets ready.

    ``start`` comes from :func:`start_pose`; ``robot_option`` is ``--robot`` as given.
    """
    import rosgraph

    uri = rosgraph.get_master_uri()
    namespace = f"/{config.namespace}" if config.namespace else ""
    action = f"{namespace}/move_base"
    specs = node_specs(config, start, robot_param_value(robot_option))
    env = dict(os.environ, ROS_MASTER_URI=uri, PYTHONUNBUFFERED="1")
    env.pop("ROS_NAMESPACE", None)  # --ns says where the nodes go

    stop = threading.Event()
    previous: dict[int, Any] = {}

    def request_stop(_signum: int, _frame: FrameType | None) -> None:
        stop.set()

    for signum in (signal.SIGINT, signal.SIGTERM):
        previous[signum] = signal.signal(signum, request_stop)
    master: Child | None = None
    nodes: list[Child] = []
    try:
        if answers(uri):
            _say(f"using the ROS master at {uri}")
            for spec in specs:
                if node_running(uri, f"{namespace}/{spec.name}"):
                    raise NavseqError(
                        f"a node {namespace}/{spec.name} already runs on this master "
                        "(another simulator?): stop it, or give another --ns",
                        source=f"ROS master {uri}",
                    )
        else:
            master = _start_master(uri, env)
            _say(f"no ROS master at {uri}: started one (rosmaster pid {master.popen.pid})")
        _set_params(uri, namespace, specs, config.sim_time)
        for spec in specs:
            nodes.append(Child.start(spec.name, _node_argv(spec, namespace), env, echo=True))
        return _serve(uri, action, config, start, nodes, stop)
    finally:
        # Our handlers stay in place until the end: a second Ctrl-C cannot cut this short.
        for node in nodes:
            node.signal(signal.SIGINT)  # rospy's own clean shutdown (unregisters the node)
        for node in nodes:
            node.reap()
        if master is not None:
            master.stop(signal.SIGTERM)  # rosmaster started in the background ignores SIGINT
            _say("stopped the ROS master it started")
        for number, handler in previous.items():
            signal.signal(number, handler)


def _dead(nodes: list[Child]) -> Child | None:
    return next((node for node in nodes if not node.running()), None)


def _report_death(node: Child) -> int:
    if node.reader is not None:
        node.reader.join(timeout=2.0)  # its last words
    _say(f"node {node.label} exited with status {node.popen.returncode}; its last output:")
    print(node.last_output(), file=sys.stderr, flush=True)
    return 1


def _serve(
    uri: str,
    action: str,
    config: SimConfig,
    start: Pose2D,
    nodes: list[Child],
    stop: threading.Event,
) -> int:
    deadline = time.monotonic() + READY_TIMEOUT
    while not action_server_up(uri, action):
        if stop.wait(0.1):
            return 0
        dead = _dead(nodes)
        if dead is not None:
            return _report_death(dead)
        if time.monotonic() > deadline:
            _say(f"the action server {action} did not come up within {READY_TIMEOUT:g} s")
            return 1
    print(
        f"navseq sim: ready: {action} on {config.map_yaml}, robot at "
        f"({start.x:.2f}, {start.y:.2f}), speed x{config.speed:g}"
        + (" (/clock published: use_sim_time is true)" if config.sim_time else "")
        + (f", {filters_summary(config.filters)}" if config.filters else ""),
        flush=True,
    )
    while not stop.wait(0.2):
        dead = _dead(nodes)
        if dead is not None:
            return _report_death(dead)
    return 0
