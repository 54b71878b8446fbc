"""Missions: the data model and loaders for every source format (no ROS here)."""

from navseq.mission.model import POLICY_FIELDS, FailureAction, Mission, Policy, Waypoint

__all__ = ["POLICY_FIELDS", "FailureAction", "Mission", "Policy", "Waypoint"]
