"""navseq's ROS 2 faces: the simulator as a Nav2 stand-in (:mod:`navseq.ros2.sim_node`).

This package is the only place that imports rclpy and ROS 2 messages, except the
ROS-free rules in :mod:`navseq.ros2.standin`, which import neither (tests use them in
process). Importing ``navseq.ros2`` itself imports nothing from ROS 2.
"""
