"""ROS 1 nodes and adapters: the only package (with ``navigators.ros1``) that imports rospy.

- :mod:`navseq.ros.navseq_node`: the sequencer node (tutorial params, markers, services);
- :mod:`navseq.ros.record`: waypoint recorder (``navseq record`` and ``record_node``);
- :mod:`navseq.ros.markers`: RViz markers of a mission;
- :mod:`navseq.ros.mission_topics`: a mission listener publishing markers and a JSON status;
- :mod:`navseq.ros.navstack_params`: the robot profile from a running move_base's params;
- :mod:`navseq.ros.run_setup`: ``navseq run --navigator ros1``'s connection to the stack;
- :mod:`navseq.ros.conversions`: navseq types <-> ROS messages, shared by all nodes;
- :mod:`navseq.ros.params`: typed private parameters with errors naming the parameter;
- :mod:`navseq.ros.fleet`: the other robots of a simulated fleet, their poses from TF;
- ``sim_robot_node`` / ``sim_nav_node``: the embedded simulator served as ROS nodes.

Importing this package imports nothing from ROS; each module does so itself.
"""
