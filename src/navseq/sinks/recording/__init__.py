"""A run recorded as MCAP (``navseq run --record``): for Foxglove, ``ros2 bag`` and rosbags.

The recording is a sink like the journal and the report: it listens to the mission's
events and writes, while the mission runs, the map, the robot's pose, odometry and
``/tf``, each plan, the goals, the waypoint markers and navseq's own events
(:mod:`navseq.sinks.recording.sink`). The messages are the standard ROS ones, encoded
by the maintained ``mcap`` library and its ROS support packages in ROS 2 (CDR) or ROS 1
encoding (:mod:`navseq.sinks.recording.encoding`), their definitions taken verbatim
from the ROS packages (``definitions/``, made by ``scripts/ros_msg_definitions.py``).

It needs the ``record`` extra (``pip install 'navseq[record]'``); nothing here imports
ROS, so a recording works on a machine without it.
"""

from __future__ import annotations

from navseq.sinks.recording.encoding import FORMATS, RecordingFormat

__all__ = ["FORMATS", "RecordingFormat"]
