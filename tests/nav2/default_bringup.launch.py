"""nav2_bringup's default Jazzy bringup (localization_launch.py + navigation_launch.py,
docking included) on Nav2's loopback simulator, for listing its interfaces.

usage: ros2 launch tests/nav2/default_bringup.launch.py map:=maps/turtlebot3_world.yaml

The nodes, names, remappings and parameters (``nav2_params.yaml``) are those of
nav2_bringup's two launch files, without composition; ``route_server`` is left out
because the test machine's Nav2 build has none (``tests/data/nav2_bringup_interfaces.yaml``
lists its interfaces as a known gap) and the controller is Regulated Pure Pursuit (the
build has no MPPI), as in ``nav2_loopback.launch.py``. Not used by the test suite: it is how the
interface list of the test data was checked against a running Nav2.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

NAVIGATION = [
    ("nav2_controller", "controller_server", "controller_server", [("cmd_vel", "cmd_vel_nav")]),
    ("nav2_smoother", "smoother_server", "smoother_server", []),
    ("nav2_planner", "planner_server", "planner_server", []),
    ("nav2_behaviors", "behavior_server", "behavior_server", [("cmd_vel", "cmd_vel_nav")]),
    (
        "nav2_velocity_smoother",
        "velocity_smoother",
        "velocity_smoother",
        [("cmd_vel", "cmd_vel_nav")],
    ),
    ("nav2_collision_monitor", "collision_monitor", "collision_monitor", []),
    ("nav2_bt_navigator", "bt_navigator", "bt_navigator", []),
    ("nav2_waypoint_follower", "waypoint_follower", "waypoint_follower", []),
    ("opennav_docking", "opennav_docking", "docking_server", []),
]
RPP = {
    "FollowPath.plugin": "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController",
    "FollowPath.desired_linear_vel": 0.5,
}
LOCALIZATION = [
    ("nav2_map_server", "map_server", "map_server", []),
    ("nav2_amcl", "amcl", "amcl", []),
]


def _nodes(context):
    params = os.path.join(get_package_share_directory("nav2_bringup"), "params", "nav2_params.yaml")
    map_yaml = LaunchConfiguration("map").perform(context)
    remappings = [("/tf", "tf"), ("/tf_static", "tf_static")]
    nodes = [
        Node(
            package="nav2_loopback_sim",
            executable="loopback_simulator",
            name="loopback_simulator",
            parameters=[params],
        ),
        Node(
            package="tf2_ros",
            executable="static_transform_publisher",
            name="static_base_link",
            arguments=["--frame-id", "base_footprint", "--child-frame-id", "base_link"],
        ),
        Node(
            package="tf2_ros",
            executable="static_transform_publisher",
            name="static_base_scan",
            arguments=["--frame-id", "base_link", "--child-frame-id", "base_scan", "--z", "0.17"],
        ),
    ]
    for group, manager in ((LOCALIZATION, "localization"), (NAVIGATION, "navigation")):
        for package, executable, name, remap in group:
            extra = {"map_server": {"yaml_filename": map_yaml}, "controller_server": RPP}.get(
                name, {}
            )
            nodes.append(
                Node(
                    package=package,
                    executable=executable,
                    name=name,
                    parameters=[params, {"use_sim_time": True, **extra}],
                    remappings=remappings + remap,
                )
            )
        nodes.append(
            Node(
                package="nav2_lifecycle_manager",
                executable="lifecycle_manager",
                name=f"lifecycle_manager_{manager}",
                parameters=[
                    {"use_sim_time": True, "autostart": True},
                    {"node_names": [name for _p, _e, name, _r in group]},
                ],
            )
        )
    return nodes


def generate_launch_description():
    return LaunchDescription([DeclareLaunchArgument("map"), OpaqueFunction(function=_nodes)])
