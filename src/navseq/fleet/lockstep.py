"""One clock for a fleet whose robots each run in a thread of their own.

Each robot's run is a :class:`~navseq.run.session.Session` (its executor, journal and
report as for one robot) in a thread; its navigator is a :class:`MemberNavigator`, a
:class:`~navseq.navigators.sim.SimNavigator` on that robot's world inside one
:class:`~navseq.sim.fleet_world.FleetWorld`. A run's loop asks its navigator to spin
``tick`` seconds; here that is a rendezvous (:class:`FleetClock`): once every robot
still running has asked, the last to ask steps the whole fleet, every member turns
the step into its own events, and all go on. So the robots share one simulated clock
and never move while an executor is deciding, and no robot's executor sees another
robot's time.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterable

from navseq.navigators.sim import SimNavigator
from navseq.sim.fleet_world import FleetWorld


class FleetClock:
    """The fleet's rendezvous: :meth:`advance` blocks until every member still in the
    run has asked, then the fleet steps. ``realtime`` paces simulated time against the
    wall clock (None: as fast as the CPU allows)."""

    def __init__(
        self,
        fleet: FleetWorld,
        members: Iterable[str],
        *,
        realtime: float | None = None,
        wall_clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.fleet = fleet
        self.realtime = realtime
        self._wall_clock = wall_clock
        self._waiting: set[str] = set()
        self._members = set(members)
        self._asked = 0.0  # the longest spin asked for in this round
        self._unspun = 0.0
        self._round = 0
        self._condition = threading.Condition()
        self._step_hooks: dict[str, Callable[[], None]] = {}
        self._pace_origin: tuple[float, float] | None = None
        self.stepped = threading.Event()  # set after every round, for a live display
        self._failure: BaseException | None = None  # a step that raised: every run ends

    def on_step(self, name: str, hook: Callable[[], None]) -> None:
        """Call ``hook`` after every fleet step (a member turning it into events)."""
        self._step_hooks[name] = hook

    def advance(self, name: str, seconds: float) -> None:
        """Member ``name`` waits for the fleet to move ``seconds`` (with the others)."""
        with self._condition:
            self._waiting.add(name)
            self._asked = max(self._asked, seconds)
            here = self._round
            self._step_if_all_asked()
            while self._round == here and self._failure is None:
                self._condition.wait()
            if self._failure is not None:
                # Every robot's run ends (its goal cancelled), not just the stepping one's.
                raise RuntimeError(f"the fleet's simulator failed: {self._failure!r}")

    def leave(self, name: str) -> None:
        """Member ``name``'s run has ended: the fleet no longer waits for it (its robot
        stays where it is, an obstacle to the others)."""
        with self._condition:
            self._members.discard(name)
            self._step_hooks.pop(name, None)
            self._step_if_all_asked()

    def _step_if_all_asked(self) -> None:
        if not self._waiting or not self._members <= self._waiting:
            return
        fleet = self.fleet
        self._unspun += self._asked
        steps = math.floor(self._unspun / fleet.dt + 1e-9)
        self._unspun -= steps * fleet.dt
        hooks = list(self._step_hooks.values())
        try:
            for _ in range(steps):
                fleet.step()
                for hook in hooks:
                    hook()
                if self.realtime is not None:
                    self._pace()
        except BaseException as error:
            self._failure = error
            self._condition.notify_all()
            raise
        self._waiting.clear()
        self._asked = 0.0
        self._round += 1
        self._condition.notify_all()
        self.stepped.set()

    def _pace(self) -> None:
        assert self.realtime is not None
        now = self._wall_clock()
        if self._pace_origin is None:
            self._pace_origin = (self.fleet.now, now)
            return
        sim_origin, wall_origin = self._pace_origin
        due = wall_origin + (self.fleet.now - sim_origin) / self.realtime
        if due > now:
            time.sleep(due - now)


class MemberNavigator(SimNavigator):
    """A robot of a :class:`FleetWorld` behind the Navigator interface: goals and poses
    as :class:`SimNavigator`'s, but time moves only when the whole fleet steps."""

    def __init__(self, fleet: FleetWorld, name: str, clock: FleetClock) -> None:
        super().__init__(fleet.world(name))
        self.name = name
        self._last_pose = self.world.robot.pose
        self._clock = clock
        clock.on_step(name, self._after_step)

    def spin(self, seconds: float) -> None:
        self._clock.advance(self.name, seconds)

    def _after_step(self) -> None:
        """What :meth:`SimNavigator.spin` does after each step of its own world."""
        world = self.world
        pose = world.robot.pose
        if pose is not self._last_pose:  # a new pose object: the robot moved
            self._last_pose = pose
            self.trajectory.append((world.time, pose.x, pose.y))
        if self._active is not None:
            self._report(self._active)


__all__ = ["FleetClock", "MemberNavigator"]
