"""Right of way between the robots of a :class:`~navseq.sim.fleet_world.FleetWorld`.

Each robot's navigation server already plans around the other robots and waits, at
rest, while only robots block its way (:mod:`navseq.sim.navserver`). Left at that, two
robots that meet head-on in a corridor, or one parked on another's goal, wait for each
other until both give up. :class:`RightOfWay` resolves such conflicts with priorities
and priority inheritance, in the spirit of PIBT (Okumura et al., 2022):

- **Priorities.** A robot pursuing a goal ranks by its place in the fleet (the first
  robot highest); an idle robot ranks below every busy one. A robot giving way *inherits*
  the rank of the robot it gives way to, just below it, so robots in the way of its
  way aside give way in turn.
- **Blocked.** A robot that pursues a goal (or its way aside) and has not moved for
  ``blocked_after`` seconds (or only turned on the spot for ``turning_patience``), or
  whose server waits for a robot, is blocked. Its *route*
  is the plan it follows, or, when the robots leave it no plan, the plan on the bare
  map: where it would go were the others not there.
- **Giving way.** Every lower-ranked robot whose footprint could touch the blocked
  robot's footprint along the stretch of that route within the blocked robot's sight
  (its server's sensing range, plus ``sight_margin``: a robot farther along is not
  what holds it up) gives way: it drives to the nearest
  *refuge* (:func:`find_refuge`: a place out of that route's band and away from the
  other robots, reached without passing through any of them) and holds there. Its goal
  is kept (the server stays ACTIVE; a mission sees nothing but a slower leg); it takes
  it up again once the robot it gave way to has finished or its route has moved away.
  An idle robot gives way the same way, and stays where it went.
- **Inversion.** When a lower-ranked robot in the way has no refuge (it is in a dead
  end), the blocked robot gives way to it instead, if that robot has somewhere to go;
  and when a robot giving way finds the robot it makes way for in its way aside, that
  one steps out of it.
- **Patience.** A blocked robot for which some robot is giving way, or that waits for
  a higher-ranked one, has its server's patience (``blocked_patience``) restarted: the
  fleet is dealing with it. A conflict nobody can resolve still ends ABORTED.
- **Held.** Such a robot, and one giving way, is *held* (``held_reason`` on its server,
  until the next decision finds it no longer so): a mission's executor stops its goal's
  timeout and stall clocks meanwhile (``GoalHeld`` / ``GoalReleased`` from the ``sim``
  navigator), since the wait is the fleet's doing.

The highest-ranked blocked robot always has its way cleared whenever refuges exist,
so it progresses; when it is done the next one is highest. Decisions are taken every
``period`` seconds of simulated time, and cost nothing while no robot is blocked.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

from navseq.geometry import Pose2D
from navseq.sim.costmap import Costmap
from navseq.sim.detour import blocked_stretch, local_detour
from navseq.sim.footprint import TURTLEBOT3_BURGER, Footprint, footprint_cells
from navseq.sim.navserver import NavigationServer, NavParams, NavState
from navseq.sim.planner import Plan

if TYPE_CHECKING:
    from navseq.sim.fleet_world import FleetWorld


class FleetNavigationServer(NavigationServer):
    """A robot's navigation server in a fleet: it can be sent aside without losing its goal.

    :meth:`give_way` drives the robot to a place (with a server of its own, on the same
    costmap, seeing the same robots) while the goal waits: ``state``, ``goal`` and
    ``plan`` stay as they were, and the goal's clocks stand still. :meth:`end_give_way`
    takes the goal up again with a new plan from where the robot is.

    Planning sees the other robots within ``sensing_range`` of this one only, as a robot
    sees them with its sensors (Nav2's local costmap is a few metres across): a robot
    far away will have moved by the time this one gets there, and re-planning around
    all of them, in a fleet of twenty, would cost more than everything else together.
    For the same reason a robot that moves near the plan makes the server re-plan at
    most every ``robot_replan_interval`` seconds, and such a re-plan keeps the plan
    while it is clear of them, or goes round them through a window
    (:mod:`navseq.sim.detour`). The safety test sees every robot the fleet finds near
    enough to touch.
    """

    sensing_range = 3.0  # m from this robot's centre to another's, for planning
    robot_replan_interval = 1.0  # s between re-plans caused by robots moving near the plan
    detour_rejoin = 1.0  # m past the stretch robots block where a detour rejoins the plan
    detour_margin = 2.0  # m round that stretch a detour may use (else: the whole map)

    def __init__(
        self,
        costmap: Costmap,
        params: NavParams | None = None,
        footprint: Footprint = TURTLEBOT3_BURGER,
    ) -> None:
        super().__init__(costmap, params, footprint)
        self._aside: NavigationServer | None = None
        self.aside_target: Pose2D | None = None
        self._at: Pose2D | None = None  # where the robot was at the last step or plan
        self._sensed: list[tuple[int, Pose2D]] = []  # (index, pose) in planning_costmap
        self._robot_came_near = False  # the re-plan now due is for a robot near the plan
        # Which robots the plan went round (their indices): one standing still that came
        # into sight since is news as much as one that moved.
        self._plan_sensed: set[int] = set()
        # Indices into the other robots of those that may be in sight (the fleet's broad
        # phase, every step); None: look at every one.
        self.in_sight: list[int] | None = None

    @property
    def giving_way(self) -> bool:
        """True while the robot is out of its goal's way, letting another robot pass."""
        return self.aside_target is not None

    @property
    def aside_state(self) -> NavState:
        """ACTIVE while driving aside; SUCCEEDED there; ABORTED when it found no way."""
        return self._aside.state if self._aside is not None else NavState.IDLE

    @property
    def waits_for_robot(self) -> bool:
        """True while the goal's server holds still or creeps because of other robots."""
        return self._waiting or (self._blocked_since is not None and self._blocked_by_robot)

    def give_way(self, target: Pose2D) -> None:
        """Drive to ``target`` (any heading) and hold there; the goal waits."""
        if self._aside is None:
            params = dataclasses.replace(self.params, yaw_tolerance=math.pi, xy_tolerance=0.1)
            self._aside = NavigationServer(self.costmap, params, self.footprint)
        self._aside.set_goal(target)
        self.aside_target = target

    def end_give_way(self) -> None:
        """Take the goal up again (re-planned from here), or simply stay when idle."""
        if self._aside is not None:
            self._aside.cancel()
        self.aside_target = None
        if self.state is NavState.ACTIVE and self.goal is not None and not self._follows_given_path:
            self._needs_plan = True
            self._waiting = False
            self._waiting_since = None
            self._blocked_since = None
            self._escape_time_left = 0.0

    def extend_patience(self) -> None:
        """Restart the clocks of waiting for a robot: the fleet is clearing the way."""
        if self._waiting_since is not None:
            self._waiting_since = self._goal_time
        if self._blocked_since is not None and self._blocked_by_robot:
            self._blocked_since = self._goal_time

    def compute_velocity(self, pose: Pose2D, v: float, w: float, dt: float) -> tuple[float, float]:
        self._at = pose
        if self.aside_target is None:
            return super().compute_velocity(pose, v, w, dt)
        aside = self._aside
        assert aside is not None
        aside.set_other_robots(self._others, self._nearby)
        return aside.compute_velocity(pose, v, w, dt)

    def make_plan(self, start: Pose2D, goal: Pose2D) -> Plan | None:
        self._at = start
        return super().make_plan(start, goal)

    def _replan(self, pose: Pose2D) -> bool:
        """A robot came near the plan: keep the plan while it is clear, else go round
        the robots through a window (:mod:`navseq.sim.detour`); otherwise, and for every
        other cause, plan over the whole map."""
        came_near, self._robot_came_near = self._robot_came_near, False
        if (
            came_near
            and self.plan is not None
            and self.goal is not None
            and not (self._needs_plan or self._waiting)
            and self._keep_or_go_round(pose, self.plan, self.goal)
        ):
            self._since_plan = 0.0
            return True
        return super()._replan(pose)

    def _keep_or_go_round(self, pose: Pose2D, plan: Plan, goal: Pose2D) -> bool:
        """True if the plan is kept (still clear of the robots) or replaced by a detour."""
        self._at = pose
        self._refresh_planning_costmap()
        costmap = self.planning_costmap
        rest = plan.points[self.controller.closest_index :]
        blocked = blocked_stretch(costmap, rest)
        if not blocked.any():
            self._plan_others = self._costmap_others
            self._plan_sensed = {index for index, _ in self._sensed}
            return True
        if not costmap.is_free(pose.x, pose.y):
            return False  # hemmed in: the whole-map planner knows where to start from
        detour = local_detour(
            costmap,
            (pose.x, pose.y),
            rest,
            blocked,
            rejoin=self.detour_rejoin,
            margin=self.detour_margin,
        )
        if detour is None:
            return False
        self._needs_plan = False
        self._follow(detour, goal)
        return True

    def _sensed_robots(self) -> list[tuple[int, Pose2D, Footprint]]:
        """The other robots within ``sensing_range`` (all of them before the first step)."""
        at = self._at
        reach = self.sensing_range
        return [
            (index, pose, footprint)
            for index, (pose, footprint) in enumerate(self._others)
            if at is None or math.hypot(pose.x - at.x, pose.y - at.y) <= reach
        ]

    def _refresh_planning_costmap(self) -> None:
        """The map's costmap plus the sensed robots, rebuilt only when they changed."""
        sensed = self._sensed_robots()
        before = self._sensed
        self._costmap_others = [pose for pose, _ in self._others]
        if len(sensed) == len(before) and all(
            index == seen_index and not self._robot_moved(seen, pose, footprint)
            for (index, pose, footprint), (seen_index, seen) in zip(sensed, before, strict=True)
        ):
            return
        self._sensed = [(index, pose) for index, pose, _ in sensed]
        grid = self.costmap.grid
        groups = [footprint_cells(grid, footprint, pose) for _, pose, footprint in sensed]
        costmap = self.costmap.with_obstacle_groups(
            [cells for cells in groups if cells is not None], padding=self.params.robot_margin
        )
        self._use_planning_costmap(costmap)

    def _robot_near_plan(self) -> bool:
        """True if a sensed robot that moved since the plan was made is near its rest."""
        plan, at = self.plan, self._at
        if plan is None or self._since_plan < self.robot_replan_interval:
            return False
        seen = self._plan_others
        reach = self.sensing_range
        others = self._others
        looked_at = range(len(others)) if self.in_sight is None else self.in_sight
        planned_round = self._plan_sensed
        moved: list[tuple[float, float]] = []
        for index in looked_at:
            pose, footprint = others[index]
            if at is not None and abs(pose.x - at.x) + abs(pose.y - at.y) > reach * 1.5:
                continue  # out of sight (a cheap bound on the distance)
            came_into_sight = (
                index not in planned_round
                and at is not None
                and math.hypot(pose.x - at.x, pose.y - at.y) <= reach
            )
            if (
                not came_into_sight
                and index < len(seen)
                and not self._robot_moved(seen[index], pose, footprint)
            ):
                continue
            moved.append((pose.x, pose.y))
        ahead = plan.points[self.controller.closest_index :]
        if not moved or not len(ahead):
            return False
        robots = np.array(moved)
        squared = (ahead[None, :, 0] - robots[:, None, 0]) ** 2 + (
            ahead[None, :, 1] - robots[:, None, 1]
        ) ** 2
        self._robot_came_near = float(squared.min()) < self.params.robot_near_plan**2
        return self._robot_came_near

    def _follow(self, plan: Plan, goal: Pose2D) -> None:
        super()._follow(plan, goal)
        self._plan_sensed = {index for index, _ in self._sensed}

    def _use_costmap(self, costmap: Costmap) -> None:
        super()._use_costmap(costmap)
        self._sensed = []  # force the robots back in at the next plan

    def route(self) -> np.ndarray | None:
        """The rest of the plan the robot follows now (to its goal, or aside), or None."""
        server: NavigationServer = self
        if self.aside_target is not None:
            assert self._aside is not None
            server = self._aside
        if server.state is not NavState.ACTIVE or server.plan is None:
            return None
        return server.plan.points[server.controller.closest_index :]

    def route_on_map(self, pose: Pose2D) -> np.ndarray | None:
        """Where the robot would go from ``pose`` to its target were no robot there."""
        target = self.aside_target if self.aside_target is not None else self.goal
        if target is None:
            return None
        plan = self._plan_on(self.costmap, pose, target)
        return None if plan is None else plan.points


@dataclass
class _Yield:
    """The robot this entry is filed under gives way to robot ``to`` (an index into the
    fleet) since ``since`` (s of fleet time)."""

    to: int
    since: float


@dataclass
class _Watch:
    """When a robot last moved, to tell a blocked robot from a busy one."""

    anchor: Pose2D
    moved_at: float = 0.0
    travelled_at: float = 0.0  # when it last moved 2 cm (turning on the spot is no way on)
    map_route: np.ndarray | None = None  # route on the bare map, while it has no plan
    map_route_at: float = -math.inf


class RightOfWay:
    """Decides, before fleet steps, which robot gives way to which; see the module docstring."""

    period = 0.25  # s of simulated time between two decisions
    blocked_after = 1.0  # s at rest while pursuing a target: blocked
    turning_patience = 5.0  # s turning on the spot, getting nowhere: blocked too
    # m beyond touching circumscribed circles within which a robot is in a route's way:
    # the planner keeps the robot's own radius from another robot's footprint grown by
    # ``robot_margin``, measured from cell edges, so a robot that near still blocks plans.
    way_margin = 0.3
    refuge_margin = 0.1  # m more that a refuge keeps, so that it is out of the way for good
    yield_limit = 90.0  # s a robot gives way before it takes its goal up again anyway
    # m beyond a blocked robot's sensing range within which its route's points count for
    # who is in its way: a robot its server sees blocks route points this near it
    sight_margin = 1.0
    # s after robot A was sent aside for robot B during which A does not send B aside,
    # nor B make way for A, in turn: two robots almost touching would otherwise send each
    # other aside at every decision, each new way aside replacing the last before either
    # moved (a livelock). A waits for B to move instead.
    return_guard = 10.0

    def __init__(self, fleet: FleetWorld) -> None:
        self.fleet = fleet
        self._watch = [_Watch(world.robot.pose) for world in fleet.worlds]
        self._yields: dict[int, _Yield] = {}
        self._sent: dict[tuple[int, int], float] = {}  # (index, for whom) -> when sent aside
        self._next = 0.0
        self.yields_started = 0  # how often a robot was sent aside (benchmarks, tests)

    def before_step(self) -> None:
        """Every ``period``: end the giving way that is over, start what is needed."""
        now = self.fleet.now
        if now + 1e-9 < self._next:
            return
        self._next = now + self.period
        poses = [world.robot.pose for world in self.fleet.worlds]
        self._note_motion(poses, now)
        self._end_yields(poses, now)
        self._mark_held(self._resolve(poses, now))

    def _mark_held(self, waiting: dict[int, int]) -> None:
        """Say on each server whether the fleet holds its robot back, and for whom:
        giving way, or waiting (``waiting``: index -> the robot it waits on)."""
        names = self.fleet.names
        for index, server in enumerate(self.fleet.servers):
            if index in self._yields:
                server.held_reason = f"giving way to {names[self._yields[index].to]}"
            elif index in waiting:
                server.held_reason = f"waiting for {names[waiting[index]]}"
            else:
                server.held_reason = None

    # -- state -----------------------------------------------------------------------

    def _note_motion(self, poses: list[Pose2D], now: float) -> None:
        for watch, pose in zip(self._watch, poses, strict=True):
            anchor = watch.anchor
            travelled = math.hypot(pose.x - anchor.x, pose.y - anchor.y) > 0.02
            if travelled or abs(math.remainder(pose.yaw - anchor.yaw, math.tau)) > 0.05:
                watch.anchor = pose
                watch.moved_at = now
            if travelled:
                watch.travelled_at = now

    def _pursuing(self, index: int) -> bool:
        server = self.fleet.servers[index]
        if server.giving_way:
            return server.aside_state is NavState.ACTIVE
        return server.state is NavState.ACTIVE

    def _busy(self, index: int) -> bool:
        """Pursuing its goal, or giving way (whose rank it carries)."""
        server = self.fleet.servers[index]
        return server.giving_way or server.state is NavState.ACTIVE

    def _rank(self, index: int) -> tuple[int, int]:
        """Sort key, smaller first: (rank inherited along giving way, depth of inheritance)."""
        depth = 0
        seen = {index}
        while index in self._yields:
            index = self._yields[index].to
            depth += 1
            if index in seen:  # a cycle, which only inversions could make: stop there
                break
            seen.add(index)
        if self._busy(index):
            return index, depth
        return len(self._watch) + index, depth

    def _blocked(self, index: int, now: float) -> bool:
        if not self._pursuing(index):
            return False
        server = self.fleet.servers[index]
        watch = self._watch[index]
        at_rest = now - watch.moved_at >= self.blocked_after or (
            now - watch.travelled_at >= self.turning_patience
        )
        return at_rest or (not server.giving_way and server.waits_for_robot)

    def _route(self, index: int, pose: Pose2D, now: float) -> np.ndarray | None:
        """Where robot ``index`` wants to go: its plan, or the bare map's plan without one."""
        server = self.fleet.servers[index]
        route = server.route()
        if route is not None and not server.waits_for_robot:
            return route
        watch = self._watch[index]
        if watch.map_route is None or now - watch.map_route_at > 2.0:
            watch.map_route = server.route_on_map(pose)
            watch.map_route_at = now
        return watch.map_route if watch.map_route is not None else route

    # -- decisions -------------------------------------------------------------------

    def _end_yields(self, poses: list[Pose2D], now: float) -> None:
        servers = self.fleet.servers
        for index, yielding in list(self._yields.items()):
            server = servers[index]
            over = (
                not server.giving_way
                or not self._pursuing(yielding.to)
                or now - yielding.since > self.yield_limit
                or server.aside_state is NavState.ABORTED
            )
            if not over and server.aside_state is not NavState.ACTIVE:
                route = self._route(yielding.to, poses[yielding.to], now)
                over = route is None or not self._in_band(index, yielding.to, route, poses)
            if over:
                del self._yields[index]
                if server.giving_way:
                    server.end_give_way()

    def _resolve(self, poses: list[Pose2D], now: float) -> dict[int, int]:
        """Start the giving way that is needed; returns the blocked robots the fleet is
        dealing with (index -> the robot it waits on, or that gives way for it)."""
        waiting: dict[int, int] = {}
        count = len(poses)
        blocked = sorted(
            (index for index in range(count) if self._blocked(index, now)), key=self._rank
        )
        servers = self.fleet.servers
        for index in blocked:
            if not self._blocked(index, now):
                continue  # sent aside earlier in this round
            route = self._route(index, poses[index], now)
            if route is None:
                continue
            rank = self._rank(index)
            ahead = self._stretch_in_reach(index, route, poses[index])
            in_way = [
                other
                for other in range(count)
                if other != index and self._in_band(other, index, ahead, poses)
            ]
            helped: int | None = None  # the first robot the fleet deals with for it
            giving_way_to = self._yields[index].to if index in self._yields else None
            for other in sorted(in_way, key=self._rank):
                if self._sent_for_lately(index, other, now):
                    # Sent aside for ``other`` a moment ago: it does not send ``other``
                    # aside in turn, it waits for it to move (see ``return_guard``).
                    helped = other if helped is None else helped
                    continue
                if other == giving_way_to:
                    # The robot this one makes way for blocks its way aside: it steps
                    # out of that way instead (a cycle of giving way, which ends as
                    # soon as either is through).
                    if self._send_aside(other, index, route, poses, now) and helped is None:
                        helped = other
                    continue
                if self._rank(other) < rank:
                    helped = other if helped is None else helped  # higher-ranked: wait
                    continue
                if other in self._yields and self._yields[other].to == index:
                    helped = other if helped is None else helped  # already on its way aside
                    continue
                if self._send_aside(other, index, route, poses, now):
                    helped = other if helped is None else helped
                elif self._pursuing(other) and not self._sent_for_lately(other, index, now):
                    # Inversion: the robot in the way cannot get out of it; make way for it.
                    other_route = self._route(other, poses[other], now)
                    if other_route is not None and self._send_aside(
                        index, other, other_route, poses, now
                    ):
                        helped = other if helped is None else helped
                        break
            if helped is not None:
                servers[index].extend_patience()
                waiting[index] = helped
        return waiting

    def _sent_for_lately(self, index: int, other: int, now: float) -> bool:
        """True if robot ``index`` was sent aside for ``other`` less than
        ``return_guard`` seconds ago."""
        return now - self._sent.get((index, other), -math.inf) < self.return_guard

    def _stretch_in_reach(self, index: int, route: np.ndarray, pose: Pose2D) -> np.ndarray:
        """The points of robot ``index``'s ``route`` that robots blocking it now can be on.

        Its server sees (plans around, waits for) the robots within its sensing range
        only, so a robot farther along the route is not what holds it up: sending that
        one aside now would be a needless move, made again, if at all, when the robot
        gets there. A robot giving way plans around every robot: its whole (short)
        route counts.
        """
        server = self.fleet.servers[index]
        if server.giving_way:
            return route
        reach = server.sensing_range + self.sight_margin
        squared = (route[:, 0] - pose.x) ** 2 + (route[:, 1] - pose.y) ** 2
        return route[squared <= reach * reach]

    def _send_aside(
        self, index: int, to: int, route: np.ndarray, poses: list[Pose2D], now: float
    ) -> bool:
        """Send robot ``index`` to a refuge off ``route`` (robot ``to``'s); False if none."""
        fleet = self.fleet
        targets = [
            fleet.servers[other].aside_target
            for other in self._yields
            if other != index and fleet.servers[other].aside_target is not None
        ]
        others = [
            (pose, fleet.footprints[other].circumscribed_radius)
            for other, pose in enumerate(poses)
            if other != index
        ]
        others += [
            (target, fleet.footprints[index].circumscribed_radius)
            for target in targets
            if target is not None
        ]
        server = fleet.servers[index]
        refuge = find_refuge(
            server.costmap,
            poses[index],
            fleet.footprints[index].circumscribed_radius,
            route,
            self._way(index, to) + self.refuge_margin,
            others,
        )
        if refuge is None:
            return False
        server.give_way(refuge)
        self._yields[index] = _Yield(to, now)
        self._sent[(index, to)] = now
        self.yields_started += 1
        return True

    def _way(self, index: int, of: int) -> float:
        return way_reach(self.fleet.footprints, index, of, self.way_margin)

    def _in_band(self, index: int, of: int, route: np.ndarray, poses: list[Pose2D]) -> bool:
        return in_band(poses[index], route, self._way(index, of))


def way_reach(footprints: Sequence[Footprint], index: int, of: int, margin: float) -> float:
    """How near robot ``index``'s centre to a point of robot ``of``'s route blocks it."""
    return footprints[index].circumscribed_radius + footprints[of].circumscribed_radius + margin


def in_band(pose: Pose2D, route: np.ndarray, reach: float) -> bool:
    """True if a robot at ``pose`` is within ``reach`` of some point of ``route``."""
    squared = (route[:, 0] - pose.x) ** 2 + (route[:, 1] - pose.y) ** 2
    return bool(squared.size) and float(squared.min()) < reach * reach


def find_refuge(
    costmap: Costmap,
    start: Pose2D,
    radius: float,
    route: np.ndarray,
    band: float,
    others: list[tuple[Pose2D, float]],
    *,
    search: float = 8.0,
) -> Pose2D | None:
    """The nearest place (along the free cells) where a robot of circumscribed ``radius``
    at ``start`` is more than ``band`` from every point of ``route`` and clear of the
    ``others`` (centres and circumscribed radii), reached without passing closer to any
    of them than it is now; None within ``search`` metres. Faces as the robot does."""
    grid = costmap.grid
    resolution = grid.resolution
    row, col = grid.world_to_cell(start.x, start.y)
    reach = math.ceil(search / resolution)
    height, width = costmap.cost.shape
    top, bottom = max(row - reach, 0), min(row + reach + 1, height)
    left, right = max(col - reach, 0), min(col + reach + 1, width)
    free = np.array(costmap.free_mask()[top:bottom, left:right], dtype=bool)
    rows, cols = np.mgrid[top:bottom, left:right]
    centres = grid.cells_to_world(rows.ravel(), cols.ravel())
    cell_x = centres[:, 0].reshape(free.shape)
    cell_y = centres[:, 1].reshape(free.shape)
    passable = free.copy()
    settled = free.copy()
    for at, other_radius in others:
        gap = np.hypot(cell_x - at.x, cell_y - at.y)
        touching = radius + other_radius + 0.05
        now_gap = math.hypot(start.x - at.x, start.y - at.y)
        passable &= gap >= min(touching, now_gap - resolution)
        settled &= gap >= touching + 0.1
    marked = np.zeros(free.shape, dtype=bool)
    route_rows, route_cols = grid.world_to_cells(route[:, 0], route[:, 1])
    inside = (
        (route_rows >= top) & (route_rows < bottom) & (route_cols >= left) & (route_cols < right)
    )
    marked[route_rows[inside] - top, route_cols[inside] - left] = True
    if marked.any():
        distance = ndimage.distance_transform_edt(~marked) * resolution
        settled &= distance > band
    start_cell = (row - top, col - left)
    if not (0 <= start_cell[0] < free.shape[0] and 0 <= start_cell[1] < free.shape[1]):
        return None
    passable[start_cell] = True
    seen = np.zeros(free.shape, dtype=bool)
    seen[start_cell] = True
    queue = deque([start_cell])
    shape = free.shape
    steps = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1))
    while queue:
        r, c = queue.popleft()
        if settled[r, c]:
            x, y = grid.cell_to_world(r + top, c + left)
            return Pose2D(x, y, start.yaw)
        for dr, dc in steps:
            nr, nc = r + dr, c + dc
            if 0 <= nr < shape[0] and 0 <= nc < shape[1] and passable[nr, nc] and not seen[nr, nc]:
                seen[nr, nc] = True
                queue.append((nr, nc))
    return None


__all__ = ["FleetNavigationServer", "RightOfWay", "find_refuge"]
