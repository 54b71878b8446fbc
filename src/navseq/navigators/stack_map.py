"""Pre-flight on the map a running navigation stack publishes, when no map file is known.

``navseq run --navigator ros1|nav2`` without ``--map`` (and no ``map:`` in the mission)
still has a map to check the waypoints against: the stack's own. ROS 1's map_server
latches ``nav_msgs/OccupancyGrid`` on ``map``; Nav2's map_server publishes it on ``map``
with transient-local durability (reliable, depth 1), which a late subscriber receives
just the same. Each ROS package only subscribes (``navseq.ros1.run_setup``,
:meth:`navseq.ros2.navigator.Nav2Navigator.read_map`); which topic to take, how long to
wait, the conversion (:func:`navseq.sim.occupancy.grid_from_map_message`) and what is
said about it live here, once, without ROS.

Which topic. ``map`` is resolved in the robot's namespace, as the stacks themselves do:
Nav2's multi-robot bringup starts one map_server per robot namespace (``/robot1/map``,
which the namespace's costmaps subscribe to), and move_base's static layer subscribes to
``map`` relative to its namespace too. Many ROS 1 fleets instead run a single
map_server on the global ``/map`` and remap each robot's ``map`` to it (navseq's own
ROS 1 fleet launch does). So the candidates are the namespaced ``map`` first, then
``/map`` (one topic without a namespace), and a message on ``/map`` is taken only when
nobody publishes the namespaced topic, or when only it came within the wait.

The wait is bounded (:data:`MAP_WAIT` wall seconds, ``--map-wait``): a latched or
transient-local map comes within milliseconds of the subscription, so the wait is only
long for a stack without a map, whose run then goes on with pre-flight skipped, said on
stderr. A map in another frame than the goals' is not used: its cells would be checked
at the wrong places.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from navseq.navigators.registry import NavigatorDraft
    from navseq.sim.occupancy import OccupancyGrid

MAP_WAIT = 2.0  # s of wall time for the stack's map when no map file is known
MAP_TOPIC = "map"  # resolved in the robot's namespace
GLOBAL_MAP_TOPIC = "/map"
GRAPH_LOOK = 0.1  # s between looks at who publishes the candidate topics


def map_wait_setting(value: Any) -> float:
    """``--map-wait S`` as seconds: finite and >= 0 (0: do not read the map)."""
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        seconds = math.nan
    if not 0.0 <= seconds < math.inf:
        raise NavseqError(
            f"must be >= 0 seconds (0: do not read the stack's map), not {value}",
            source="--map-wait",
        )
    return seconds


def map_topics(own: str) -> tuple[str, ...]:
    """The topics to take the map from, best first: ``own`` (``map`` resolved in the
    robot's namespace, e.g. ``/robot1/map``), then the global ``/map``."""
    return (own,) if own == GLOBAL_MAP_TOPIC else (own, GLOBAL_MAP_TOPIC)


def topics_text(topics: Sequence[str]) -> str:
    return " or ".join(topics)


@dataclass(frozen=True)
class StackMap:
    """The map a stack published: the topic it came on, its frame, its cells."""

    topic: str
    frame: str  # header.frame_id without a leading slash; "" when the stack left it empty
    grid: OccupancyGrid

    @property
    def description(self) -> str:
        """``the map on /map: 384 x 384 cells at 0.050 m``: stderr and the report say so."""
        grid = self.grid
        return (
            f"the map on {self.topic}: {grid.width} x {grid.height} cells at "
            f"{grid.resolution:.3f} m"
        )


def stack_map_from_message(message: Any, topic: str) -> StackMap:
    """A ``nav_msgs/OccupancyGrid`` (ROS 1 or ROS 2) heard on ``topic``; NavseqError
    when its fields do not make a map (see :func:`~navseq.sim.occupancy.grid_from_cells`)."""
    from navseq.sim.occupancy import grid_from_map_message

    grid = grid_from_map_message(message, source=f"topic {topic}")
    return StackMap(topic, str(message.header.frame_id).lstrip("/"), grid)


class MapCatch:
    """The first map message heard on each candidate topic, and the choice among them.

    Subscription callbacks (on the client library's threads) call :meth:`offer`; the
    caller's thread blocks in :meth:`wait`. Messages are kept as they came and converted
    by the caller, so a callback never does more than store a reference.
    """

    def __init__(self, topics: Sequence[str]) -> None:
        self.topics = tuple(topics)
        self._messages: dict[str, Any] = {}
        self._heard = threading.Condition()

    def offer(self, topic: str, message: Any) -> None:
        with self._heard:
            self._messages.setdefault(topic, message)
            self._heard.notify_all()

    def wait(self, timeout: float, has_publisher: Callable[[str], bool]) -> tuple[str, Any] | None:
        """(topic, message) of the best candidate heard within ``timeout`` wall seconds.

        The first candidate is taken as soon as it comes; a later one once no earlier
        candidate has a publisher (``has_publisher``, asked of the ROS graph), or at the
        deadline. None: no map came.
        """
        deadline = time.monotonic() + timeout
        while True:
            with self._heard:
                heard = dict(self._messages)
            for index, topic in enumerate(self.topics):
                if topic not in heard:
                    continue
                better = self.topics[:index]
                if not better or not any(has_publisher(name) for name in better):
                    return topic, heard[topic]
                break  # a better topic has a publisher: its message may still come
            remaining = deadline - time.monotonic()
            if remaining <= 0.0:
                return next(((t, heard[t]) for t in self.topics if t in heard), None)
            with self._heard:
                if len(self._messages) == len(heard):
                    self._heard.wait(min(remaining, GRAPH_LOOK))


@dataclass(frozen=True)
class MapUse:
    """What a run takes from the stack's map: the grid (None: none usable) and one line
    saying so, for stderr (``note``) and the report's ``navigator.map_source``."""

    grid: OccupancyGrid | None
    note: str
    source: str


def preflight_on_stack_map(
    draft: NavigatorDraft,
    read: Callable[[Sequence[str], float], StackMap | None],
    topics: Sequence[str],
    goal_frame: str,
    wait: float = MAP_WAIT,
) -> MapUse:
    """Read the stack's map (``read(topics, wait)``: the ROS package's subscription) and
    check the mission against it for the draft's robot, already settled from the stack.

    Raises :class:`~navseq.errors.MissionErrors` (exit 2, nothing moved) when pre-flight
    finds problems; a map that does not come, cannot be read or is in another frame
    than the goals is said in the note, and the run goes on without pre-flight.
    """
    skipped = "pre-flight skipped" if draft.preflight else "no pre-flight (--no-preflight)"
    where = topics_text(topics)
    if wait <= 0.0:
        text = "--map-wait 0: the stack's map was not read"
        return MapUse(None, f"{text}: {skipped}", text)
    try:
        found = read(topics, wait)
    except NavseqError as error:
        text = f"the stack's map cannot be used: {error}"
        return MapUse(None, f"{text}: {skipped}", text)
    if found is None:
        text = f"no map on {where} within {wait:g} s"
        hint = " (give --map to check the waypoints)" if draft.preflight else ""
        return MapUse(None, f"{text}: {skipped}{hint}", text)
    goal_frame = goal_frame.lstrip("/")
    if found.frame and goal_frame and found.frame != goal_frame:
        text = (
            f"{found.description} is in frame '{found.frame}', the goals in "
            f"'{goal_frame}': not used"
        )
        return MapUse(None, f"{text}: {skipped}", text)
    draft.check_map(found.grid, context=f"pre-flight on {found.description}")
    if draft.preflight:
        return MapUse(found.grid, f"pre-flight on {found.description}", found.description)
    return MapUse(found.grid, f"{found.description} ({skipped})", found.description)
