"""The rest of Nav2's costmap and planner services on the ROS 2 simulator node.

What nav2_simple_commander's ``clearCostmapAroundRobot`` / ``clearCostmapAroundPose`` /
``clearCostmapExceptRegion`` / ``getCostmap``-style probes and a behaviour tree's
``IsPathValid`` condition call, under nav2_bringup's names:

- ``{global,local}_costmap/clear_around_{global,local}_costmap``
  (``nav2_msgs/srv/ClearCostmapAroundRobot``), ``…/clear_around_pose_…``
  (``ClearCostmapAroundPose``) and ``…/clear_except_…`` (``ClearCostmapExceptRegion``):
  the stand-in's costmap holds only the map and the other robots, nothing a sensor
  marked, so clearing any region rebuilds it, as ``clear_entirely`` does; each call is
  logged (``global_costmap: cleared around the robot``);
- ``{global,local}_costmap/get_cost_{global,local}_costmap`` (``nav2_msgs/srv/GetCost``):
  the cost of the cell at (x, y) in the costmap's frame (map, or odom for the local
  one); with ``use_footprint``, 254 (lethal) where the robot's footprint at (x, y,
  theta) touches an obstacle, else the centre cell's cost (Nav2 takes the highest cost
  under the footprint's outline);
- ``is_path_valid`` (``nav2_msgs/srv/IsPathValid``, planner_server): false with the
  indices of the poses on a lethal or inscribed cell, or off the map (Nav2 checks from
  the pose nearest the robot on; the stand-in checks every pose).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import PoseStamped
from nav2_msgs.srv import (
    ClearCostmapAroundPose,
    ClearCostmapAroundRobot,
    ClearCostmapExceptRegion,
    GetCost,
    IsPathValid,
)
from rclpy.node import Node

from navseq.geometry import Pose2D, compose
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.costmap import INSCRIBED, LETHAL

InMap = Callable[[PoseStamped], Pose2D | str]


class CostmapServices:
    """The services on ``node``, answered from ``standin``'s costmap under ``lock``."""

    def __init__(
        self, node: Node, standin: Nav2StandIn, lock: threading.Lock, group: Any, *, in_map: InMap
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._in_map = in_map
        self._log = node.get_logger()
        for costmap in ("global_costmap", "local_costmap"):
            for service, name, what in (
                (ClearCostmapAroundRobot, "clear_around", "around the robot"),
                (ClearCostmapAroundPose, "clear_around_pose", "around a pose"),
                (ClearCostmapExceptRegion, "clear_except", "except a region"),
            ):
                node.create_service(
                    service,
                    f"{costmap}/{name}_{costmap}",
                    self._clear(f"{costmap}: cleared {what}"),
                    callback_group=group,
                )
            node.create_service(
                GetCost,
                f"{costmap}/get_cost_{costmap}",
                self._cost(local=costmap == "local_costmap"),
                callback_group=group,
            )
        node.create_service(IsPathValid, "is_path_valid", self._path_valid, callback_group=group)

    def _clear(self, said: str) -> Callable[[Any, Any], Any]:
        def clear(_request: Any, response: Any) -> Any:
            with self._lock:
                self._standin.world.server.clear_costmaps()
            self._log.info(said)
            return response

        return clear

    def _cost(self, *, local: bool) -> Callable[[Any, Any], Any]:
        def cost(request: Any, response: Any) -> Any:
            with self._lock:
                world = self._standin.world
                at = Pose2D(float(request.x), float(request.y), float(request.theta))
                if local:  # the local costmap's frame is odom
                    at = compose(world.body.map_to_odom, at)
                if request.use_footprint and world.body.collides(at):
                    response.cost = float(LETHAL)
                else:
                    response.cost = float(world.server.costmap.cost_at(at.x, at.y))
            return response

        return cost

    def _path_valid(self, request: Any, response: Any) -> Any:
        invalid: list[int] = []
        with self._lock:
            costmap = self._standin.world.server.costmap
            for index, pose in enumerate(request.path.poses):
                if not pose.header.frame_id:
                    pose.header.frame_id = request.path.header.frame_id
                planar = self._in_map(pose)
                if isinstance(planar, str) or costmap.cost_at(planar.x, planar.y) >= INSCRIBED:
                    invalid.append(index)
        response.is_valid = not invalid
        response.invalid_pose_indices = invalid
        return response


__all__ = ["CostmapServices"]
