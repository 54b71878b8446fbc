"""Nav2's behaviour server on the simulated robot: spin, backup, drive_on_heading, wait,
assisted_teleop.

The rules of ``nav2_behaviors`` (Jazzy), without ROS, so that they can be read and
tested alone; the ROS 2 simulator node serves them as Nav2's four actions.

- **spin** turns by ``target_yaw`` (radians, signed) at ``sqrt(2 * rotational_acc_lim
  * remaining)`` clamped between ``min_rotational_vel`` and ``max_rotational_vel``, and
  succeeds once the turned angle reaches the target.
- **drive_on_heading** drives straight at ``speed`` until the robot is ``target.x``
  metres from where it started. Only x: a y or z is INVALID_INPUT, and so is a speed
  whose sign differs from the target's. **backup** is the same backwards: it takes the
  magnitudes of both (Nav2 does so silently).
- **wait** succeeds after ``time`` seconds.
- **assisted_teleop** drives with the operator's last twist (:meth:`BehaviorServer.teleop`,
  Nav2's ``cmd_vel_teleop``; kept until the next one, as Nav2 keeps it) through Nav2's
  collision projection (:mod:`navseq.sim.assisted_teleop`: slowed down before an
  obstacle, stopped when it is one step ahead). It SUCCEEDS when the operator says so
  (:meth:`BehaviorServer.preempt_teleop`, Nav2's ``preempt_teleop`` topic) and ends
  with TIMEOUT once a positive ``time_allowance`` runs out; its feedback is the time it
  has run. The twist is forgotten when the goal ends.

Each cycle, spin and drive_on_heading first look ``simulate_ahead_time`` seconds ahead
along their command (in steps of one cycle, no further than what is left to do) and
end ABORTED with COLLISION_AHEAD when the robot's footprint would touch an obstacle
there; a positive ``time_allowance`` that runs out ends them with TIMEOUT. Nav2's
behaviours set no ``error_msg``: neither do these. A new behaviour goal ends the running
one ABORTED (Nav2 aborts a behaviour asked to preempt; with one robot, a behaviour of
another kind takes it over too); a cancel ends it CANCELED. Errors are named as the
action's result constants (``COLLISION_AHEAD``): each action numbers them differently.

Times are simulated seconds; :meth:`BehaviorServer.step` is called once per simulator
step with the robot's pose and returns the velocity to command.
"""

from __future__ import annotations

import enum
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from navseq.geometry import Pose2D
from navseq.sim.assisted_teleop import TeleopParams, assisted_command


class Behavior(enum.Enum):
    """The behaviours of nav2_bringup's default ``behavior_server`` (each one's action name)."""

    SPIN = "spin"
    BACKUP = "backup"
    DRIVE_ON_HEADING = "drive_on_heading"
    WAIT = "wait"
    ASSISTED_TELEOP = "assisted_teleop"


@dataclass(frozen=True)
class BehaviorParams:
    """nav2_bringup's ``behavior_server`` parameters (Jazzy ``nav2_params.yaml``)."""

    cycle_frequency: float = 10.0  # Hz
    simulate_ahead_time: float = 2.0  # s
    max_rotational_vel: float = 1.0  # rad/s
    min_rotational_vel: float = 0.4  # rad/s
    rotational_acc_lim: float = 3.2  # rad/s²
    teleop: TeleopParams = field(default_factory=TeleopParams)


class Outcome(enum.Enum):
    SUCCEEDED = "SUCCEEDED"
    ABORTED = "ABORTED"
    CANCELED = "CANCELED"


@dataclass(frozen=True)
class BehaviorEnding:
    """How a behaviour goal ended: ``error`` is the result constant's name ("" for NONE),
    ``elapsed`` its ``total_elapsed_time``; ``log`` what Nav2 logs about it."""

    outcome: Outcome
    error: str = ""
    elapsed: float = 0.0
    log: str = ""


@dataclass
class BehaviorGoal:
    """One behaviour goal and how far it got (``progress``: the action's feedback value:
    radians turned, metres driven, or seconds left; seconds run for assisted_teleop)."""

    behavior: Behavior
    started: float
    time_allowance: float = 0.0  # s; 0: none
    target: float = 0.0  # radians (spin), metres (drive), seconds (wait)
    speed: float = 0.0  # m/s, signed
    progress: float = 0.0
    ending: BehaviorEnding | None = None
    done: threading.Event = field(default_factory=threading.Event, repr=False)
    # Where it started and what it measures from (set by the first cycle).
    _origin: Pose2D | None = None
    _last_yaw: float = 0.0
    _preempted: bool = False  # assisted_teleop: the operator said it is done

    def end(self, ending: BehaviorEnding) -> None:
        if self.ending is None:
            self.ending = ending
            self.done.set()


Collides = Callable[[Pose2D], bool]


class BehaviorServer:
    """Runs one behaviour at a time on one robot; see the module docstring."""

    def __init__(self, params: BehaviorParams | None = None) -> None:
        self.params = params or BehaviorParams()
        self.active: BehaviorGoal | None = None
        self.teleop_twist = (0.0, 0.0)  # the operator's last (v, w) on cmd_vel_teleop

    # -- goals -----------------------------------------------------------------------

    def spin(self, now: float, target_yaw: float, time_allowance: float) -> BehaviorGoal:
        return self._start(BehaviorGoal(Behavior.SPIN, now, time_allowance, target_yaw))

    def drive(
        self,
        behavior: Behavior,
        now: float,
        target: tuple[float, float, float],
        speed: float,
        time_allowance: float,
    ) -> BehaviorGoal:
        """drive_on_heading or backup to ``target`` (x, y, z) at ``speed``."""
        x, y, z = target
        goal = BehaviorGoal(behavior, now, time_allowance)
        if y != 0.0 or z != 0.0:
            goal.end(
                BehaviorEnding(
                    Outcome.ABORTED,
                    "INVALID_INPUT",
                    log=f"{_title(behavior)} in Y and Z is not supported: it only moves in X",
                )
            )
            return goal
        if behavior is Behavior.BACKUP:
            x, speed = -abs(x), -abs(speed)  # Nav2 makes both negative, silently
        elif (x > 0.0) != (speed > 0.0):
            goal.end(
                BehaviorEnding(
                    Outcome.ABORTED, "INVALID_INPUT", log="Speed and command sign did not match"
                )
            )
            return goal
        goal.target, goal.speed = abs(x), speed
        return self._start(goal)

    def wait(self, now: float, seconds: float) -> BehaviorGoal:
        goal = BehaviorGoal(Behavior.WAIT, now, target=seconds, progress=seconds)
        return self._start(goal)

    def assisted_teleop(self, now: float, time_allowance: float) -> BehaviorGoal:
        return self._start(BehaviorGoal(Behavior.ASSISTED_TELEOP, now, time_allowance))

    def teleop(self, v: float, w: float) -> None:
        """The operator's twist (``cmd_vel_teleop``): assisted_teleop drives with it."""
        self.teleop_twist = (v, w)

    def preempt_teleop(self) -> None:
        """The operator ends assisted teleop (``preempt_teleop``): it SUCCEEDS at its next
        cycle. Heard while none runs, it is forgotten (Nav2 clears it at every start)."""
        goal = self.active
        if goal is not None and goal.behavior is Behavior.ASSISTED_TELEOP:
            goal._preempted = True

    def cancel(self, goal: BehaviorGoal, now: float) -> None:
        """The client cancels ``goal``: it ends CANCELED, the robot is told to stop."""
        goal.end(BehaviorEnding(Outcome.CANCELED, elapsed=now - goal.started))
        if goal is self.active:
            self._release()

    def abort_all(self, now: float, why: str) -> None:
        if self.active is not None:
            self.active.end(
                BehaviorEnding(Outcome.ABORTED, elapsed=now - self.active.started, log=why)
            )
            self._release()

    @property
    def running(self) -> bool:
        return self.active is not None

    def drives(self, _now: float) -> bool:
        """Whether a behaviour drives the robot this step (the stand-in's driver rule)."""
        return self.active is not None

    def _start(self, goal: BehaviorGoal) -> BehaviorGoal:
        previous = self.active
        if previous is not None:
            previous.end(
                BehaviorEnding(
                    Outcome.ABORTED,
                    elapsed=goal.started - previous.started,
                    log=f"Received a preemption request for {previous.behavior.value}: "
                    "aborting and stopping",
                )
            )
            self._release()
        self.active = goal
        return goal

    # -- simulation ------------------------------------------------------------------

    def step(self, now: float, pose: Pose2D, collides: Collides) -> tuple[float, float]:
        """One cycle of the running behaviour: the (v, w) to command now.

        (0, 0) once it ended (or when none runs): the robot brakes.
        """
        goal = self.active
        if goal is None:
            return (0.0, 0.0)
        command = self._cycle(goal, now, pose, collides)
        if goal.ending is not None:
            self._release()
            return (0.0, 0.0)
        return command

    def _release(self) -> None:
        """The running goal has ended: none runs, and the operator's twist is forgotten
        (Nav2's assisted teleop clears it on completion)."""
        self.active = None
        self.teleop_twist = (0.0, 0.0)

    def _cycle(
        self, goal: BehaviorGoal, now: float, pose: Pose2D, collides: Collides
    ) -> tuple[float, float]:
        elapsed = now - goal.started
        if goal.behavior is Behavior.WAIT:
            goal.progress = max(0.0, goal.target - elapsed)
            if goal.progress <= 0.0:
                goal.end(BehaviorEnding(Outcome.SUCCEEDED, elapsed=elapsed))
            return (0.0, 0.0)
        if 0.0 < goal.time_allowance < elapsed:
            name = _title(goal.behavior)
            goal.end(
                BehaviorEnding(
                    Outcome.ABORTED,
                    "TIMEOUT",
                    elapsed,
                    f"Exceeded time allowance before reaching the {name} goal - Exiting {name}",
                )
            )
            return (0.0, 0.0)
        if goal.behavior is Behavior.ASSISTED_TELEOP:
            return self._teleop_cycle(goal, pose, elapsed, collides)
        if goal._origin is None:
            goal._origin, goal._last_yaw = pose, pose.yaw
        if goal.behavior is Behavior.SPIN:
            return self._spin_cycle(goal, pose, elapsed, collides)
        return self._drive_cycle(goal, pose, elapsed, collides)

    def _teleop_cycle(
        self, goal: BehaviorGoal, pose: Pose2D, elapsed: float, collides: Collides
    ) -> tuple[float, float]:
        goal.progress = elapsed
        if goal._preempted:
            goal.end(BehaviorEnding(Outcome.SUCCEEDED, elapsed=elapsed))
            return (0.0, 0.0)
        return assisted_command(pose, self.teleop_twist, collides, self.params.teleop)

    def _spin_cycle(
        self, goal: BehaviorGoal, pose: Pose2D, elapsed: float, collides: Collides
    ) -> tuple[float, float]:
        turned = math.remainder(pose.yaw - goal._last_yaw, math.tau)
        goal.progress += turned
        goal._last_yaw = pose.yaw
        remaining = abs(goal.target) - abs(goal.progress)
        if remaining < 1e-6:
            goal.end(BehaviorEnding(Outcome.SUCCEEDED, elapsed=elapsed))
            return (0.0, 0.0)
        params = self.params
        speed = math.sqrt(2.0 * params.rotational_acc_lim * remaining)
        speed = min(max(speed, params.min_rotational_vel), params.max_rotational_vel)
        w = math.copysign(speed, goal.target)

        def ahead(t: float) -> Pose2D | None:
            turn = w * t
            if remaining - abs(turn) <= 0.0:
                return None
            return Pose2D(pose.x, pose.y, pose.yaw + turn)

        if self._collision_ahead(ahead, collides):
            goal.end(
                BehaviorEnding(
                    Outcome.ABORTED, "COLLISION_AHEAD", elapsed, "Collision Ahead - Exiting Spin"
                )
            )
            return (0.0, 0.0)
        return (0.0, w)

    def _drive_cycle(
        self, goal: BehaviorGoal, pose: Pose2D, elapsed: float, collides: Collides
    ) -> tuple[float, float]:
        assert goal._origin is not None
        goal.progress = math.hypot(pose.x - goal._origin.x, pose.y - goal._origin.y)
        if goal.progress >= goal.target:
            goal.end(BehaviorEnding(Outcome.SUCCEEDED, elapsed=elapsed))
            return (0.0, 0.0)
        remaining = goal.target - goal.progress
        v = goal.speed

        def ahead(t: float) -> Pose2D | None:
            move = v * t
            if remaining - abs(move) <= 0.0:
                return None
            return Pose2D(
                pose.x + move * math.cos(pose.yaw), pose.y + move * math.sin(pose.yaw), pose.yaw
            )

        if self._collision_ahead(ahead, collides):
            name = _title(goal.behavior)
            goal.end(
                BehaviorEnding(
                    Outcome.ABORTED, "COLLISION_AHEAD", elapsed, f"Collision Ahead - Exiting {name}"
                )
            )
            return (0.0, 0.0)
        return (v, 0.0)

    def _collision_ahead(self, ahead: Callable[[float], Pose2D | None], collides: Collides) -> bool:
        """Whether a pose ``ahead(t)`` collides, for t in steps of one cycle up to
        ``simulate_ahead_time`` (None: the behaviour ends before t)."""
        params = self.params
        for cycle in range(int(params.cycle_frequency * params.simulate_ahead_time)):
            pose = ahead(cycle / params.cycle_frequency)
            if pose is None:
                return False
            if collides(pose):
                return True
        return False


def _title(behavior: Behavior) -> str:
    """The behaviour's name as Nav2's log lines spell it."""
    return {
        Behavior.SPIN: "Spin",
        Behavior.BACKUP: "DriveOnHeading",  # BackUp is a DriveOnHeading in Nav2
        Behavior.DRIVE_ON_HEADING: "DriveOnHeading",
        Behavior.WAIT: "Wait",
        Behavior.ASSISTED_TELEOP: "assisted_teleop",  # Nav2 names it by its plugin name
    }[behavior]


__all__ = [
    "Behavior",
    "BehaviorEnding",
    "BehaviorGoal",
    "BehaviorParams",
    "BehaviorServer",
    "Outcome",
]
