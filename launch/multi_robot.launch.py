"""ROS 2 launch file: two simulated robots that see each other, in one world.

    ros2 launch launch/multi_robot.launch.py

Starts ``launch/sim.launch.py`` twice: robot1 and robot2, each a navseq sim node with
Nav2's interfaces under its namespace (``/robot1/navigate_to_pose``; transforms on
``/robot1/tf`` with plain frames ``map``, ``odom``, ``base_footprint`` as nav2_bringup's
multi-robot launch, or with ``tf_convention:=ros1`` on ``/tf`` with frames
``robot1/odom`` ...) and the other's namespace in ``other_robots``: each reads the
other's pose from its transforms, plans around its footprint and never drives into it
— what ``multi_robot.launch`` does for ROS 1. Both are the same
model (``robot``). At a ``speed`` other than 1 robot1 publishes ``/clock`` and robot2
steps with it (``follow_clock``), so both live on one simulated time. Arguments: map,
robot, speed, robot1_start, robot2_start (x,y,yaw in degrees), tf_convention, python
(the Python that can import navseq).
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PythonExpression

HERE = Path(__file__).resolve().parent
DEFAULT_MAP = str(HERE.parent / "maps" / "turtlebot3_world.yaml")
ROBOTS = {"robot1": "robot2", "robot2": "robot1"}  # each robot -> the one it must avoid
CLOCK_DRIVER = "robot1"  # the one that publishes /clock away from wall-clock speed


def generate_launch_description() -> LaunchDescription:
    arguments = {
        "map": (DEFAULT_MAP, "map_server YAML"),
        "robot": ("turtlebot3_burger", "robot profile name or YAML file (every robot)"),
        "speed": ("1.0", "simulated seconds per wall second; not 1: robot1 publishes /clock"),
        "robot1_start": ("-2.0,-0.5,0", "robot1's start x,y,yaw (metres, metres, degrees)"),
        "robot2_start": ("2.0,0.5,180", "robot2's start x,y,yaw (metres, metres, degrees)"),
        "tf_convention": ("nav2", "nav2: /NS/tf, plain frames; ros1: /tf, frames NS/odom ..."),
        "python": ("python3", "the Python that can import navseq"),
    }
    declared = [
        DeclareLaunchArgument(name, default_value=default, description=description)
        for name, (default, description) in arguments.items()
    ]
    speed = LaunchConfiguration("speed")
    fast = PythonExpression(["'true' if float('", speed, "') != 1.0 else 'false'"])
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
                        "tf_convention": LaunchConfiguration("tf_convention"),
                        # Set in this order: the include sets them one by one, and
                        # `fast` reads the launch's speed before robot2's 1.0 hides it.
                        "follow_clock": "false" if robot == CLOCK_DRIVER else fast,
                        "speed": speed if robot == CLOCK_DRIVER else "1.0",
                    }.items(),
                )
            ]
        )
        for robot, other in ROBOTS.items()
    ]
    return LaunchDescription([*declared, *robots])
