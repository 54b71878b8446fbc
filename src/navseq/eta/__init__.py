"""The mission's ETA: how long it takes before the robot moves, and while it does.

- :mod:`navseq.eta.drive`: how long the robot takes to drive one planned path (a speed
  profile with the robot's limits, turns in place, slowing to stop);
- :mod:`navseq.eta.predict`: the mission's expected duration and its upper bound, leg by
  leg, planned on the map before anything moves;
- :mod:`navseq.eta.live`: a listener of mission events that keeps the time still to go
  while the mission runs, and afterwards says how far off each prediction was;
- :mod:`navseq.eta.text`: the figures as ``navseq plan``, ``validate`` and the progress
  say them.

No ROS, no I/O: every navigator and every face gets the same figures.
"""
