"""Several simulated robots on one map, in one process, on one clock: a fleet without ROS.

:class:`FleetWorld` holds one :class:`~navseq.sim.world.SimWorld` per robot (its own body
and navigation server, each robot with its own :class:`~navseq.mission.robot.RobotProfile`:
mixed footprints are fine) and steps them together. Each :meth:`FleetWorld.step`:

1. lets the right-of-way rule (:class:`navseq.sim.right_of_way.RightOfWay`) look at the
   fleet and decide who gives way to whom (it sends a robot aside, or back to its goal);
2. steps the robots one after another, each after being told where every other robot
   is *now* (those stepped before it at their new poses), so a body never moves into
   another robot: a move that would overlap one is refused, as the single robot's body
   refuses to enter a wall;
3. counts, in ``collisions``, the pairs of robots whose footprints overlap after the
   step (with a correct server and rule it stays zero).

Goals go through each robot's own server: ``fleet.world("r1").server.set_goal(pose)``
and ``.cancel()`` (or :meth:`FleetWorld.set_goal` / :meth:`FleetWorld.cancel`). Step
the robots only through :meth:`FleetWorld.step` (or :meth:`run` / :meth:`run_until`),
never through a member's own ``SimWorld.step``: that would move one robot on its own
clock. Simulated time runs as fast as the CPU allows; a caller paces it if it wants.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.sim.costmap import Costmap
from navseq.sim.footprint import Footprint, footprints_overlap
from navseq.sim.navserver import NavParams
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.profile import SimSettings
from navseq.sim.right_of_way import FleetNavigationServer, RightOfWay
from navseq.sim.world import SimWorld


@dataclass(frozen=True)
class FleetRobot:
    """One robot of a fleet: a unique ``name``, where it starts, and what robot it is."""

    name: str
    start: Pose2D
    profile: RobotProfile = DEFAULT_PROFILE


class FleetWorld:
    """Robots on ``grid`` stepped together every ``dt`` seconds; see the module docstring.

    Pairs of robots are sorted every ``broad_phase_steps`` steps into those near enough
    to touch (only they get the exact collision tests) and those in sight of each other
    (only they can make a server re-plan), with room for what they move meanwhile.

    ``nav_params``, when given, tunes every robot's server (each robot's profile still
    sets its limits and tolerances). ``right_of_way=False`` leaves conflicts to the
    servers alone (they wait for each other and may give up: the comparison the
    benchmark makes). Raises :class:`NavseqError` for two robots of one name, a start in
    an obstacle, or two starts whose footprints overlap.
    """

    broad_phase_steps = 5

    def __init__(
        self,
        grid: OccupancyGrid,
        robots: Sequence[FleetRobot],
        *,
        dt: float = 0.05,
        nav_params: NavParams | None = None,
        right_of_way: bool = True,
    ) -> None:
        if not robots:
            raise NavseqError("a fleet needs at least one robot", source=grid.source)
        names = [robot.name for robot in robots]
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise NavseqError(
                f"robot name(s) {', '.join(repeated)} used more than once", source=grid.source
            )
        self.grid = grid
        self.dt = dt
        self.robots: tuple[FleetRobot, ...] = tuple(robots)
        self.names: tuple[str, ...] = tuple(names)
        self._check_starts()
        costmaps: dict[RobotProfile, Costmap] = {}  # one inflation per robot model
        self._worlds: list[SimWorld] = []
        self.servers: list[FleetNavigationServer] = []  # the worlds' servers, typed as such
        for robot in self.robots:
            settings = SimSettings.of(robot.profile)
            costmap = costmaps.get(robot.profile)
            if costmap is None:
                costmap = costmaps[robot.profile] = Costmap.from_grid(grid, settings.costmap_params)
            params = settings.nav_params
            if nav_params is not None:
                from navseq.sim.profile import nav_params_of

                params = nav_params_of(robot.profile, nav_params)
            server = FleetNavigationServer(costmap, params, settings.footprint)
            world = SimWorld(
                grid,
                robot.start,
                dt=dt,
                costmap=costmap,
                nav_params=params,
                footprint=settings.footprint,
                server=server,
            )
            self._worlds.append(world)
            self.servers.append(server)
        self._by_name = dict(zip(self.names, self._worlds, strict=True))
        self.footprints: tuple[Footprint, ...] = tuple(world.footprint for world in self._worlds)
        self._radii = np.array([fp.circumscribed_radius for fp in self.footprints])
        self._near_reach, self._sight_reach = self._broad_phase_reaches()
        self._neighbours_now: tuple[list[list[int]], list[list[int]]] = ([], [])
        self._neighbours_until = 0  # the step from which they must be sorted again
        self.right_of_way: RightOfWay | None = RightOfWay(self) if right_of_way else None
        self.steps = 0
        self.collisions = 0  # robot pairs found overlapping after a step, summed over steps

    # -- what callers use ------------------------------------------------------------

    @property
    def now(self) -> float:
        """Simulated time (s) since the fleet was made; every robot's world shares it."""
        return self.steps * self.dt

    def world(self, name: str) -> SimWorld:
        """The robot ``name``'s own world: ``.server`` takes its goals, ``.robot`` its pose."""
        try:
            return self._by_name[name]
        except KeyError:
            raise KeyError(f"no robot {name!r} in the fleet ({', '.join(self.names)})") from None

    @property
    def worlds(self) -> tuple[SimWorld, ...]:
        """Every robot's world, in the order of ``robots``."""
        return tuple(self._worlds)

    def set_goal(self, name: str, goal: Pose2D) -> None:
        """Send robot ``name`` to ``goal`` (replacing its goal, as its server does)."""
        self.world(name).server.set_goal(goal)

    def cancel(self, name: str) -> None:
        """Cancel robot ``name``'s goal (it stops; nothing happens when it has none)."""
        self.world(name).server.cancel()

    def poses(self) -> dict[str, Pose2D]:
        """Where every robot is now, by name."""
        return {name: world.robot.pose for name, world in self._by_name.items()}

    def step(self) -> None:
        """Advance every robot by one ``dt``; see the module docstring."""
        if self.right_of_way is not None:
            self.right_of_way.before_step()
        worlds = self._worlds
        footprints = self.footprints
        servers = self.servers
        poses = [world.robot.pose for world in worlds]
        if self.steps >= self._neighbours_until:
            self._neighbours_now = self._neighbours(poses)
            self._neighbours_until = self.steps + self.broad_phase_steps
        near, in_sight = self._neighbours_now
        for index, world in enumerate(worlds):
            world.set_other_robots(
                [
                    (pose, footprint)
                    for other, (pose, footprint) in enumerate(zip(poses, footprints, strict=True))
                    if other != index
                ],
                [(poses[other], footprints[other]) for other in near[index]],
            )
            # Indices among the others, which leave this robot out.
            servers[index].in_sight = [
                other if other < index else other - 1 for other in in_sight[index]
            ]
            world.step()
            poses[index] = world.robot.pose
        self.steps += 1
        self.collisions += self._overlapping_pairs(poses)

    def run(self, seconds: float) -> None:
        """Step for ``seconds`` of simulated time, as fast as the CPU allows."""
        for _ in range(round(seconds / self.dt)):
            self.step()

    def run_until(self, done: Callable[[FleetWorld], bool], limit: float) -> bool:
        """Step until ``done(self)`` is true (True) or ``limit`` simulated seconds have
        passed (False); ``done`` is asked before every step."""
        end = self.steps + round(limit / self.dt)
        while not done(self):
            if self.steps >= end:
                return False
            self.step()
        return True

    def busy(self) -> bool:
        """True while some robot pursues a goal or is giving way to another."""
        from navseq.sim.navserver import NavState

        return any(server.state is NavState.ACTIVE or server.giving_way for server in self.servers)

    # -- internals -------------------------------------------------------------------

    def _check_starts(self) -> None:
        robots = self.robots
        settings = [SimSettings.of(robot.profile) for robot in robots]
        for i, first in enumerate(robots):
            for j in range(i + 1, len(robots)):
                second = robots[j]
                if footprints_overlap(
                    settings[i].footprint, first.start, settings[j].footprint, second.start
                ):
                    raise NavseqError(
                        f"robots {first.name} and {second.name} start overlapping each other",
                        source=self.grid.source,
                    )

    def _broad_phase_reaches(self) -> tuple[np.ndarray, np.ndarray]:
        """Per pair of robots, the distance between centres within which (1) one could
        touch the other, or come within the margin its server keeps, during a step and
        the braking after it, and (2) one may see the other (its server's sight, plus
        what both move in a step)."""
        pads = []
        sights = []
        for server in self.servers:
            limits = server.params.limits
            # Until the pairs are sorted again, each robot moves, and then may brake.
            moves = limits.max_v * self.dt * (self.broad_phase_steps + 1)
            travel = moves + limits.max_v * self.dt + limits.max_v**2 / (2.0 * limits.acc_v)
            pads.append(travel + server.params.robot_margin + 0.05)
            sights.append(server.sensing_range * 1.5 + moves)
        pad = np.array(pads)
        near = self._radii[:, None] + self._radii[None, :] + pad[:, None] + pad[None, :]
        sight = np.array(sights)[:, None] + pad[None, :]
        return near, sight

    def _neighbours(self, poses: list[Pose2D]) -> tuple[list[list[int]], list[list[int]]]:
        """For each robot, the others it may touch this step, and those it may see."""
        count = len(poses)
        if count < 2:
            return [[] for _ in poses], [[] for _ in poses]
        xy = np.array([(pose.x, pose.y) for pose in poses])
        gaps = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
        np.fill_diagonal(gaps, np.inf)
        return self._rows_of(gaps < self._near_reach), self._rows_of(gaps < self._sight_reach)

    @staticmethod
    def _rows_of(pairs: np.ndarray) -> list[list[int]]:
        """Per row of a square boolean matrix, the columns that are True (ascending)."""
        rows: list[list[int]] = [[] for _ in range(len(pairs))]
        for row, col in zip(*(index.tolist() for index in np.nonzero(pairs)), strict=True):
            rows[row].append(col)
        return rows

    def _overlapping_pairs(self, poses: list[Pose2D]) -> int:
        """Pairs of robots whose footprints overlap at ``poses`` (exactly, after a cheap
        test of their circumscribed circles)."""
        if len(poses) < 2:
            return 0
        xy = np.array([(pose.x, pose.y) for pose in poses])
        gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        reach = self._radii[:, None] + self._radii[None, :]
        close_i, close_j = np.nonzero(np.triu(gaps < reach, k=1))
        footprints = self.footprints
        return sum(
            footprints_overlap(footprints[i], poses[i], footprints[j], poses[j])
            for i, j in zip(close_i.tolist(), close_j.tolist(), strict=True)
        )


__all__ = ["FleetRobot", "FleetWorld"]
