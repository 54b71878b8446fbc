# Minimal real-Nav2 bringup on nav2_loopback_sim (no Gazebo, robot_state_publisher, rviz).
# A copy of the test machine's ../shared/ros2/nav2/nav2_loopback.launch.py, kept here so
# the real-Nav2 tests (tests/nav2_real_support.py) do not depend on where shared/ lies.
#
#   ros2 launch nav2_loopback.launch.py map:=/path/map.yaml [params_file:=...]
#       [keepout_mask:=/path/keepout.yaml] [speed_mask:=/path/speed.yaml]
#
# Starts: static TFs base_footprint->base_link->base_scan, nav2_loopback_sim (fakes odom, TF
# map->odom->base_footprint, /scan and /clock from cmd_vel), map_server, planner_server,
# controller_server, smoother_server, behavior_server, bt_navigator, waypoint_follower,
# velocity_smoother, and two lifecycle managers (autostart).  Parameters: nav2_bringup's
# nav2_params.yaml; the controller plugin is switched to Regulated Pure Pursuit because
# this build has no MPPI.  Everything runs on sim time from the loopback sim's /clock.
# The loopback sim waits for an initial pose on /initialpose (map frame) before it
# publishes map->odom, so publish one (nav_goal_test.py does) after launching.
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

RPP = "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController"


def _have(pkg):
    try:
        get_package_share_directory(pkg)
        return True
    except Exception:
        return False


def _nodes(context):
    params = LaunchConfiguration("params_file").perform(context)
    map_yaml = LaunchConfiguration("map").perform(context)
    controller = LaunchConfiguration("controller").perform(context)
    log_level = LaunchConfiguration("log_level").perform(context)
    sim = {"use_sim_time": True}
    args = ["--ros-args", "--log-level", log_level]
    ctrl_over = dict(sim)
    if controller == "rpp":
        ctrl_over.update(
            {
                "FollowPath.plugin": RPP,
                "FollowPath.desired_linear_vel": 0.5,
                "FollowPath.lookahead_dist": 0.6,
                "FollowPath.use_rotate_to_heading": True,
                "FollowPath.allow_reversing": False,
            }
        )

    keepout = LaunchConfiguration("keepout_mask").perform(context)
    speed = LaunchConfiguration("speed_mask").perform(context)
    filters_params = _filters_params(keepout, speed)

    def node(pkg, exe, name, extra=None, remap=(), filtered=False):
        files = [params] + ([filters_params] if filtered and filters_params else [])
        return Node(
            package=pkg,
            executable=exe,
            name=name,
            output="screen",
            parameters=[*files, dict(sim, **(extra or {}))],
            remappings=list(remap),
            arguments=args,
        )

    have_wpf = _have("nav2_waypoint_follower")
    nav_nodes = [
        "controller_server",
        "smoother_server",
        "planner_server",
        "behavior_server",
        "velocity_smoother",
        "bt_navigator",
    ] + (["waypoint_follower"] if have_wpf else [])
    return (
        [
            Node(
                package="tf2_ros",
                executable="static_transform_publisher",
                name="static_base_link",
                output="screen",
                arguments=["--frame-id", "base_footprint", "--child-frame-id", "base_link"],
            ),
            Node(
                package="tf2_ros",
                executable="static_transform_publisher",
                name="static_base_scan",
                output="screen",
                arguments=[
                    "--frame-id",
                    "base_link",
                    "--child-frame-id",
                    "base_scan",
                    "--z",
                    "0.17",
                ],
            ),
            Node(
                package="nav2_loopback_sim",
                executable="loopback_simulator",
                name="loopback_simulator",
                output="screen",
                parameters=[params],
            ),
            node("nav2_map_server", "map_server", "map_server", {"yaml_filename": map_yaml}),
            node(
                "nav2_lifecycle_manager",
                "lifecycle_manager",
                "lifecycle_manager_localization",
                {"autostart": True, "node_names": ["map_server"]},
            ),
            node(
                "nav2_controller",
                "controller_server",
                "controller_server",
                ctrl_over,
                remap=[("cmd_vel", "cmd_vel_nav")],
                filtered=True,
            ),
            node("nav2_smoother", "smoother_server", "smoother_server"),
            node("nav2_planner", "planner_server", "planner_server", filtered=True),
            node(
                "nav2_behaviors",
                "behavior_server",
                "behavior_server",
                remap=[("cmd_vel", "cmd_vel_nav")],
            ),
            node("nav2_bt_navigator", "bt_navigator", "bt_navigator"),
        ]
        + (
            [node("nav2_waypoint_follower", "waypoint_follower", "waypoint_follower")]
            if have_wpf
            else []
        )
        + _filter_servers(node, keepout, speed)
        + [
            # no collision_monitor here: the smoothed command goes straight to the robot
            node(
                "nav2_velocity_smoother",
                "velocity_smoother",
                "velocity_smoother",
                remap=[("cmd_vel", "cmd_vel_nav"), ("cmd_vel_smoothed", "cmd_vel")],
            ),
            node(
                "nav2_lifecycle_manager",
                "lifecycle_manager",
                "lifecycle_manager_navigation",
                {"autostart": True, "node_names": nav_nodes},
            ),
        ]
    )


# Costmap filters (keepout_mask:=..., speed_mask:=...): each mask served by a map_server
# and a costmap_filter_info_server under the names of nav2_bringup's params after Jazzy
# (keepout_filter_mask / keepout_costmap_filter_info, speed_filter_mask /
# speed_costmap_filter_info; speed: the speed-filter tutorial's base 100, multiplier -1),
# and the KeepoutFilter in both costmaps, the SpeedFilter in the global one.
FILTERS = {
    "keepout": ("nav2_costmap_2d::KeepoutFilter", 0, 0.0, 1.0),
    "speed": ("nav2_costmap_2d::SpeedFilter", 1, 100.0, -1.0),
}


def _filters_params(keepout, speed):
    """A parameter file adding the filters to both costmaps; None without masks."""
    import tempfile

    kinds = [kind for kind, mask in (("keepout", keepout), ("speed", speed)) if mask]
    if not kinds:
        return None
    lines = []
    for costmap in ("global_costmap", "local_costmap"):
        mine = [kind for kind in kinds if costmap == "global_costmap" or kind == "keepout"]
        if not mine:
            continue
        lines += [f"{costmap}:", f"  {costmap}:", "    ros__parameters:"]
        lines.append("      filters: [" + ", ".join(f'"{k}_filter"' for k in mine) + "]")
        for kind in mine:
            lines += [
                f"      {kind}_filter:",
                f'        plugin: "{FILTERS[kind][0]}"',
                "        enabled: true",
                f'        filter_info_topic: "/{kind}_costmap_filter_info"',
            ]
    handle, path = tempfile.mkstemp(prefix="nav2-filters-", suffix=".yaml")
    with os.fdopen(handle, "w") as file:
        file.write("\n".join(lines) + "\n")
    return path


def _filter_servers(node, keepout, speed):
    nodes, names = [], []
    for kind, mask in (("keepout", keepout), ("speed", speed)):
        if not mask:
            continue
        _, filter_type, base, multiplier = FILTERS[kind]
        nodes.append(
            node(
                "nav2_map_server",
                "map_server",
                f"{kind}_filter_mask_server",
                {"yaml_filename": mask, "topic_name": f"/{kind}_filter_mask", "frame_id": "map"},
            )
        )
        nodes.append(
            node(
                "nav2_map_server",
                "costmap_filter_info_server",
                f"{kind}_costmap_filter_info_server",
                {
                    "type": filter_type,
                    "filter_info_topic": f"/{kind}_costmap_filter_info",
                    "mask_topic": f"/{kind}_filter_mask",
                    "base": base,
                    "multiplier": multiplier,
                },
            )
        )
        names += [f"{kind}_filter_mask_server", f"{kind}_costmap_filter_info_server"]
    if names:
        nodes.append(
            node(
                "nav2_lifecycle_manager",
                "lifecycle_manager",
                "lifecycle_manager_costmap_filters",
                {"autostart": True, "node_names": names},
            )
        )
    return nodes


def generate_launch_description():
    # nav2_bringup's params; or NAV2_PARAMS (e.g. src/navigation2/nav2_bringup/params/...)
    params = os.environ.get("NAV2_PARAMS") or os.path.join(
        get_package_share_directory("nav2_bringup"), "params", "nav2_params.yaml"
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument("map", description="map yaml (map_server format)"),
            DeclareLaunchArgument("params_file", default_value=params),
            DeclareLaunchArgument(
                "controller",
                default_value="rpp",
                description='rpp (Regulated Pure Pursuit) or "yaml" (keep the file\'s)',
            ),
            DeclareLaunchArgument("log_level", default_value="info"),
            DeclareLaunchArgument("keepout_mask", default_value=""),
            DeclareLaunchArgument("speed_mask", default_value=""),
            OpaqueFunction(function=_nodes),
        ]
    )
