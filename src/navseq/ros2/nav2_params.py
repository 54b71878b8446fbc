"""The robot as a running Nav2 knows it: a RobotProfile from Nav2's node parameters.

``navseq run --navigator nav2`` must judge arrival with the tolerance Nav2's goal
checker uses: Nav2's usual ``xy_goal_tolerance`` is 0.25 m, and a robot that stops
0.2 m from its goal has arrived, not "succeeded far from goal". It must also check
and plan with the robot's own outline. Nav2 keeps these as parameters of its nodes,
under the robot's namespace:

- ``controller_server``: the goal checker (``goal_checker_plugins``, first entry, e.g.
  ``general_goal_checker``) with ``<checker>.xy_goal_tolerance`` and
  ``<checker>.yaw_goal_tolerance``; the controller (``controller_plugins``, first
  entry, e.g. ``FollowPath``) with its speeds and accelerations, under DWB's names
  (``max_vel_x``, ``max_vel_theta``, ``acc_lim_x``, ``acc_lim_theta``) or Regulated Pure
  Pursuit's (``desired_linear_vel``, ``rotate_to_heading_angular_vel``);
- ``global_costmap/global_costmap`` and ``local_costmap/local_costmap``: ``footprint``
  (costmap_2d's string ``"[[x, y], ...]"``; ``"[]"`` means ``robot_radius``),
  ``robot_radius``, ``inflation_layer.inflation_radius`` and
  ``inflation_layer.cost_scaling_factor``.

They are read through each node's ``list_parameters`` / ``get_parameters`` services
(:meth:`navseq.ros2.navigator.Nav2Navigator.read_parameters`) and turned into the
same parameter tree ROS 1's move_base has, so that one set of rules
(:func:`navseq.roscore.stack_profile.profile_from_navstack_params`, ROS-free) reads
both stacks. A node that does not answer is left out: what it would have said keeps
the base profile's value, and the note says what was read.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.roscore.stack_profile import profile_from_navstack_params

#: Our name for each Nav2 node read -> its name relative to the robot's namespace.
NODES = {
    "controller_server": "controller_server",
    "global_costmap": "global_costmap/global_costmap",
    "local_costmap": "local_costmap/local_costmap",
}
#: The tree's name for Nav2's controller, as a ROS 1 local planner is named.
_CONTROLLER = "nav2_controller"
#: Our name -> the controller parameters that mean it, DWB's first.
_CONTROLLER_PARAMS = {
    "max_vel_x": ("max_vel_x", "desired_linear_vel"),
    "max_vel_theta": ("max_vel_theta", "rotate_to_heading_angular_vel"),
    "acc_lim_x": ("acc_lim_x",),
    "acc_lim_theta": ("acc_lim_theta",),
}


def profile_from_nav2_params(
    params: Mapping[str, Mapping[str, Any]], namespace: str, base: RobotProfile = DEFAULT_PROFILE
) -> tuple[RobotProfile, str]:
    """``base`` with what Nav2's node parameters say (``params``: our node name -> that
    node's parameters by their dotted names), and a one-line note saying what was read."""
    label = "/" + namespace.strip("/") if namespace.strip("/") else "/"
    return profile_from_navstack_params(
        navstack_tree(params), label, base, where=f"Nav2's parameters under {label}"
    )


def navstack_tree(params: Mapping[str, Mapping[str, Any]]) -> dict[str, Any]:
    """Nav2's parameters as the tree move_base's would be (see the module docstring)."""
    tree: dict[str, Any] = {}
    for costmap in ("global_costmap", "local_costmap"):
        if costmap in params:
            tree[costmap] = _nested(params[costmap])
    controller = params.get("controller_server", {})
    planner: dict[str, Any] = {}
    checker = _first(controller.get("goal_checker_plugins")) or _first(
        controller.get("goal_checker_plugin")
    )
    if checker is not None:
        for name in ("xy_goal_tolerance", "yaw_goal_tolerance"):
            if f"{checker}.{name}" in controller:
                planner[name] = controller[f"{checker}.{name}"]
    follower = _first(controller.get("controller_plugins"))
    if follower is not None:
        for ours, theirs in _CONTROLLER_PARAMS.items():
            names = [f"{follower}.{name}" for name in theirs if f"{follower}.{name}" in controller]
            if names:
                planner[ours] = controller[names[0]]
    if planner:
        tree[_CONTROLLER] = planner
        tree["base_local_planner"] = f"nav2/{_CONTROLLER}"
    return tree


def _nested(flat: Mapping[str, Any]) -> dict[str, Any]:
    """``{"inflation_layer.inflation_radius": 0.5}`` -> ``{"inflation_layer": {...: 0.5}}``."""
    tree: dict[str, Any] = {}
    for name, value in flat.items():
        *parents, leaf = name.split(".")
        node = tree
        for part in parents:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):  # "a" and "a.b" both given: keep the first
                break
            node = child
        else:
            node.setdefault(leaf, value)
    return tree


def _first(value: Any) -> str | None:
    """The first plugin a ``*_plugins`` parameter names (a string array, or one string)."""
    if isinstance(value, str) and value:
        return value
    if isinstance(value, (list, tuple)) and value and isinstance(value[0], str) and value[0]:
        return value[0]
    return None


__all__ = ["NODES", "navstack_tree", "profile_from_nav2_params"]
