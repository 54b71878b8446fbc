"""Right of way for a fleet on ROS navigation stacks, decided in navseq, not in the stacks.

On the embedded simulator the fleet's navigation servers give way to each other
(:mod:`navseq.sim.right_of_way`). A robot on its own Nav2 or move_base stack has no such
rule: two robots that meet head-on in a corridor both wait until their stacks give up
(ABORTED), and a robot parked on another's goal stays there. The
:class:`FleetCoordinator` watches every robot through its navigator — its pose, the
goal its mission has out — and steps in before the stacks' own blocked / abort logic
fires, with the simulator's rule where it makes sense (PIBT-style priorities with
inheritance; :func:`navseq.sim.right_of_way.find_refuge` for the place to go):

- **Priorities.** A robot pursuing a goal ranks by its place in the fleet (the first
  robot highest); an idle robot (no goal: its share done, or none) ranks below every
  busy one; a robot giving way inherits the rank of the robot it makes way for.
- **Blocked.** A robot that pursues a goal and has not moved for ``blocked_after``
  seconds (or only turned on the spot for ``turning_patience``) is blocked. Its
  *route* is the plan on the bare map (the fleet's map, its own footprint): where it
  would go were the other robots not there.
- **Sent aside.** Every lower-ranked robot near that route drives to the nearest
  refuge (off the route, clear of the others, reached without passing through any of
  them) and holds there; its mission's goal waits (the executor sees a slower leg)
  and is sent again once the robot it made way for has finished or gone past.
- **Held back.** While a robot is being sent out of its way, the blocked robot's goal
  is cancelled on its stack and held (the robot stands still, its stack has nothing to
  give up on), then sent again once the way is clear. A new goal whose pose an idle
  robot stands on is held the same way while that robot moves aside, before the stack
  plans to a goal it cannot reach.
- **Inversion.** A robot in the way that has no refuge (a dead end) makes the blocked
  robot give way to it instead, if that one has somewhere to go.

It is ROS-free: it sees the robots only through :class:`CoordinatedNavigator`, the
wrapper each robot's navigator is put in (the executor's goals pass through it; the
coordinator's goals aside never reach the executor). Decisions are taken every
``period`` seconds of the fleet's clock (the first robot's navigator time), in a
thread of its own (:meth:`FleetCoordinator.start`).
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from navseq.geometry import Pose2D
from navseq.mission.robot import RobotProfile
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalHeld,
    GoalOutcome,
    GoalReleased,
    NavEvent,
    Navigator,
)
from navseq.sim.costmap import Costmap
from navseq.sim.footprint import Footprint, footprints_overlap
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.right_of_way import in_band, way_reach


class Mode:
    """What the coordinator is doing with a robot (a :class:`CoordinatedNavigator`)."""

    FREE = "free"  # the mission's goals go to the stack as they come
    HELD = "held"  # standing still: the mission's goal waits, off the stack
    ASIDE = "aside"  # driving to (or holding at) a refuge; the mission's goal waits


class CoordinatedNavigator:
    """A robot's navigator as the executor and the coordinator share it.

    The executor's calls pass through while the robot is free. The coordinator may
    :meth:`hold` the robot (its goal is cancelled on the stack but stays the mission's)
    or send it :meth:`aside` (a goal of the coordinator's, whose events the executor
    never sees), and :meth:`release` it (the mission's goal is sent again, same id).
    A goal the executor sends meanwhile waits until then. While held or aside, the
    executor hears ``GoalHeld`` about its goal, and ``GoalReleased`` after: the wait is
    the fleet's doing, so its goal's timeout and stall clocks stand still. Every other
    attribute (ROS tasks, recoveries, recording taps) is the wrapped navigator's.
    """

    def __init__(self, inner: Navigator, name: str) -> None:
        self.inner = inner
        self.name = name
        self._lock = threading.RLock()
        self._goal: Goal | None = None  # the mission's goal out, as the executor sees it
        self._accepted: set[int] = set()
        self._aside_ids = 0
        self._aside_id: int | None = None
        self.mode = Mode.FREE
        self.aside_target: Pose2D | None = None
        self.aside_driving = False  # the way aside is being driven (not there, not failed)
        self.aside_failed = False
        self.goal_changed = 0  # counts goals sent to the stack, for the coordinator's watch
        self._news: list[NavEvent] = []  # GoalHeld / GoalReleased for the executor
        self._held_goal: int | None = None  # the mission's goal the executor knows is held
        self._held_reason = ""
        self.trajectory: list[tuple[float, float, float]] = []  # (t, x, y), for the picture

    def __getattr__(self, name: str) -> Any:
        # Only reached for what this class lacks: the wrapped navigator's extras.
        inner = self.__dict__.get("inner")
        if inner is None:
            raise AttributeError(name)
        return getattr(inner, name)

    # -- the Navigator interface (the executor's thread) --------------------------------

    def now(self) -> float:
        return self.inner.now()

    def wait_for_server(self, timeout: float) -> bool:
        return self.inner.wait_for_server(timeout)

    def send_goal(self, goal: Goal) -> None:
        with self._lock:
            self._goal = goal
            self._accepted.discard(goal.goal_id)
            if self.mode == Mode.FREE:
                self._to_stack(goal)
            else:
                self._tell_held()  # a new goal while held: it waits too

    def cancel_goal(self) -> None:
        with self._lock:
            self._goal = None
            if self.mode == Mode.FREE:
                self.inner.cancel_goal()
            # Held: nothing is out. Aside: the way aside goes on; the robot stays there.

    def clear_costmaps(self) -> None:
        with self._lock:
            self.inner.clear_costmaps()

    def robot_pose(self) -> Pose2D | None:
        with self._lock:
            return self.inner.robot_pose()

    def odometry_pose(self) -> Pose2D | None:
        with self._lock:
            return self.inner.odometry_pose()

    def poll(self) -> list[NavEvent]:
        with self._lock:
            news, self._news = self._news, []
            return news + [event for event in self.inner.poll() if self._passes(event)]

    def spin(self, seconds: float) -> None:
        self.inner.spin(seconds)

    def close(self) -> None:
        """The run's end: the mission's goal is given up (the owner closes the stack)."""
        self.cancel_goal()

    # -- the coordinator's side -------------------------------------------------------

    @property
    def goal(self) -> Goal | None:
        """The mission's goal the executor has out (held or not), or None."""
        return self._goal

    @property
    def pursuing(self) -> bool:
        """Driving somewhere: the mission's goal on the stack, or the way aside."""
        return (self.mode == Mode.FREE and self._goal is not None) or (
            self.mode == Mode.ASIDE and self.aside_driving
        )

    @property
    def busy(self) -> bool:
        """Has somewhere to go, now or once the coordinator lets it."""
        return self._goal is not None or (self.mode == Mode.ASIDE and self.aside_driving)

    def target(self) -> Pose2D | None:
        """Where the robot is driving: the refuge while aside, else the mission's goal."""
        if self.mode == Mode.ASIDE:
            return self.aside_target
        return self._goal.pose if self._goal is not None else None

    def hold(self, reason: str = "") -> None:
        """Stand still: the mission's goal off the stack (a way aside ends where the
        robot is), kept for :meth:`release`. ``reason``: for whom, for the executor."""
        with self._lock:
            self._held_reason = reason
            if (self.mode == Mode.FREE and self._goal is not None) or (
                self.mode == Mode.ASIDE and self.aside_driving
            ):
                self.inner.cancel_goal()
            self.mode = Mode.HELD
            self.aside_target, self._aside_id = None, None
            self.aside_driving = False
            self._tell_held()

    def aside(self, target: Pose2D, reason: str = "") -> None:
        """Drive to ``target`` and stay there; the mission's goal waits."""
        with self._lock:
            self._held_reason = reason
            self._aside_ids -= 1  # the executor's ids are positive: these never clash
            self._aside_id = self._aside_ids
            frame = self._goal.frame if self._goal is not None else "map"
            self.mode = Mode.ASIDE
            self.aside_target = target
            self.aside_driving, self.aside_failed = True, False
            self.goal_changed += 1
            self.inner.send_goal(Goal(self._aside_id, target, frame=frame))
            self._tell_held()

    def release(self) -> None:
        """Back to the mission: its goal (if one is out) is sent again."""
        with self._lock:
            if self.mode == Mode.FREE:
                return
            driving = self.mode == Mode.ASIDE and self.aside_driving
            self.mode = Mode.FREE
            self.aside_target, self._aside_id = None, None
            self.aside_driving = False
            if self._held_goal is not None:
                self._news.append(GoalReleased(self._held_goal))
                self._held_goal = None
            if self._goal is not None:
                self._to_stack(self._goal)
            elif driving:
                self.inner.cancel_goal()

    def _tell_held(self) -> None:
        """The executor hears once that its goal out is held (aside counts as held)."""
        goal = self._goal
        if goal is not None and self._held_goal != goal.goal_id:
            self._held_goal = goal.goal_id
            self._news.append(GoalHeld(goal.goal_id, self._held_reason))

    def _to_stack(self, goal: Goal) -> None:
        self.goal_changed += 1
        self.inner.send_goal(goal)

    def _passes(self, event: NavEvent) -> bool:
        """Whether the executor sees ``event``; the way aside's end is noted here."""
        goal_id = getattr(event, "goal_id", None)
        if goal_id is None:
            return True  # server lost / back, a recovery's end: the mission's business
        if goal_id < 0:
            if isinstance(event, GoalDone) and goal_id == self._aside_id:
                self.aside_driving = False
                self.aside_failed = event.outcome is not GoalOutcome.SUCCEEDED
            return False
        goal = self._goal
        if goal is None or goal_id != goal.goal_id:
            return True  # an older goal's late word: the executor ignores it itself
        if self.mode != Mode.FREE:
            return False  # the held goal's cancel, its stale feedback
        if isinstance(event, GoalAccepted):
            if goal_id in self._accepted:
                return False  # sent again after a hold: accepted once is enough
            self._accepted.add(goal_id)
        elif isinstance(event, GoalDone):
            self._goal = None  # the mission's goal is over: the robot is idle until the next
        return True


@dataclass
class _Watch:
    """When a robot last moved, and its route on the bare map while it is wanted."""

    anchor: Pose2D | None = None
    moved_at: float = 0.0
    travelled_at: float = 0.0
    goal_seen: int = -1  # CoordinatedNavigator.goal_changed when last looked at
    route: np.ndarray | None = None
    route_for: tuple[float, float] | None = None
    route_at: float = -math.inf


@dataclass
class _Yield:
    """Robot ``to`` (an index) is the one this robot makes way for, since ``since``."""

    to: int
    since: float


@dataclass
class _Hold:
    """This robot waits while robot ``for_`` gets out of its way, since ``since``."""

    for_: int
    since: float


@dataclass(frozen=True)
class CoordinatedRobot:
    """One robot for the coordinator: its name, navigator and model."""

    name: str
    navigator: CoordinatedNavigator
    profile: RobotProfile


class FleetCoordinator:
    """Watches a fleet's robots and gives way among them; see the module docstring.

    Also what a fleet run's display and report read: :attr:`now` (seconds since the
    run began, on the fleet's clock), :attr:`collisions` (robot pairs seen with
    overlapping footprints at a look, summed), :attr:`stepped` (set after each look).
    """

    period = 0.25  # s of fleet time between two looks
    blocked_after = 1.0  # s at rest while pursuing a goal: blocked
    turning_patience = 5.0  # s turning on the spot, getting nowhere: blocked too
    way_margin = 0.3  # m beyond touching circumscribed circles: in a route's way
    refuge_margin = 0.1  # m more that a refuge keeps
    yield_limit = 90.0  # s a robot gives way before it takes its goal up again anyway
    hold_limit = 30.0  # s a robot is held back at most for one robot's way aside
    route_age = 2.0  # s before a robot's route on the bare map is planned again
    # s after robot A was sent aside for robot B during which A does not send B aside,
    # nor make B make way for it, in turn (the rule's ``return_guard``: two robots almost
    # touching would send each other aside for ever).
    return_guard = 10.0

    def __init__(
        self,
        grid: OccupancyGrid,
        robots: Sequence[CoordinatedRobot],
        *,
        clock: Callable[[], float] | None = None,
    ) -> None:
        from navseq.sim.profile import SimSettings

        self.robots = tuple(robots)
        self.names = tuple(robot.name for robot in robots)
        costmaps: dict[RobotProfile, Costmap] = {}
        self._footprints: list[Footprint] = []
        self._costmaps: list[Costmap] = []
        for robot in robots:
            settings = SimSettings.of(robot.profile)
            costmap = costmaps.get(robot.profile)
            if costmap is None:
                costmap = costmaps[robot.profile] = Costmap.from_grid(grid, settings.costmap_params)
            self._costmaps.append(costmap)
            self._footprints.append(settings.footprint)
        self._clock = clock or (robots[0].navigator.now if robots else time.monotonic)
        self._origin: float | None = None
        self._watch = [_Watch() for _ in robots]
        self._yields: dict[int, _Yield] = {}
        self._holds: dict[int, _Hold] = {}
        self._sent: dict[tuple[int, int], float] = {}  # (index, for whom) -> when sent aside
        self._next = -math.inf
        self._running: set[str] = set()  # robots whose mission's thread polls their navigator
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.stepped = threading.Event()
        self.collisions = 0
        self.sent_aside = 0  # how often a robot was sent aside
        self.held_back = 0  # how often a robot was held back
        self.now = 0.0
        self.error: BaseException | None = None
        #: The latest decisions, ``(t, text)``, for the fleet report (bounded).
        self.decisions: deque[tuple[float, str]] = deque(maxlen=200)

    # -- the fleet run's side ----------------------------------------------------------

    def follow(self, running: Sequence[str]) -> None:
        """``running`` names the robots whose runs poll their own navigators (the
        coordinator polls the others', to hear their ways aside end)."""
        self._running = set(running)

    def start(self, running: Sequence[str], threads: Sequence[threading.Thread]) -> None:
        """Look every ``period`` while any of ``threads`` (the robots' runs) is alive;
        ``running`` as for :meth:`follow`."""
        self.follow(running)

        def loop() -> None:
            try:
                while not self._stop.is_set() and any(t.is_alive() for t in threads):
                    self.look()
                    self._stop.wait(0.05)
            except BaseException as error:  # said by the face; the runs go on uncoordinated
                self.error = error
            finally:
                self.stepped.set()

        self._thread = threading.Thread(target=loop, name="fleet-coordinator", daemon=True)
        self._thread.start()

    def leave(self, name: str) -> None:
        """Robot ``name``'s run has ended: from now on the coordinator polls its navigator."""
        self._running.discard(name)

    def close(self) -> None:
        """Stop looking; every robot still aside or held is released (stands still)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        for robot in self.robots:
            navigator = robot.navigator
            if navigator.mode == Mode.ASIDE and navigator.aside_driving:
                navigator.inner.cancel_goal()

    def summary(self) -> dict[str, object]:
        """For the fleet report (``error``: why it stopped looking, when it did)."""
        summary: dict[str, object] = {"sent_aside": self.sent_aside, "held_back": self.held_back}
        if self.error is not None:
            summary["error"] = f"{type(self.error).__name__}: {self.error}"
        summary["decisions"] = [f"{t:.1f} s: {text}" for t, text in self.decisions]
        return summary

    def _say(self, text: str) -> None:
        self.decisions.append((self.now, text))

    # -- one look ------------------------------------------------------------------------

    def look(self) -> None:
        """Every ``period`` of fleet time: note where the robots are, end what is over,
        start what is needed."""
        clock = self._clock()
        if self._origin is None:
            self._origin = clock
        now = self.now = clock - self._origin
        if now + 1e-9 < self._next:
            return
        self._next = now + self.period
        for robot in self.robots:
            if robot.name not in self._running:
                robot.navigator.poll()  # its run is over (or never was): its aside's end
        poses = [robot.navigator.robot_pose() for robot in self.robots]
        if any(pose is None for pose in poses):
            self.stepped.set()
            return  # a robot not seen yet: no decision on half the fleet
        seen = [pose for pose in poses if pose is not None]
        self._note_motion(seen, now)
        self._count_overlaps(seen)
        self._end_yields(seen, now)
        self._end_holds(seen, now)
        self._clear_goals(seen, now)
        self._resolve(seen, now)
        self.stepped.set()

    def _nav(self, index: int) -> CoordinatedNavigator:
        return self.robots[index].navigator

    def _note_motion(self, poses: list[Pose2D], now: float) -> None:
        for index, (watch, pose) in enumerate(zip(self._watch, poses, strict=True)):
            navigator = self._nav(index)
            if watch.goal_seen != navigator.goal_changed:  # a goal just sent: not at rest
                watch.goal_seen = navigator.goal_changed
                watch.moved_at = watch.travelled_at = now
            anchor = watch.anchor
            if anchor is None:
                watch.anchor = pose
                watch.moved_at = watch.travelled_at = now
                navigator.trajectory.append((now, pose.x, pose.y))
                continue
            travelled = math.hypot(pose.x - anchor.x, pose.y - anchor.y) > 0.02
            if travelled or abs(math.remainder(pose.yaw - anchor.yaw, math.tau)) > 0.05:
                watch.anchor = pose
                watch.moved_at = now
            if travelled:
                watch.travelled_at = now
                navigator.trajectory.append((now, pose.x, pose.y))

    def _count_overlaps(self, poses: list[Pose2D]) -> None:
        footprints = self._footprints
        for a in range(len(poses)):
            for b in range(a + 1, len(poses)):
                if footprints_overlap(footprints[a], poses[a], footprints[b], poses[b]):
                    self.collisions += 1

    def _rank(self, index: int) -> tuple[int, int]:
        """Sort key, smaller first: (rank inherited along giving way, depth)."""
        depth = 0
        seen = {index}
        while index in self._yields:
            index = self._yields[index].to
            depth += 1
            if index in seen:
                break
            seen.add(index)
        if self._nav(index).busy:
            return index, depth
        return len(self.robots) + index, depth

    def _blocked(self, index: int, now: float) -> bool:
        if not self._nav(index).pursuing:
            return False
        watch = self._watch[index]
        return (
            now - watch.moved_at >= self.blocked_after
            or now - watch.travelled_at >= self.turning_patience
        )

    def _route(self, index: int, pose: Pose2D, now: float) -> np.ndarray | None:
        """Where robot ``index`` wants to go, planned on the bare map (kept a while)."""
        from navseq.sim.planner import plan_path

        target = self._nav(index).target()
        if target is None:
            return None
        watch = self._watch[index]
        key = (target.x, target.y)
        if watch.route is None or watch.route_for != key or now - watch.route_at > self.route_age:
            plan = plan_path(self._costmaps[index], (pose.x, pose.y), key)
            # No plan from where it stands (too near a wall to turn): the straight line.
            watch.route = (
                plan.points if plan is not None else np.array([[pose.x, pose.y], [*key]], float)
            )
            watch.route_for, watch.route_at = key, now
        return watch.route

    def _way(self, index: int, of: int) -> float:
        return way_reach(self._footprints, index, of, self.way_margin)

    def _in_band(self, index: int, of: int, route: np.ndarray, poses: list[Pose2D]) -> bool:
        return in_band(poses[index], route, self._way(index, of))

    # -- decisions -----------------------------------------------------------------------

    def _end_yields(self, poses: list[Pose2D], now: float) -> None:
        for index, yielding in list(self._yields.items()):
            navigator = self._nav(index)
            other = self._nav(yielding.to)
            over = (
                navigator.mode != Mode.ASIDE
                or not other.busy
                or now - yielding.since > self.yield_limit
                or navigator.aside_failed
            )
            if not over and not navigator.aside_driving and other.mode == Mode.FREE:
                route = self._route(yielding.to, poses[yielding.to], now)
                over = route is None or not self._in_band(index, yielding.to, route, poses)
            if over:
                del self._yields[index]
                if navigator.goal is None:
                    navigator.release()  # an idle robot stays where it went, free again
                    continue
                self._watch[index].route = None
                if other.busy and now - yielding.since <= self.yield_limit:
                    mine = self._route(index, poses[index], now)
                    if mine is not None and self._in_band(yielding.to, index, mine, poses):
                        # Its own way runs where the other robot still goes: it waits
                        # here, its goal off the stack, rather than for the stack to give up.
                        navigator.hold(f"waiting aside for {self.names[yielding.to]}")
                        self._holds[index] = _Hold(yielding.to, now)
                        self._say(f"{self.names[index]} waits aside for {self.names[yielding.to]}")
                        continue
                navigator.release()
                self._say(f"{self.names[index]} back on its way")

    def _end_holds(self, poses: list[Pose2D], now: float) -> None:
        for index, held in list(self._holds.items()):
            navigator = self._nav(index)
            other = self._nav(held.for_)
            route = self._route(index, poses[index], now) if navigator.goal is not None else None
            # Clear once the other robot is out of the way: gone past, done, or at the
            # refuge it was sent to.
            clear = (
                navigator.mode != Mode.HELD
                or navigator.goal is None
                or now - held.since > self.hold_limit
                or route is None
                or not self._in_band(held.for_, index, route, poses)
                or not other.busy
                or (other.mode == Mode.ASIDE and not other.aside_driving)
            )
            if clear:
                del self._holds[index]
                navigator.release()
                self._say(f"{self.names[index]} released")

    def _hold(self, index: int, for_: int, now: float) -> None:
        """Robot ``index`` waits, its goal off the stack, while ``for_`` clears its way."""
        navigator = self._nav(index)
        if navigator.mode == Mode.FREE and navigator.goal is not None:
            navigator.hold(f"held back for {self.names[for_]}")
            self._holds[index] = _Hold(for_, now)
            self.held_back += 1
            self._say(f"{self.names[index]} held back for {self.names[for_]}")
            self._watch[index].moved_at = self._watch[index].travelled_at = now

    def _clear_goals(self, poses: list[Pose2D], now: float) -> None:
        """A goal whose pose a standing robot (idle, or held back) is on: that one moves
        aside first. A stack plans to the nearest free place instead of a goal another
        robot covers, and says SUCCEEDED there, short of the goal."""
        for index in range(len(poses)):
            navigator = self._nav(index)
            goal = navigator.goal
            if goal is None or navigator.mode != Mode.FREE:
                continue
            end = np.array([[goal.pose.x, goal.pose.y]])
            for other in range(len(poses)):
                if other == index or self._nav(other).pursuing or other in self._yields:
                    continue
                if self._in_band(other, index, end, poses):
                    route = self._route(index, poses[index], now)
                    if route is not None and self._send_aside(other, index, route, poses, now):
                        self._hold(index, other, now)

    def _resolve(self, poses: list[Pose2D], now: float) -> None:
        count = len(poses)
        blocked = sorted(
            (index for index in range(count) if self._blocked(index, now)), key=self._rank
        )
        for index in blocked:
            if not self._blocked(index, now):
                continue  # sent aside earlier in this look
            route = self._route(index, poses[index], now)
            if route is None:
                continue
            rank = self._rank(index)
            in_way = [
                other
                for other in range(count)
                if other != index and self._in_band(other, index, route, poses)
            ]
            giving_way_to = self._yields[index].to if index in self._yields else None
            for other in sorted(in_way, key=self._rank):
                if other in self._yields and self._yields[other].to == index:
                    continue  # already on its way aside for this one
                if now - self._sent.get((index, other), -math.inf) < self.return_guard:
                    continue  # sent aside for it a moment ago: it waits for it to move
                if other == giving_way_to:
                    self._send_aside(other, index, route, poses, now)
                    continue
                if self._rank(other) < rank:
                    # A higher-ranked robot: its turn comes first; this one waits off
                    # its stack, which would otherwise give up on its goal.
                    self._hold(index, other, now)
                    break
                if self._send_aside(other, index, route, poses, now):
                    self._hold(index, other, now)
                elif (
                    self._nav(other).pursuing
                    and now - self._sent.get((other, index), -math.inf) >= self.return_guard
                ):
                    # Inversion: the robot in the way cannot get out of it; make way for it.
                    other_route = self._route(other, poses[other], now)
                    if other_route is not None and self._send_aside(
                        index, other, other_route, poses, now
                    ):
                        break

    def _send_aside(
        self, index: int, to: int, route: np.ndarray, poses: list[Pose2D], now: float
    ) -> bool:
        """Send robot ``index`` to a refuge off ``route`` (robot ``to``'s); False if none."""
        from navseq.sim.right_of_way import find_refuge

        radius = self._footprints[index].circumscribed_radius
        others = [
            (pose, self._footprints[other].circumscribed_radius)
            for other, pose in enumerate(poses)
            if other != index
        ]
        others += [
            (target, radius)
            for other in self._yields
            if other != index and (target := self._nav(other).aside_target) is not None
        ]
        refuge = find_refuge(
            self._costmaps[index],
            poses[index],
            radius,
            route,
            self._way(index, to) + self.refuge_margin,
            others,
        )
        if refuge is None:
            return False
        self._holds.pop(index, None)  # held for another robot: now it moves out of the way
        self._nav(index).aside(refuge, f"giving way to {self.names[to]}")
        self._say(
            f"{self.names[index]} sent aside to ({refuge.x:.2f}, {refuge.y:.2f}) "
            f"for {self.names[to]}"
        )
        self._yields[index] = _Yield(to, now)
        self._sent[(index, to)] = now
        watch = self._watch[index]
        watch.route, watch.moved_at, watch.travelled_at = None, now, now
        self.sent_aside += 1
        return True


__all__ = [
    "CoordinatedNavigator",
    "CoordinatedRobot",
    "FleetCoordinator",
    "Mode",
]
