"""ROS 1 (rospy) code: the only package that imports rospy and ROS 1 messages.

- :mod:`navseq.ros1.navigator`: the ``ros1`` navigator (move_base over actionlib);

- :mod:`navseq.ros1.navseq_node`: the sequencer node (tutorial params, markers, services);
- :mod:`navseq.ros1.record`: waypoint recorder (``navseq record`` and ``record_node``);
- :mod:`navseq.ros1.markers`: RViz markers of a mission;
- :mod:`navseq.ros1.mission_topics`: a mission listener publishing markers and a JSON status;
- :mod:`navseq.ros1.navstack_params`: a running move_base's params, fetched (the rules
  that read them: :mod:`navseq.roscore.stack_profile`);
- :mod:`navseq.ros1.run_setup`: ``navseq run --navigator ros1``'s connection to the stack
  (the ``create`` of the kind in :mod:`navseq.navigators.registry`);
- :mod:`navseq.ros1.conversions`: navseq types <-> ROS 1 messages, shared by all nodes
  (the message-free readers live in :mod:`navseq.geometry`, for ROS 2 too);
- :mod:`navseq.ros1.params`: typed private parameters with errors naming the parameter;
- :mod:`navseq.ros1.fleet`: the other robots of a simulated fleet, their poses from TF;
- ``sim_robot_node`` / ``sim_nav_node``: the embedded simulator served as ROS nodes.
- :mod:`navseq.ros1.sim_launcher`: ``navseq sim --ros1``, those two nodes (and a rosmaster
  when none answers) started and stopped as child processes.

What ROS 1 and ROS 2 do alike (clock and server waits, goal bookkeeping, the node's
run and exit status, the services' answers, the robot from the stack's parameters)
lives once in the ROS-free :mod:`navseq.roscore`; this package never imports
``navseq.ros2``. Importing this package imports nothing from ROS; each module does so
itself.
"""
