"""The costmaps' own nodes on the ROS 2 simulator: lifecycle nodes their servers own.

In Nav2 the planner server runs ``global_costmap/global_costmap`` and the controller
server ``local_costmap/local_costmap``, each a lifecycle node that the lifecycle managers
never see: its server configures, activates, deactivates, cleans up and shuts it down
in its own transitions. The stand-in does the same (:meth:`navseq.ros2.lifecycle.
_ManagedServer.own`): ``ros2 lifecycle get /global_costmap/global_costmap`` follows
``planner_server`` through ``lifecycle_manager_navigation``'s startup, pause, resume and
shutdown (the ``transition_event`` topics say each step). Their parameters hold the robot
where Nav2's costmaps keep it (``footprint``, ``inflation_layer.inflation_radius`` and
``cost_scaling_factor``); the costmaps' topics and services are the simulator node's
(:mod:`navseq.ros2.costmap_topics`, :mod:`navseq.ros2.costmap_layers`).
"""

from __future__ import annotations

from rclpy.node import Node
from rclpy.parameter import Parameter

from navseq.mission.robot import RobotProfile
from navseq.ros2.lifecycle import Nav2Lifecycle, managed_node

#: Each costmap and the server that owns it (nav2_bringup's).
COSTMAP_OWNERS = {"global_costmap": "planner_server", "local_costmap": "controller_server"}


def nav2_costmap_nodes(
    robot: RobotProfile, namespace: str | None, lifecycle: Nav2Lifecycle
) -> list[Node]:
    """``global_costmap/global_costmap`` and ``local_costmap/local_costmap``, owned by
    their servers in ``lifecycle``, holding the robot's outline and inflation."""
    ns = f"/{namespace.strip('/')}" if namespace and namespace.strip("/") else ""
    outline = "[" + ", ".join(f"[{x:g}, {y:g}]" for x, y in robot.footprint) + "]"
    costmap = [
        Parameter("footprint", value=outline),
        Parameter("inflation_layer.inflation_radius", value=robot.inflation_radius),
        Parameter("inflation_layer.cost_scaling_factor", value=robot.cost_scaling_factor),
    ]
    nodes: list[Node] = []
    for name, owner in COSTMAP_OWNERS.items():
        node = managed_node(name, f"{ns}/{name}", costmap)
        lifecycle.servers[owner].own(node)
        nodes.append(node)
    return nodes


__all__ = ["COSTMAP_OWNERS", "nav2_costmap_nodes"]
