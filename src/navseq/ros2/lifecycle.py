"""Nav2's lifecycle surface for the ROS 2 simulator node: its managed nodes and managers.

A default Jazzy bringup runs each server as a lifecycle node under its own name, brought
up by two lifecycle managers. Clients depend on that: ``ros2 lifecycle get
/bt_navigator``, ``nav2_simple_commander``'s ``waitUntilNav2Active()`` (``get_state``),
``lifecycleStartup()`` / ``lifecycleShutdown()`` (every ``ManageLifecycleNodes``
service). So the stand-in runs the same:

- one rclpy ``LifecycleNode`` per Nav2 server, under nav2_bringup's names
  (:data:`NAVIGATION_NODES`, :data:`LOCALIZATION_NODES`), with the real lifecycle
  services (``get_state``, ``change_state``, ``get_available_states`` ...) and
  transitions; configured and activated at start (nav2_bringup's ``autostart``);
- ``lifecycle_manager_navigation`` and ``lifecycle_manager_localization`` with
  ``manage_nodes`` (``nav2_msgs/srv/ManageLifecycleNodes``: STARTUP, PAUSE, RESUME, RESET,
  SHUTDOWN, CONFIGURE, CLEANUP, in Nav2's order — bring-up in list order, tear-down in
  reverse) and ``is_active`` (``std_srvs/srv/Trigger``);
- more groups of servers with their own manager when the run has them (``groups``: the
  costmap filters' mask and filter info servers, :mod:`navseq.ros2.filter_topics`),
  brought up after localization and before navigation.

A server may do something when it is activated (:meth:`_ManagedServer.when_activated`:
the filter servers publish their mask and filter info then, as Nav2's do in
``on_activate``).

The simulator asks :meth:`Nav2Lifecycle.active` before it takes a goal: an action whose
server is not active rejects new goals, as Nav2's action servers do between configure and
activate (goals already running go on). After SHUTDOWN the nodes are finalized, and a
later STARTUP fails, as in Nav2. The servers' own work (planning, costmaps) does not stop
while inactive: only their action goals are refused.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from lifecycle_msgs.msg import State
from nav2_msgs.srv import ManageLifecycleNodes
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_srvs.srv import Trigger

#: nav2_bringup's navigation_launch.py lifecycle_nodes (Jazzy), in bring-up order.
NAVIGATION_NODES = (
    "controller_server",
    "smoother_server",
    "planner_server",
    "route_server",
    "behavior_server",
    "velocity_smoother",
    "collision_monitor",
    "bt_navigator",
    "waypoint_follower",
    "docking_server",
)
#: nav2_bringup's localization_launch.py lifecycle_nodes.
LOCALIZATION_NODES = ("map_server", "amcl")

#: Which Nav2 server serves each action the simulator answers.
ACTION_SERVERS = {
    "navigate_to_pose": "bt_navigator",
    "navigate_through_poses": "bt_navigator",
    "follow_waypoints": "waypoint_follower",
    "compute_path_to_pose": "planner_server",
    "compute_path_through_poses": "planner_server",
    "smooth_path": "smoother_server",
    "follow_path": "controller_server",
    "spin": "behavior_server",
    "backup": "behavior_server",
    "drive_on_heading": "behavior_server",
    "wait": "behavior_server",
    "assisted_teleop": "behavior_server",
    "compute_route": "route_server",
    "compute_and_track_route": "route_server",
    "dock_robot": "docking_server",
    "undock_robot": "docking_server",
}

_ACTIVE = State.PRIMARY_STATE_ACTIVE
_INACTIVE = State.PRIMARY_STATE_INACTIVE
_UNCONFIGURED = State.PRIMARY_STATE_UNCONFIGURED
_FINALIZED = State.PRIMARY_STATE_FINALIZED


class _ManagedServer(LifecycleNode):
    """A Nav2 server's lifecycle: every transition succeeds; the state is all it keeps.

    Nodes it owns (:meth:`own`: the planner's and the controller's costmaps, as in Nav2)
    take each of its transitions with it, whoever asked for it.
    """

    owned: list[_ManagedServer]
    activated: list[Callable[[], None]]

    @property
    def state_id(self) -> int:
        # The state machine's own record (changed by change_state calls from outside too).
        return int(self._state_machine.current_state[0])

    def own(self, node: _ManagedServer) -> None:
        if not hasattr(self, "owned"):
            self.owned = []
        self.owned.append(node)

    def _follow(self, source: int | None, trigger: str) -> None:
        for node in getattr(self, "owned", []):
            _move(node, node.state_id if source is None else source, getattr(node, trigger))

    def on_configure(self, state: Any) -> TransitionCallbackReturn:
        self._follow(_UNCONFIGURED, "trigger_configure")
        return super().on_configure(state)

    def when_activated(self, callback: Callable[[], None]) -> None:
        """Call ``callback`` at each activation (the first one: the manager's startup)."""
        if not hasattr(self, "activated"):
            self.activated = []
        self.activated.append(callback)

    def on_activate(self, state: Any) -> TransitionCallbackReturn:
        self._follow(_INACTIVE, "trigger_activate")
        result = super().on_activate(state)
        if result == TransitionCallbackReturn.SUCCESS:
            for callback in getattr(self, "activated", []):
                callback()
        return result

    def on_deactivate(self, state: Any) -> TransitionCallbackReturn:
        self._follow(_ACTIVE, "trigger_deactivate")
        return super().on_deactivate(state)

    def on_cleanup(self, state: Any) -> TransitionCallbackReturn:
        self._follow(_INACTIVE, "trigger_cleanup")
        return super().on_cleanup(state)

    def on_shutdown(self, state: Any) -> TransitionCallbackReturn:
        self._follow(None, "trigger_shutdown")
        return super().on_shutdown(state)


def managed_node(
    name: str, namespace: str | None, parameters: Sequence[Parameter]
) -> _ManagedServer:
    """A lifecycle node of the kind the Nav2 servers are (for nodes a server owns)."""
    return _ManagedServer(
        name,
        namespace=namespace or None,
        parameter_overrides=list(parameters),
        automatically_declare_parameters_from_overrides=True,
    )


class Nav2Lifecycle:
    """The managed nodes and their managers; see the module docstring.

    ``parameters`` gives some nodes their parameters (the robot where Nav2 keeps it);
    ``groups`` adds, per ``(manager name, server names)``, those servers and their manager.
    """

    def __init__(
        self,
        namespace: str | None,
        parameters: dict[str, list[Parameter]] | None = None,
        groups: Sequence[tuple[str, Sequence[str]]] = (),
    ) -> None:
        given = parameters or {}
        self._lock = threading.Lock()
        extra = [name for _manager, names in groups for name in names]
        self.servers = {
            name: _ManagedServer(
                name,
                namespace=namespace or None,
                parameter_overrides=given.get(name, []),
                automatically_declare_parameters_from_overrides=True,
            )
            for name in (*NAVIGATION_NODES, *LOCALIZATION_NODES, *extra)
        }
        self.managers = [
            self._manager("lifecycle_manager_navigation", NAVIGATION_NODES, namespace),
            self._manager("lifecycle_manager_localization", LOCALIZATION_NODES, namespace),
            *(self._manager(manager, names, namespace) for manager, names in groups),
        ]
        # Bring-up order: the map, then what reads it (filter masks), then navigation.
        self._startup_order = [LOCALIZATION_NODES, *(tuple(names) for _m, names in groups)]
        self._startup_order.append(NAVIGATION_NODES)

    @property
    def nodes(self) -> list[Node]:
        return [*self.servers.values(), *self.managers]

    def start(self) -> None:
        """Configure and activate every server, as nav2_bringup's autostart does."""
        for names in self._startup_order:
            self._startup(names)

    def active(self, action: str) -> bool:
        """Whether the server of ``action`` takes goals now."""
        return self.servers[ACTION_SERVERS[action]].state_id == _ACTIVE

    def is_active(self, server: str) -> bool:
        """Whether the Nav2 server named ``server`` (``map_server`` ...) is active."""
        return self.servers[server].state_id == _ACTIVE

    def gate(self, action: str, log: Callable[[str], None]) -> Callable[[Any], GoalResponse]:
        """The goal callback of ``action``'s server: accept while it is active; a refusal
        is logged with Nav2's words."""

        def take(_request: Any) -> GoalResponse:
            if self.active(action):
                return GoalResponse.ACCEPT
            log(f"{action}: Action server is inactive. Rejecting the goal.")
            return GoalResponse.REJECT

        return take

    def action_servers(
        self,
        node: Node,
        group: Any,
        log: Callable[[str], None],
        handlers: Iterable[tuple[Any, str, Callable[[Any], Any]]],
    ) -> list[ActionServer]:
        """One action server per ``(action type, name, execute callback)``, as Nav2's
        servers take goals: only while their lifecycle node is active (:meth:`gate`);
        a cancel is always accepted."""
        return [
            ActionServer(
                node,
                action,
                name,
                execute_callback=execute,
                goal_callback=self.gate(name, log),
                cancel_callback=lambda _handle: CancelResponse.ACCEPT,
                callback_group=group,
            )
            for action, name, execute in handlers
        ]

    # -- managers ----------------------------------------------------------------------

    def _manager(self, name: str, managed: Sequence[str], namespace: str | None) -> Node:
        node = Node(
            name,
            namespace=namespace or None,
            parameter_overrides=[
                Parameter("node_names", value=list(managed)),
                Parameter("autostart", value=True),
            ],
            automatically_declare_parameters_from_overrides=True,
        )
        commands: dict[int, Callable[[Sequence[str]], bool]] = {
            ManageLifecycleNodes.Request.STARTUP: self._startup,
            ManageLifecycleNodes.Request.PAUSE: self._pause,
            ManageLifecycleNodes.Request.RESUME: self._resume,
            ManageLifecycleNodes.Request.RESET: self._reset,
            ManageLifecycleNodes.Request.SHUTDOWN: self._shutdown,
            ManageLifecycleNodes.Request.CONFIGURE: self._configure,
            ManageLifecycleNodes.Request.CLEANUP: self._cleanup,
        }

        def manage(request: Any, response: Any) -> Any:
            command = commands.get(request.command)
            response.success = command is not None and command(managed)
            return response

        def is_active(_request: Any, response: Any) -> Any:
            response.success = all(self.servers[n].state_id == _ACTIVE for n in managed)
            return response

        node.create_service(ManageLifecycleNodes, f"{name}/manage_nodes", manage)
        node.create_service(Trigger, f"{name}/is_active", is_active)
        return node

    def _each(self, names: Sequence[str], step: Callable[[_ManagedServer], bool]) -> bool:
        with self._lock:
            return all(step(self.servers[name]) for name in names)

    def _startup(self, names: Sequence[str]) -> bool:
        return self._configure(names) and self._resume(names)

    def _configure(self, names: Sequence[str]) -> bool:
        return self._each(names, lambda s: _move(s, _UNCONFIGURED, s.trigger_configure))

    def _resume(self, names: Sequence[str]) -> bool:
        return self._each(names, lambda s: _move(s, _INACTIVE, s.trigger_activate))

    def _pause(self, names: Sequence[str]) -> bool:
        return self._each(names[::-1], lambda s: _move(s, _ACTIVE, s.trigger_deactivate))

    def _cleanup(self, names: Sequence[str]) -> bool:
        return self._each(names[::-1], lambda s: _move(s, _INACTIVE, s.trigger_cleanup))

    def _reset(self, names: Sequence[str]) -> bool:
        return self._pause(names) and self._cleanup(names)

    def _shutdown(self, names: Sequence[str]) -> bool:
        return self._reset(names) and self._each(
            names[::-1], lambda s: _move(s, _UNCONFIGURED, s.trigger_shutdown)
        )


def _move(server: _ManagedServer, source: int, trigger: Callable[[], Any]) -> bool:
    """Take ``server`` out of state ``source`` with ``trigger``; a server already past it
    (at the state the step leads to, or further on the same way) needs nothing. False
    when it cannot: finalized, or the transition failed."""
    state = server.state_id
    if state == _FINALIZED:
        return False
    if state != source:
        return True
    try:
        return _ok(trigger())
    except Exception:  # rclpy's RCLError: the state machine has no such transition
        return False


def _ok(result: Any) -> bool:
    return bool(result == TransitionCallbackReturn.SUCCESS)


__all__ = [
    "ACTION_SERVERS",
    "LOCALIZATION_NODES",
    "NAVIGATION_NODES",
    "Nav2Lifecycle",
    "managed_node",
]
