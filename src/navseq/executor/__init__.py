"""The executor: one mission run as an explicit state machine (no ROS, no threads)."""
