"""Fleets: several robots sharing one mission (no ROS here).

- :mod:`~navseq.fleet.model`: the fleet as plain data (robots, the mission, who may
  take which waypoint);
- :mod:`~navseq.fleet.fleet_format`: the fleet YAML file (docs/fleet.md), every
  problem at once with file:line;
- :mod:`~navseq.fleet.checks`: the fleet against its map (start poses in obstacles or
  on one another, waypoints no robot may take), before anything moves;
- :mod:`~navseq.fleet.split`: the waypoints split among the robots so that the last
  robot finishes as early as it can (OR-tools vehicle routing);
- :mod:`~navseq.fleet.planning`: a fleet file made into a checked split, for both faces;
- :mod:`~navseq.fleet.lockstep`, :mod:`~navseq.fleet.run`, :mod:`~navseq.fleet.products`:
  the robots run together on the embedded simulator, one clock, one run folder, one
  fleet report and picture.
"""
