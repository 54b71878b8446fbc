"""What the ROS 1 and ROS 2 faces of navseq share, once, without importing any ROS.

``navseq.ros1`` (rospy, actionlib) and ``navseq.ros2`` (rclpy) each keep only what
their client library needs; the rules live here and both use them through a small
protocol (:class:`~navseq.roscore.client.ClientLibrary`, :class:`~navseq.roscore.node.NodeFace`):

- :mod:`~navseq.roscore.client`: what the core asks of a client library;
- :mod:`~navseq.roscore.clock`: waiting on ROS time, a valid clock, time jumping back;
- :mod:`~navseq.roscore.server`: when the action server counts as lost and as back;
- :mod:`~navseq.roscore.goals`: which goal is tracked, and whether its cancel was answered;
- :mod:`~navseq.roscore.navigator`: the navigator's shared half, built from the above;
- :mod:`~navseq.roscore.operator`: the answers of the pause / resume / skip / cancel services;
- :mod:`~navseq.roscore.node`: the node's run, its ending, keep-alive and exit status;
- :mod:`~navseq.roscore.stack_profile`: the robot from a navigation stack's parameters.

ROS 1 and ROS 2 never import each other: what both need is here (or in the other
ROS-free packages: ``navseq.navigators``, ``navseq.sinks.mission_status``, ``navseq.sim``).
"""
