"""ROS 2 launch file: navseq's simulated robot (Nav2 stand-in) and the navseq node.

    ros2 launch navseq sim_navseq.launch.py                  # the tutorial's p_seq/yea_seq
    ros2 launch navseq sim_navseq.launch.py mission:=examples/turtlebot3_world.yaml speed:=4
    ros2 launch navseq sim_navseq.launch.py keep_alive:=true rviz:=true

Includes ``launch/sim.launch.py`` (``python3 -m navseq.ros2.sim_node``) and starts
``python3 -m navseq.ros2.navseq_node`` (as ``ros2 run navseq navseq_node``), so it works
from a colcon workspace and from a source checkout whose venv is first on PATH alike.
The node reads the tutorial's parameters from ``examples/tutorial_params_ros2.yaml``, or
the ``mission`` file when one is given. It follows the simulator's ``/clock`` when
``speed`` is not 1. When the node exits (the mission is over, unless ``keep_alive``),
the whole launch shuts down, so ``ros2 launch`` returns when the mission is done.
``rviz:=true`` also starts RViz 2 with ``rviz/navseq_ros2.rviz``.
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    EmitEvent,
    ExecuteProcess,
    IncludeLaunchDescription,
    OpaqueFunction,
    RegisterEventHandler,
)
from launch.conditions import IfCondition
from launch.event_handlers import OnProcessExit
from launch.events import Shutdown
from launch.launch_context import LaunchContext
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration

SHARE = Path(__file__).resolve().parents[1]  # the repository, or share/navseq when installed
DEFAULT_MAP = str(SHARE / "maps" / "turtlebot3_world.yaml")
TUTORIAL_PARAMS = str(SHARE / "examples" / "tutorial_params_ros2.yaml")
RVIZ_CONFIG = str(SHARE / "rviz" / "navseq_ros2.rviz")
SIM_LAUNCH = str(SHARE / "launch" / "sim.launch.py")
# The simulator's arguments this file passes on (sim.launch.py declares and documents them).
SIM_ARGUMENTS = ("map", "start", "ns", "speed", "robot", "python")


def _navseq_node(context: LaunchContext) -> list[ExecuteProcess]:
    mission = LaunchConfiguration("mission").perform(context)
    source = (
        ["-p", f"mission:={Path(mission).resolve()}"]
        if mission
        else ["--params-file", TUTORIAL_PARAMS]
    )
    node = ExecuteProcess(
        cmd=[
            LaunchConfiguration("python"),
            "-m",
            "navseq.ros2.navseq_node",
            "--ros-args",
            "-r",
            ["__ns:=/", LaunchConfiguration("ns")],
            *source,
            "-p",
            ["keep_alive:=", LaunchConfiguration("keep_alive")],
        ],
        name="navseq",
        output="screen",
        sigterm_timeout="10",
    )
    ends_launch = RegisterEventHandler(
        OnProcessExit(target_action=node, on_exit=[EmitEvent(event=Shutdown(reason="navseq done"))])
    )
    return [node, ends_launch]


def generate_launch_description() -> LaunchDescription:
    arguments = {
        "map": (DEFAULT_MAP, "map_server YAML"),
        "start": ("-2.0,-0.5,0", "start pose x,y,yaw (metres, metres, degrees)"),
        "ns": ("", "namespace of the robot and the node (robot1 -> /robot1/navigate_to_pose)"),
        "speed": ("1.0", "simulated seconds per wall second; not 1: /clock is published"),
        "robot": ("turtlebot3_burger", "robot profile name or YAML file"),
        "mission": ("", "mission file (empty: the tutorial's p_seq/yea_seq)"),
        "keep_alive": ("false", "keep the navseq node (markers, status) up after the mission"),
        "rviz": ("false", "start RViz 2 with rviz/navseq_ros2.rviz"),
        "python": ("python3", "the Python that can import navseq"),
    }
    declared = [
        DeclareLaunchArgument(name, default_value=default, description=description)
        for name, (default, description) in arguments.items()
    ]
    sim = IncludeLaunchDescription(
        PythonLaunchDescriptionSource(SIM_LAUNCH),
        launch_arguments={name: LaunchConfiguration(name) for name in SIM_ARGUMENTS}.items(),
    )
    rviz = ExecuteProcess(
        cmd=["rviz2", "-d", RVIZ_CONFIG],
        condition=IfCondition(LaunchConfiguration("rviz")),
        output="screen",
    )
    return LaunchDescription([*declared, sim, OpaqueFunction(function=_navseq_node), rviz])
