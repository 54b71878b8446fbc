"""A fleet run recorded as one MCAP file (``navseq run --fleet FLEET --record``).

One file, ``RUN/fleet.mcap``, for the whole fleet, because that is what a Foxglove
user opens: one 3-D panel shows every robot on the one map, on one time line. The
map is written once (``/map``); every robot's topics are its one-robot recording's
under its namespace (``/alpha/navseq/pose``, ``/alpha/odom``, ``/alpha/plan`` ...,
:class:`~navseq.sinks.recording.sink.RecordingSink` with a namespace), and its frames
carry the namespace as prefix on the one ``/tf`` (``map → alpha/odom →
alpha/base_footprint``, as ROS 1's ``multi_robot.launch`` and Nav2's multi-robot
launch files name them), so the robots' trees join at ``map`` instead of fighting
over one ``odom``. All messages are stamped with the robots' one clock (the fleet
simulator's, or the stacks' ROS time).

A resumed fleet run records into a new file beside the first (``fleet-2.mcap``, ...),
as a resumed one-robot run does (``run-2.mcap``): the simulator's clock starts again
at 0 there, and nothing already written is touched.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.sinks.recording.encoding import RecordingFormat

if TYPE_CHECKING:
    from navseq.fleet.run import FleetRun
    from navseq.sinks.recording.sink import RecordingFile

FLEET_RECORDING = "fleet.mcap"
#: The metadata record naming the fleet's robots and their namespaces.
FLEET_METADATA = "navseq.fleet"


@dataclass(frozen=True)
class FleetRecordingChoice:
    """Whether a fleet run is recorded, in which encoding, and which of each robot's
    stack's own topics (``--record-topics``, under each robot's namespace)."""

    record: bool
    record_format: RecordingFormat = "ros2"
    topics: tuple[str, ...] = ()


#: The encoding a kind's stacks publish in: their messages are recorded as they come.
STACK_ENCODINGS = {"ros1": "ros1", "nav2": "ros2"}


def choose(
    given: bool | None,
    given_format: str | None,
    mission_record: bool,
    earlier: FleetRecordingChoice | None = None,
    *,
    topics: tuple[str, ...] = (),
    kind: str | None = None,
) -> FleetRecordingChoice:
    """``--record`` (else the mission's ``record:``; a resume also records when the run
    it continues did), ``--record-format`` (else the earlier run's, else ros2) and
    ``--record-topics`` on ``kind``'s stacks (None: the embedded simulator).

    Raises :class:`NavseqError` for what cannot be recorded, before anything is written
    or moves: no ``record`` extra, topics without ``--record``, topics of the simulator
    (navseq writes its topics itself), or in another encoding than the stacks'.
    """
    record = bool(given) or mission_record or (earlier is not None and earlier.record)
    chosen = given_format or (earlier.record_format if earlier is not None else None)
    record_format: RecordingFormat = "ros1" if chosen == "ros1" else "ros2"
    if record:
        from navseq.extras import require_extra

        require_extra("record", "recording the run (--record)")
    if topics:
        _check_topics(record, record_format, kind)
    return FleetRecordingChoice(record, record_format, topics if record else ())


def _check_topics(record: bool, record_format: str, kind: str | None) -> None:
    from navseq.errors import NavseqError

    if not record:
        raise NavseqError("adds topics to a recording: add --record", source="--record-topics")
    if kind not in STACK_ENCODINGS:
        raise NavseqError(
            "records each robot's stack's topics under its namespace, with --navigator ros1 "
            "or nav2 only (not the embedded simulator, whose map, poses, odometry, /tf and "
            "plans are recorded anyway)",
            source="--record-topics",
        )
    if record_format != STACK_ENCODINGS[kind]:
        ros = "ROS 1" if kind == "ros1" else "ROS 2"
        raise NavseqError(
            f"records the {ros} stacks' messages as they are published: add "
            f"--record-format {STACK_ENCODINGS[kind]}",
            source="--record-topics",
        )


def robot_topic(namespace: str, topic: str) -> str:
    """``/scan`` of the robot in ``alpha``: ``/alpha/scan``."""
    from navseq.sinks.recording.sink import namespace_prefix

    return f"{namespace_prefix(namespace)}/{topic.lstrip('/')}"


class FleetRecording:
    """The fleet's file: opened with the map before the robots move, one sink per robot
    with waypoints (a robot's listener), finished when every robot's run has ended."""

    def __init__(
        self, path: Path, record_format: RecordingFormat, topics: tuple[str, ...] = ()
    ) -> None:
        from navseq.sinks.recording.sink import RecordingFile

        self.path = path
        self.file: RecordingFile = RecordingFile(path, record_format)
        self.topics = topics

    @property
    def error(self) -> str | None:
        """Why the file could not be written to the end (None: it was)."""
        return self.file.error

    def start(self, run: FleetRun) -> None:
        """Open the file, write the fleet's metadata and its map, and give each robot
        at work its sink (before the robots' threads start)."""
        from navseq.sinks.recording import messages as msg
        from navseq.sinks.recording.sink import RecordingSink

        fleet = run.plan.fleet
        robots = {robot.name: robot.namespace for robot in fleet.robots}
        self.file.open({FLEET_METADATA: {"fleet": fleet.source, "robots": json.dumps(robots)}})
        grid = run.plan.grid
        clock = _clock_of(run)
        with self.file.lock:
            recording = self.file.recording
            if recording is not None and grid is not None:
                t = clock()
                recording.write(
                    "/map",
                    "nav_msgs/OccupancyGrid",
                    msg.occupancy_grid(t, fleet.mission.frame, grid),
                    msg.nanoseconds(t),
                )
        for member in run.members:
            if member.session is None:
                continue
            namespace = member.robot.namespace
            sink = RecordingSink(
                self.path,
                self.file.record_format,
                member.session.mission,
                numbers=member.session.numbers,
                published_topics=[robot_topic(namespace, topic) for topic in self.topics],
                namespace=namespace,
                shared=self.file,
            )
            member.listeners.append(sink)
            sink.tap(member.navigator)  # its stack's own topics, from now on

    def finish(self) -> None:
        self.file.finish()


def new_fleet_recording(folder: Path, choice: FleetRecordingChoice) -> FleetRecording:
    """``folder/fleet.mcap``, or the first free ``fleet-N.mcap`` (a resumed run's)."""
    from navseq.run.folder import reserve_file

    return FleetRecording(
        reserve_file(folder, FLEET_RECORDING), choice.record_format, choice.topics
    )


def _clock_of(run: FleetRun) -> Callable[[], float]:
    """The robots' clock, as their runs stamp their events (the first robot's navigator)."""
    for member in run.members:
        if member.navigator is not None:
            return member.navigator.now
    return lambda: 0.0


__all__ = [
    "FLEET_METADATA",
    "FLEET_RECORDING",
    "STACK_ENCODINGS",
    "FleetRecording",
    "FleetRecordingChoice",
    "choose",
    "new_fleet_recording",
    "robot_topic",
]
