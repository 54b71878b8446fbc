"""The run's recording (``run.mcap``): a mission listener writing ROS topics as it goes.

What is written, on which topic (all stamped with the run's clock, log time in ns):

=====================  ================================  ================================
topic                  type                              when
=====================  ================================  ================================
``/map``               nav_msgs/OccupancyGrid            once, when the mission starts
``/navseq/pose``       geometry_msgs/PoseStamped (map)   every progress event (~5 Hz, sim)
``/odom``              nav_msgs/Odometry                 every progress event
``/tf``                tf2_msgs/TFMessage                every progress event
``/plan``              nav_msgs/Path                     every plan the stack reports
``/navseq/goal``       geometry_msgs/PoseStamped         every goal sent
``/navseq/waypoints``  visualization_msgs/MarkerArray    at the start, each goal, each end
``/navseq/events``     JSON (events.schema.json)         every mission event
=====================  ================================  ================================

The frames are those the run knows: the mission's frame (``map``), ``odom`` and
``base_footprint``. navseq sees the robot's pose in the map only, so ``map → odom`` is
the identity and ``odom → base_footprint`` the pose (the simulator's own frames are
exactly these); the odometry's velocity is the change between two poses. The events'
JSON Schema is an attachment of the file (:meth:`McapRecording.write_json` says why).

The file is written as the run goes, chunk by chunk, and flushed at least every
:data:`FLUSH_PERIOD` seconds of wall time and at each waypoint's end: a process killed
mid-run leaves a file readable up to its last complete chunk. A write that fails (disk
full) stops the recording, not the mission: :attr:`RecordingSink.error` says why.
"""

from __future__ import annotations

import contextlib
import errno
import math
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.executor.events import (
    MissionEvent,
    MissionFinished,
    MissionStarted,
    WaypointFinished,
    WaypointPlan,
    WaypointProgress,
    WaypointStarted,
)
from navseq.geometry import Pose2D, normalize_angle
from navseq.mission.model import Mission
from navseq.sim.occupancy import OccupancyGrid
from navseq.sinks.mission_status import MissionStatus
from navseq.sinks.recording import messages as msg
from navseq.sinks.recording.encoding import McapRecording, RecordingFormat

#: Missions up to this many waypoints get every marker at each change (a player that
#: shows only a topic's latest message shows them all); longer ones the changed ones.
FULL_MARKERS_UP_TO = 500
#: Seconds of wall time between two flushes at most: what a crash can lose.
FLUSH_PERIOD = 1.0
ODOM_FRAME = "odom"
BASE_FRAME = "base_footprint"
EVENTS_SCHEMA_FILE = "events.schema.json"  # the attachment holding it
#: Topic -> ROS type of every ROS topic the sink writes (the events are JSON).
TOPICS = {
    "/map": "nav_msgs/OccupancyGrid",
    "/navseq/pose": "geometry_msgs/PoseStamped",
    "/odom": "nav_msgs/Odometry",
    "/tf": "tf2_msgs/TFMessage",
    "/plan": "nav_msgs/Path",
    "/navseq/goal": "geometry_msgs/PoseStamped",
    "/navseq/waypoints": "visualization_msgs/MarkerArray",
}
EVENTS_TOPIC = "/navseq/events"
#: The metadata record holding what a journal's header says (navseq report reads it).
RUN_METADATA = "navseq.run"
#: Topics a fleet's recording has once, whatever the robot: the map, and the one tf tree
#: (each robot's frames carry its namespace, so one 3-D view shows every robot).
SHARED_TOPICS = frozenset({"/map", "/tf"})


class RecordingFile:
    """One MCAP file being written, by one sink or by several (a fleet's robots).

    Holds what every writer of the file shares: the open :class:`McapRecording`, the
    lock that lets one writer at a time at it (a fleet's robots write from their own
    threads; a stack's taps from its client library's), the flush timing and the error
    that stopped it. :meth:`open` opens it, :meth:`finish` writes its summary.
    """

    def __init__(
        self,
        path: Path,
        record_format: RecordingFormat,
        *,
        wall_clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.path = path
        self.record_format = record_format
        self.error: str | None = None
        self.lock = threading.Lock()
        self.recording: McapRecording | None = None
        self._wall_clock = wall_clock
        self._last_flush = 0.0
        self._events_schema = ""

    def open(self, metadata: Mapping[str, Mapping[str, str]] | None = None) -> None:
        """Create the file and write its metadata records (name -> string fields)."""
        from navseq.sinks.recording.definitions import events_schema

        self._events_schema = events_schema()
        with self.lock:
            try:
                self.recording = McapRecording(self.path.open("wb"), self.record_format)
                for name, fields in (metadata or {}).items():
                    self.recording.add_metadata(name, fields)
            except OSError as error:
                self.fail(error)
            self._last_flush = self._wall_clock()

    def write_event(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """One mission event (JSON) on ``topic`` (the caller holds the lock)."""
        assert self.recording is not None
        self.recording.write_json(topic, EVENTS_SCHEMA_FILE, self._events_schema, data, log_time_ns)

    def flush(self, *, when_due: bool = False) -> None:
        """Hand the file's open chunk to the operating system (``when_due``: only if
        :data:`FLUSH_PERIOD` has passed since the last time); the caller holds the lock."""
        if self.recording is None:
            return
        if when_due and self._wall_clock() - self._last_flush < FLUSH_PERIOD:
            return
        try:
            self.recording.flush()
        except OSError as error:
            self.fail(error)
        self._last_flush = self._wall_clock()

    def finish(self) -> None:
        """Write the summary and close the file (once)."""
        with self.lock:
            recording, self.recording = self.recording, None
            if recording is not None:
                try:
                    recording.finish()
                except OSError as error:
                    self.fail(error)

    def fail(self, error: OSError) -> None:
        """Stop recording (the mission goes on) and say why (the caller holds the lock)."""
        why = "the disk is full" if error.errno == errno.ENOSPC else error.strerror or str(error)
        self.error = f"{self.path}: cannot write it: {why}"
        recording, self.recording = self.recording, None
        if recording is not None:
            # The file is as complete as it can be; the error above says why.
            with contextlib.suppress(OSError, ValueError):
                recording.finish()


class RecordingSink:
    """Writes ``path`` (an MCAP file) from the run's events; a context manager.

    ``grid`` is the map the run uses (None: no ``/map``); ``numbers`` the waypoints'
    positions in the mission file when the run is a part of it (for the events'
    ``number``); ``run_metadata`` what ``navseq report`` needs to rebuild the run from
    the recording (:func:`navseq.sinks.recording.reading.run_metadata`). The file is
    opened on entering and finished on leaving.

    A fleet's robots share one file (``shared``, opened and finished by its owner, who
    writes the one ``/map``): each robot's sink writes its topics under its
    ``namespace`` (``/alpha/navseq/pose``, ``/alpha/odom``, ``/alpha/navseq/events``)
    and its frames with the namespace as prefix (``alpha/odom``,
    ``alpha/base_footprint``) on the one ``/tf``.
    """

    def __init__(
        self,
        path: Path,
        record_format: RecordingFormat,
        mission: Mission,
        grid: OccupancyGrid | None = None,
        *,
        numbers: Sequence[int] | None = None,
        run_metadata: Mapping[str, str] | None = None,
        published_topics: Sequence[str] = (),
        wall_clock: Callable[[], float] = time.monotonic,
        namespace: str = "",
        shared: RecordingFile | None = None,
    ) -> None:
        self._own = shared is None
        self._file = (
            shared
            if shared is not None
            else RecordingFile(path, record_format, wall_clock=wall_clock)
        )
        self.path = self._file.path
        #: Topics recorded as the navigation stack publishes them (``--record-topics``,
        #: :meth:`tap`); navseq's own message on such a topic is not written.
        self.published_topics = tuple(published_topics)
        self.record_format = self._file.record_format
        #: Whether a mission event was recorded (a run refused before its start leaves
        #: a file of nothing, which the session removes).
        self.began = False
        self._mission = mission
        self._frame = mission.frame
        self._grid = grid if self._own else None  # a shared file's map is its owner's
        self._numbers = numbers
        self._run_metadata = run_metadata
        self._status = MissionStatus(mission)
        self._prefix = namespace_prefix(namespace)
        self._odom_frame = frame_in(namespace, ODOM_FRAME)
        self._base_frame = frame_in(namespace, BASE_FRAME)
        self._map_written = False
        self._last_pose: tuple[float, Pose2D] | None = None
        self._velocity = (0.0, 0.0)

    @property
    def error(self) -> str | None:
        """Why the file stopped being written (None: it did not)."""
        return self._file.error

    def tap(self, navigator: Any) -> None:
        """Record :attr:`published_topics` as ``navigator``'s stack publishes them.

        Raises :class:`NavseqError` for a navigator that cannot (``prepare`` refuses
        those first: the simulator's topics are what navseq writes anyway).
        """
        if not self.published_topics:
            return
        record_topics = getattr(navigator, "record_topics", None)
        if record_topics is None:
            raise NavseqError(
                "this navigator cannot record its stack's topics", source="--record-topics"
            )
        record_topics(self.published_topics, self.write_published)

    def write_published(
        self, topic: str, type_name: str, definition: str, data: bytes, t: float
    ) -> None:
        """Write a message as the stack published it (see :data:`PublishedSink`)."""
        file = self._file
        with file.lock:
            if file.recording is None:
                return
            try:
                file.recording.write_serialised(
                    topic, type_name, definition, data, msg.nanoseconds(t)
                )
            except OSError as error:
                file.fail(error)

    def __enter__(self) -> RecordingSink:
        if self._own:
            metadata = {} if self._run_metadata is None else {RUN_METADATA: self._run_metadata}
            self._file.open(metadata)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._own:
            self._file.finish()
        else:  # the owner finishes the file; this robot's part is handed to the system
            with self._file.lock:
                self._file.flush()

    def __call__(self, event: MissionEvent) -> None:
        file = self._file
        with file.lock:
            if file.recording is None:
                return
            self.began = True
            try:
                self._write(event)
            except OSError as error:
                file.fail(error)
                return
            file.flush(when_due=not isinstance(event, (WaypointFinished, MissionFinished)))

    # -- internals -----------------------------------------------------------------------

    def _write(self, event: MissionEvent) -> None:
        t = event.t
        update = self._status.update(event)
        if isinstance(event, MissionStarted):
            self._last_pose = None
            if self._grid is not None and not self._map_written:
                self._ros("/map", t, msg.occupancy_grid(t, self._frame, self._grid))
                self._map_written = True
            self._markers(t)
        elif isinstance(event, WaypointProgress):
            self._robot_pose(t, Pose2D(event.x, event.y, event.yaw))
        elif isinstance(event, WaypointPlan):
            self._ros("/plan", t, msg.path(t, self._frame, event.path))
        elif isinstance(event, WaypointStarted):
            goal = Pose2D(event.x, event.y, event.yaw)
            z = self._mission.waypoints[event.index].z
            self._ros("/navseq/goal", t, msg.pose_stamped(t, self._frame, goal, z))
        if update is not None and update.markers_changed:
            changed = getattr(event, "index", None)
            self._markers(
                t, None if isinstance(event, WaypointStarted) and changed == 0 else changed
            )
        self._event(event)

    def _robot_pose(self, t: float, where: Pose2D) -> None:
        last = self._last_pose
        if last is not None and t > last[0]:
            dt = t - last[0]
            heading = math.atan2(where.y - last[1].y, where.x - last[1].x)
            forward = 1.0 if math.cos(heading - where.yaw) >= 0 else -1.0
            speed = forward * math.hypot(where.x - last[1].x, where.y - last[1].y) / dt
            self._velocity = (speed, normalize_angle(where.yaw - last[1].yaw) / dt)
        self._last_pose = (t, where)
        odom, base = self._odom_frame, self._base_frame
        self._ros("/navseq/pose", t, msg.pose_stamped(t, self._frame, where))
        self._ros("/odom", t, msg.odometry(t, odom, base, where, *self._velocity))
        identity = Pose2D(0.0, 0.0, 0.0)
        transforms = [
            msg.transform(t, self._frame, odom, identity),
            msg.transform(t, odom, base, where),
        ]
        self._ros("/tf", t, msg.tf_message(transforms))

    def _markers(self, t: float, changed: int | None = None) -> None:
        """The waypoint markers: all of them, or of a long mission only the ``changed``
        waypoint's (a marker replaces the one with its namespace and id, so the rest
        stay as they were; all of them at every change would grow with the square of
        the waypoints: 10¹⁰ markers for 100 000)."""
        specs = self._status.markers()
        if changed is not None and len(self._mission.waypoints) > FULL_MARKERS_UP_TO:
            specs = [spec for spec in specs if spec.id == changed]
        self._ros("/navseq/waypoints", t, msg.marker_array(t, specs))

    def _event(self, event: MissionEvent) -> None:
        from navseq.sinks.json_events import event_to_json

        self._file.write_event(
            self._prefix + EVENTS_TOPIC,
            event_to_json(event, self._numbers).encode(),
            msg.nanoseconds(event.t),
        )

    def _ros(self, topic: str, t: float, message: dict[str, Any]) -> None:
        recording = self._file.recording
        assert recording is not None
        # One /map and one /tf for a fleet (frames carry the namespace); the rest per robot.
        name = topic if topic in SHARED_TOPICS else self._prefix + topic
        if name in self.published_topics:
            return  # the stack's own messages are recorded there
        recording.write(name, TOPICS[topic], message, msg.nanoseconds(t))


def namespace_prefix(namespace: str) -> str:
    """``/alpha`` for the namespace ``alpha`` (or ``/alpha/``), ``""`` for none: what a
    robot's topics start with."""
    stripped = namespace.strip("/")
    return f"/{stripped}" if stripped else ""


def frame_in(namespace: str, frame: str) -> str:
    """A robot's frame with its namespace as prefix (``alpha/odom``), as ROS 1's
    ``tf_prefix`` and Nav2's multi-robot launch files name them; ``frame`` for none."""
    stripped = namespace.strip("/")
    return f"{stripped}/{frame}" if stripped else frame


__all__ = [
    "EVENTS_TOPIC",
    "FLUSH_PERIOD",
    "RUN_METADATA",
    "SHARED_TOPICS",
    "TOPICS",
    "RecordingFile",
    "RecordingSink",
    "frame_in",
    "namespace_prefix",
]
