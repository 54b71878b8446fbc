"""A mission's progress on ROS topics: waypoint markers for RViz and a JSON status.

Used by the navseq node (topics ``~waypoints`` and ``~status``) and by
``navseq run --navigator ros1`` (``/navseq/waypoints`` and ``/navseq/status``, under the
robot namespace if one is given), so RViz shows the same markers whichever runs the
mission. Both topics are latched: RViz shows them whenever it connects.
"""

from __future__ import annotations

import json
import threading
from dataclasses import asdict
from typing import Any

import rosgraph.names
import rospy
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from navseq.executor.events import (
    MissionEvent,
    MissionFinished,
    MissionPaused,
    WaypointFinished,
    WaypointOutcome,
    WaypointProgress,
    WaypointStarted,
)
from navseq.mission.model import Mission
from navseq.ros1.markers import MarkerStatus, waypoint_markers

PROGRESS_PERIOD = 0.5  # s of mission time between two progress status messages
RUN_TOPICS_NS = "navseq"  # where `navseq run` publishes, like the node named navseq

_OUTCOME_MARKERS = {
    WaypointOutcome.REACHED: MarkerStatus.REACHED,
    WaypointOutcome.SKIPPED: MarkerStatus.SKIPPED,
    WaypointOutcome.FAILED: MarkerStatus.FAILED,
    WaypointOutcome.NOT_RUN: MarkerStatus.PENDING,
}


class MissionTopics:
    """A mission listener publishing ``<ns>/status`` (JSON) and ``<ns>/waypoints`` (markers).

    ``namespace`` is ``~`` for a node's private topics, or a name such as ``/navseq``.
    """

    def __init__(self, mission: Mission, namespace: str = "~"):
        self.mission = mission
        self.statuses: dict[int, MarkerStatus] = {}
        prefix = "~" if namespace == "~" else namespace.rstrip("/") + "/"
        self._status_pub = rospy.Publisher(f"{prefix}status", String, queue_size=10, latch=True)
        self._marker_pub = rospy.Publisher(
            f"{prefix}waypoints", MarkerArray, queue_size=2, latch=True
        )
        self._last_progress = float("-inf")
        self._lock = threading.Lock()
        self.active_waypoint: int | None = None  # 0-based index of the visit underway
        # Set once the mission is over for good; the services then refuse with this reason.
        self.over: str | None = None
        self.publish_markers()
        self.publish_status({"state": "waiting_for_server", "waypoints": len(mission)})

    @property
    def topics(self) -> tuple[str, str]:
        """The resolved names of the marker and status topics."""
        return self._marker_pub.resolved_name, self._status_pub.resolved_name

    def publish_markers(self) -> None:
        self._marker_pub.publish(waypoint_markers(self.mission, self.statuses))

    def publish_status(self, fields: dict[str, Any]) -> None:
        self._status_pub.publish(String(data=json.dumps(fields, default=str)))

    def __call__(self, event: MissionEvent) -> None:
        with self._lock:
            if isinstance(event, WaypointProgress):
                if event.t - self._last_progress < PROGRESS_PERIOD:
                    return
                self._last_progress = event.t
            if isinstance(event, WaypointStarted):
                if event.index == 0 and event.attempt == 1:
                    # A new loop of a patrol: every waypoint is to come again.
                    self.statuses.clear()
                self.statuses[event.index] = MarkerStatus.ACTIVE
                self.active_waypoint = event.index
                self.publish_markers()
            elif isinstance(event, WaypointFinished):
                self.statuses[event.index] = _OUTCOME_MARKERS[event.outcome]
                self.active_waypoint = None
                self.publish_markers()
            elif isinstance(event, MissionFinished):
                self.active_waypoint = None
            fields = {"event": type(event).__name__, **asdict(event)}
            fields["state"] = _state(event)
            fields["waypoints"] = len(self.mission)
            self.publish_status(fields)


def run_topics_namespace(robot_ns: str) -> str:
    """Where ``navseq run`` publishes: ``/navseq``, or ``/robot1/navseq`` with ``--ns robot1``."""
    return (
        rosgraph.names.ns_join("/" + robot_ns.strip("/"), RUN_TOPICS_NS)
        if robot_ns.strip("/")
        else "/" + RUN_TOPICS_NS
    )


def _state(event: MissionEvent) -> str:
    """The ``state`` field of a status message: running, paused, succeeded, failed,
    cancelled or interrupted."""
    if isinstance(event, MissionPaused):
        return "paused"
    if not isinstance(event, MissionFinished):
        return "running"
    if event.success:
        return "succeeded"
    # The runner's reason for a run ended from outside ("interrupted: SIGINT" ...).
    if event.reason.startswith("cancelled"):
        return "cancelled"  # by the operator (~cancel)
    return "interrupted" if event.reason.startswith("interrupted") else "failed"
