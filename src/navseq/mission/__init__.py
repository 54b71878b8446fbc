"""Missions: the data model and loaders for every source format (no ROS here).

- :func:`load_mission` reads navseq YAML, rosparam YAML, roslaunch XML or CSV;
- :func:`validate_mission_file` lists every problem of a file at once, and
  :func:`inspect_mission_file` adds what could still be read despite them;
- :func:`mission_from_params` reads a ROS node's private parameters;
- :func:`dump_mission_yaml` / :func:`write_mission` write navseq YAML.
"""

from navseq.mission.loader import (
    inspect_mission_file,
    load_mission,
    mission_from_params,
    validate_mission_file,
)
from navseq.mission.model import POLICY_KEYS, FailureAction, Mission, Policy, Waypoint
from navseq.mission.params import MISSION_PARAM_KEYS
from navseq.mission.writer import dump_mission_yaml, write_mission

__all__ = [
    "MISSION_PARAM_KEYS",
    "POLICY_KEYS",
    "FailureAction",
    "Mission",
    "Policy",
    "Waypoint",
    "dump_mission_yaml",
    "inspect_mission_file",
    "load_mission",
    "mission_from_params",
    "validate_mission_file",
    "write_mission",
]
