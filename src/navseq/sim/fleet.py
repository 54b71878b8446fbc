"""The other robots of a simulated fleet, without ROS: who they are, where they were seen.

Both the ROS 1 sim nodes (:mod:`navseq.ros1.fleet`, poses looked up in TF) and the ROS 2
sim node (:mod:`navseq.ros2.sim_node`, transforms heard on ``/tf``) give each robot the
names of the others and feed the others' poses to
:meth:`navseq.sim.world.SimWorld.set_other_robots` every step. What they share lives
here, so that both say the same thing about a bad list and treat a silent robot alike:

- :func:`other_robots_problem`: the checks of the list of other robots (no empty name,
  not this robot itself: it would bump into its own footprint, and no name twice);
- :class:`SeenRobots`: each other robot's last pose in the map frame, assembled from
  the two transforms its simulator publishes (``map -> NS/odom`` and
  ``NS/odom -> NS/base_footprint``); a robot not heard from for ``tolerance`` seconds
  is left out (its simulator is gone, most likely, and so is the robot) rather than
  guessed at, and reported as missing so the caller can warn.

Times are whatever clock the caller gives (the ROS 2 node uses the wall clock at which
a transform arrived, so that robots with different simulated clocks still see each
other).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from navseq.geometry import Pose2D, compose
from navseq.sim.footprint import TURTLEBOT3_BURGER, Footprint

WARN_PERIOD = 10.0  # s between two warnings about other robots without a pose


def other_robots_problem(names: Sequence[str], own: str, what: str = "name") -> str | None:
    """Why ``names`` (the other robots' frames or namespaces) is not a usable list, or
    None. ``own`` is this robot's own ``what`` (frame or namespace)."""
    if any(not name for name in names):
        return f"a {what} is empty: {list(names)!r}"
    if own in names:
        return f"lists this robot's own {what} {own!r}; name only the other robots"
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        return f"names {', '.join(repeated)} more than once"
    return None


def missing_warning(missing: Iterable[str], map_frame: str) -> str:
    """The one warning for robots whose pose is unknown or too old."""
    return (
        f"other robot(s) {', '.join(missing)}: no recent pose in {map_frame!r}; "
        "not avoided until there is"
    )


@dataclass
class _Sighting:
    """The two halves of one robot's pose and when each was last heard."""

    map_to_odom: Pose2D | None = None
    map_to_odom_at: float = -float("inf")
    odom_to_base: Pose2D | None = None
    odom_to_base_at: float = -float("inf")


@dataclass
class SeenRobots:
    """The other robots of a fleet by namespace, as their transforms tell where they are.

    Robot ``robot2`` is seen through ``map_frame -> robot2/odom`` and
    ``robot2/odom -> robot2/base_footprint``; every other transform is ignored (so the
    caller can hand over everything it hears on ``/tf``, its own robot's included).
    Every robot is taken to have ``footprint`` (one model for the whole fleet, as in
    ROS 1's ``multi_robot.launch``).
    """

    namespaces: tuple[str, ...]
    tolerance: float
    footprint: Footprint = TURTLEBOT3_BURGER
    map_frame: str = "map"
    _by_odom: dict[str, _Sighting] = field(init=False, default_factory=dict)
    _by_base: dict[str, _Sighting] = field(init=False, default_factory=dict)
    _sightings: dict[str, _Sighting] = field(init=False, default_factory=dict)

    def __post_init__(self) -> None:
        for namespace in self.namespaces:
            sighting = _Sighting()
            self._sightings[namespace] = sighting
            self._by_odom[f"{namespace}/odom"] = sighting
            self._by_base[f"{namespace}/base_footprint"] = sighting

    def heard(self, parent: str, child: str, pose: Pose2D, at: float) -> None:
        """One transform ``parent -> child`` (leading ``/`` allowed), heard at ``at``."""
        parent, child = parent.lstrip("/"), child.lstrip("/")
        if parent == self.map_frame and child in self._by_odom:
            sighting = self._by_odom[child]
            sighting.map_to_odom, sighting.map_to_odom_at = pose, at
        elif child in self._by_base and self._by_base[child] is self._by_odom.get(parent):
            sighting = self._by_base[child]
            sighting.odom_to_base, sighting.odom_to_base_at = pose, at

    def heard_from(self, namespace: str, parent: str, child: str, pose: Pose2D, at: float) -> None:
        """One transform heard on ``namespace``'s own tf topic (Nav2's multi-robot
        convention: plain frame names ``map``, ``odom``, ``base_footprint``)."""
        if namespace not in self._sightings:
            return
        parent, child = parent.lstrip("/"), child.lstrip("/")
        if parent != self.map_frame:
            parent = f"{namespace}/{parent}"
        self.heard(parent, f"{namespace}/{child}", pose, at)

    def poses(self, now: float) -> tuple[list[tuple[Pose2D, Footprint]], list[str]]:
        """(pose in the map frame, footprint) of every robot heard from within
        ``tolerance`` of ``now``, and the namespaces of the others."""
        found: list[tuple[Pose2D, Footprint]] = []
        missing: list[str] = []
        for namespace, sighting in self._sightings.items():
            if (
                sighting.map_to_odom is None
                or sighting.odom_to_base is None
                or now - min(sighting.map_to_odom_at, sighting.odom_to_base_at) > self.tolerance
            ):
                missing.append(namespace)
                continue
            found.append((compose(sighting.map_to_odom, sighting.odom_to_base), self.footprint))
        return found, missing
