"""navseq's ROS 2 faces: the simulator as a Nav2 stand-in (:mod:`navseq.ros2.sim_node`).

This package is the only place that imports rclpy and ROS 2 messages, except the
ROS-free rules in :mod:`navseq.ros2.standin`, which import neither (tests use them in
process). Importing ``navseq.ros2`` itself imports nothing from ROS 2. What ROS 1 and
ROS 2 do alike lives once in the ROS-free :mod:`navseq.roscore` (the simulator's
options in :mod:`navseq.sim.options`); this package never imports ``navseq.ros1``.
"""

from __future__ import annotations


def ros2_missing() -> str | None:
    """Why ROS 2 cannot be used from this process (None when rclpy and nav2_msgs import).

    ``LD_LIBRARY_PATH`` is read when a process starts, so a ROS 2 sourced after that
    shows up here as an ImportError too: the answer is always "source ROS 2 first".
    """
    try:
        import nav2_msgs.action  # noqa: F401  (the Nav2 interfaces the simulator serves)
        import rclpy  # noqa: F401
    except ImportError as error:
        return str(error)
    return None
