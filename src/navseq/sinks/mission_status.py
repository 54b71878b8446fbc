"""A mission's progress as the ROS nodes show it, without ROS: marker specs and status.

Both ROS faces (``navseq.ros1.mission_topics``, ``navseq.ros2.mission_topics``) publish
the same two things: waypoint markers for RViz (one arrow and one number per waypoint,
coloured by status) and a JSON status message per mission event. What they show is
decided here, once; each ROS package only turns :class:`MarkerSpec` into its own
``visualization_msgs/Marker`` and a status dict into ``std_msgs/String``.

:class:`MissionStatus` follows the events (which waypoint is active, each one's marker
status, whether the mission is over) and says what to publish; it is called on the
run's thread and read (``active_waypoint``, ``over``) by service handlers on another,
hence its lock.
"""

from __future__ import annotations

import abc
import enum
import json
import math
import threading
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

from navseq.executor.control import cancelled_by_operator
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
from navseq.sinks.json_events import Eta

PROGRESS_PERIOD = 0.5  # s of mission time between two progress status messages
ARROW_NS = "navseq_waypoints"
LABEL_NS = "navseq_labels"
ARROW_LENGTH = 0.35  # m
TEXT_HEIGHT = 0.18  # m
LABEL_LIFT = 0.25  # m above the waypoint


class MarkerStatus(str, enum.Enum):
    PENDING = "pending"  # not tried yet (in this loop)
    ACTIVE = "active"  # the robot is on its way there
    REACHED = "reached"
    SKIPPED = "skipped"
    FAILED = "failed"


# RGBA: grey for what is to come, blue for the current goal, green / orange / red for
# outcomes — the colours roboticists expect from traffic lights.
STATUS_COLOURS: dict[MarkerStatus, tuple[float, float, float, float]] = {
    MarkerStatus.PENDING: (0.6, 0.6, 0.6, 0.9),
    MarkerStatus.ACTIVE: (0.1, 0.45, 1.0, 1.0),
    MarkerStatus.REACHED: (0.1, 0.75, 0.2, 1.0),
    MarkerStatus.SKIPPED: (1.0, 0.6, 0.0, 1.0),
    MarkerStatus.FAILED: (0.9, 0.1, 0.1, 1.0),
}

OUTCOME_MARKERS = {
    WaypointOutcome.REACHED: MarkerStatus.REACHED,
    WaypointOutcome.SKIPPED: MarkerStatus.SKIPPED,
    WaypointOutcome.FAILED: MarkerStatus.FAILED,
    WaypointOutcome.NOT_RUN: MarkerStatus.PENDING,
}


class MarkerKind(str, enum.Enum):
    ARROW = "arrow"
    LABEL = "label"  # a text facing the viewer


@dataclass(frozen=True)
class MarkerSpec:
    """One marker, as plain data: each ROS package builds its message from it.

    ``yaw`` (radians) orients an arrow; ``scale`` is (x, y, z) as
    ``visualization_msgs/Marker`` means it for the kind (a label uses only z, the
    text height).
    """

    kind: MarkerKind
    namespace: str
    id: int
    frame: str
    x: float
    y: float
    z: float
    yaw: float
    scale: tuple[float, float, float]
    colour: tuple[float, float, float, float]
    text: str = ""


def marker_specs(
    mission: Mission,
    statuses: Mapping[int, MarkerStatus],
    *,
    arrow_length: float = ARROW_LENGTH,
    text_height: float = TEXT_HEIGHT,
) -> list[MarkerSpec]:
    """An arrow and a label for every waypoint of ``mission``, in waypoint order.

    Waypoints missing from ``statuses`` are PENDING. Labels read ``3`` or ``3 dock``
    (1-based, like navseq's messages) and float above the arrow. Every marker has the
    waypoint index as id in its namespace, so a rebuilt array replaces the last one
    in place.
    """
    specs: list[MarkerSpec] = []
    for index, waypoint in enumerate(mission.waypoints):
        colour = STATUS_COLOURS[statuses.get(index, MarkerStatus.PENDING)]
        specs.append(
            MarkerSpec(
                MarkerKind.ARROW,
                ARROW_NS,
                index,
                mission.frame,
                waypoint.x,
                waypoint.y,
                waypoint.z,
                waypoint.pose.yaw,
                (arrow_length, arrow_length * 0.2, arrow_length * 0.2),
                colour,
            )
        )
        specs.append(
            MarkerSpec(
                MarkerKind.LABEL,
                LABEL_NS,
                index,
                mission.frame,
                waypoint.x,
                waypoint.y,
                waypoint.z + LABEL_LIFT,
                0.0,
                (0.0, 0.0, text_height),
                colour,
                str(index + 1) + (f" {waypoint.name}" if waypoint.name else ""),
            )
        )
    return specs


def status_state(event: MissionEvent) -> str:
    """The ``state`` field of a status message: running, paused, succeeded, failed,
    cancelled or interrupted."""
    if isinstance(event, MissionPaused):
        return "paused"
    if not isinstance(event, MissionFinished):
        return "running"
    if event.success:
        return "succeeded"
    # The runner's reason for a run ended from outside ("interrupted: SIGINT" ...).
    if cancelled_by_operator(event.reason):
        return "cancelled"  # by the operator (~cancel)
    return "interrupted" if event.reason.startswith("interrupted") else "failed"


@dataclass(frozen=True)
class StatusUpdate:
    """What one event changes on the topics: new markers (or None), the status fields."""

    markers_changed: bool
    status: dict[str, Any]


class MissionStatus:
    """Follows one mission's events; says what its marker and status topics show."""

    def __init__(self, mission: Mission, progress_period: float = PROGRESS_PERIOD) -> None:
        self.mission = mission
        # The run's ETA, when the run service keeps one: progress messages then say
        # ``eta_s`` and ``eta_upper_s``.
        self.eta: Eta | None = None
        self.statuses: dict[int, MarkerStatus] = {}
        self.progress_period = progress_period
        self._last_progress = -math.inf
        self._lock = threading.Lock()
        self.active_waypoint: int | None = None  # 0-based index of the visit underway
        # Set once the mission is over for good; the services then refuse with this reason.
        self.over: str | None = None

    def initial_status(self) -> dict[str, Any]:
        """The status before the run starts: waiting for the navigation server."""
        return {"state": "waiting_for_server", "waypoints": len(self.mission)}

    def markers(self) -> list[MarkerSpec]:
        with self._lock:
            statuses = dict(self.statuses)
        return marker_specs(self.mission, statuses)

    def update(self, event: MissionEvent) -> StatusUpdate | None:
        """Follow ``event``; None when nothing is to be published (progress thinned to
        one message per ``progress_period`` of mission time)."""
        with self._lock:
            markers_changed = False
            if isinstance(event, WaypointProgress):
                if event.t - self._last_progress < self.progress_period:
                    return None
                self._last_progress = event.t
            if isinstance(event, WaypointStarted):
                if event.index == 0 and event.attempt == 1:
                    # A new loop of a patrol: every waypoint is to come again.
                    self.statuses.clear()
                self.statuses[event.index] = MarkerStatus.ACTIVE
                self.active_waypoint = event.index
                markers_changed = True
            elif isinstance(event, WaypointFinished):
                self.statuses[event.index] = OUTCOME_MARKERS[event.outcome]
                self.active_waypoint = None
                markers_changed = True
            elif isinstance(event, MissionFinished):
                self.active_waypoint = None
            fields = {"event": type(event).__name__, **asdict(event)}
            fields["state"] = status_state(event)
            fields["waypoints"] = len(self.mission)
            if self.eta is not None and isinstance(event, WaypointProgress):
                fields["eta_s"] = _seconds(self.eta.eta_s)
                fields["eta_upper_s"] = _seconds(self.eta.eta_upper_s)
            return StatusUpdate(markers_changed, fields)


def _seconds(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else round(max(value, 0.0), 1)


class StatusPublisher(abc.ABC):
    """A mission listener putting :class:`MissionStatus`'s markers and JSON status on two
    topics whenever an event changes them; each ROS adapter says how it publishes.

    A subclass creates its publishers, then calls :meth:`publish_all` once so that a
    latecomer to the (latched) topics sees the mission before its first event.
    """

    def __init__(self, mission: Mission) -> None:
        self.state = MissionStatus(mission)

    @abc.abstractmethod
    def publish_markers(self) -> None:
        """Publish ``self.state.markers()``."""

    @abc.abstractmethod
    def publish_status_text(self, text: str) -> None:
        """Publish one status message: the fields as a JSON object."""

    def publish_status(self, fields: dict[str, Any]) -> None:
        self.publish_status_text(json.dumps(fields, default=str))

    def publish_all(self) -> None:
        """The markers and the status before any event."""
        self.publish_markers()
        self.publish_status(self.state.initial_status())

    def __call__(self, event: MissionEvent) -> None:
        update = self.state.update(event)
        if update is None:
            return
        if update.markers_changed:
            self.publish_markers()
        self.publish_status(update.status)
