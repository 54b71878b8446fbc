"""ROS 2 launch file: two simulated robots that see each other, in one world.

    ros2 launch launch/multi_robot.launch.py

Starts ``launch/sim.launch.py`` twice: robot1 and robot2, each a navseq sim node with
Nav2's interfaces under its namespace (``/robot1/navigate_to_pose``, frames
``robot1/odom``, ``robot1/base_footprint``, ...) and the other's namespace in
``other_robots``: each reads the other's pose from ``/tf``, plans around its footprint
and never drives into it — what ``multi_robot.launch`` does for ROS 1. Both are the same
model (``robot``) and run at wall-clock speed (several robots cannot share a faster
``/clock`` yet). Arguments: map, robot, robot1_start, robot2_start (x,y,yaw in degrees),
python (the Python that can import navseq).
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration

HERE = Path(__file__).resolve().parent
DEFAULT_MAP = str(HERE.parent / "maps" / "turtlebot3_world.yaml")
ROBOTS = {"robot1": "robot2", "robot2": "robot1"}  # each robot -> the one it must avoid


def generate_launch_description() -> LaunchDescription:
    arguments = {
        "map": (DEFAULT_MAP, "map_server YAML"),
        "robot": ("turtlebot3_burger", "robot profile name or YAML file (every robot)"),
        "robot1_start": ("-2.0,-0.5,0", "robot1's start x,y,yaw (metres, metres, degrees)"),
        "robot2_start": ("2.0,0.5,180", "robot2's start x,y,yaw (metres, metres, degrees)"),
        "python": ("python3", "the Python that can import navseq"),
    }
    declared = [
        DeclareLaunchArgument(name, default_value=default, description=description)
        for name, (default, description) in arguments.items()
    ]
    # One scoped group per robot: its include's arguments (ns, ...) stay its own.
    robots = [
        GroupAction(
            [
                IncludeLaunchDescription(
                    PythonLaunchDescriptionSource(str(HERE / "sim.launch.py")),
                    launch_arguments={
                        "ns": robot,
                        "other_robots": other,
                        "start": LaunchConfiguration(f"{robot}_start"),
                        "map": LaunchConfiguration("map"),
                        "robot": LaunchConfiguration("robot"),
                        "python": LaunchConfiguration("python"),
                        "speed": "1.0",
                    }.items(),
                )
            ]
        )
        for robot, other in ROBOTS.items()
    ]
    return LaunchDescription([*declared, *robots])
