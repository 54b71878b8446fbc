"""ROS 2 launch file: navseq's simulated robot with its Nav2 stand-in.

    ros2 launch launch/sim.launch.py speed:=2 ns:=robot1

Starts ``python3 -m navseq.ros2.sim_node`` (navseq must be importable by ``python``,
e.g. the project's venv first on PATH, or ``pip install``ed) — the same node as
``navseq sim --ros2``. Arguments: map (map_server YAML; default the repository's
TurtleBot3 world), start (x,y,yaw in degrees), ns, speed, robot, stop_on_failure,
other_robots (namespaces of the other robots of a fleet, comma-separated, e.g. robot2:
their footprints are obstacles for this one; see multi_robot.launch.py), follow_clock
(true: step with another node's /clock instead of a clock of its own), tf_convention
(nav2: /NS/tf with plain frames, the default; ros1: /tf with NS/ frames).
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration

DEFAULT_MAP = str(Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml")


def generate_launch_description() -> LaunchDescription:
    arguments = {
        "map": (DEFAULT_MAP, "map_server YAML"),
        "start": ("-2.0,-0.5,0", "start pose x,y,yaw (metres, metres, degrees)"),
        "ns": ("", "namespace of the robot (robot1 -> /robot1/navigate_to_pose)"),
        "speed": ("1.0", "simulated seconds per wall second; not 1: /clock is published"),
        "robot": ("turtlebot3_burger", "robot profile name or YAML file"),
        "other_robots": ("", "namespaces of the other robots of a fleet, e.g. robot2"),
        "follow_clock": ("false", "true: step with another simulator node's /clock"),
        "tf_convention": ("nav2", "nav2: /NS/tf, plain frames; ros1: /tf, frames NS/odom ..."),
        "stop_on_failure": ("true", "follow_waypoints stops at the first missed waypoint"),
        "python": ("python3", "the Python that can import navseq"),
    }
    declared = [
        DeclareLaunchArgument(name, default_value=default, description=description)
        for name, (default, description) in arguments.items()
    ]
    node = ExecuteProcess(
        cmd=[
            LaunchConfiguration("python"),
            "-m",
            "navseq.ros2.sim_node",
            "--map",
            LaunchConfiguration("map"),
            ["--start=", LaunchConfiguration("start")],
            ["--ns=", LaunchConfiguration("ns")],
            "--speed",
            LaunchConfiguration("speed"),
            "--robot",
            LaunchConfiguration("robot"),
            ["--other-robots=", LaunchConfiguration("other_robots")],
            ["--follow-clock=", LaunchConfiguration("follow_clock")],
            ["--tf-convention=", LaunchConfiguration("tf_convention")],
            "--ros-args",
            "-p",
            ["stop_on_failure:=", LaunchConfiguration("stop_on_failure")],
        ],
        output="screen",
        sigterm_timeout="10",
    )
    return LaunchDescription([*declared, node])
