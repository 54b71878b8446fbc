"""A deterministic stand-in for a navigation stack, for tests of everything above it.

:class:`ScriptedNavigator` implements the :class:`~navseq.navigators.base.Navigator`
interface with its own simulated clock. The robot drives in a straight line to the
goal at a fixed speed, then turns in place to the goal yaw, and sends feedback every
step. What each goal does is scripted, in the order goals are sent::

    nav = ScriptedNavigator([Succeed(), Finish("ABORTED", after=2.0), Stall()])

The first goal succeeds on arrival, the second is aborted after 2 s, the third stops
moving and never finishes; goals beyond the script succeed. Statuses are actionlib's
names (the double plays move_base): ``SUCCEEDED`` ends a goal succeeded, ``LOST`` lost,
any other name failed with that name as the stack's status. :class:`FalseSuccess`
plays move_base's plan race (ros-planning/navigation #949): SUCCEEDED at once, with
the robot still where it was. A goal resent after a
server loss is a new goal and takes the next behaviour.

Everything the executor asked for (goals, cancels, costmap clears) is recorded for
assertions, and can also be appended as JSON lines to a file, so that a test can
check what a killed subprocess did. With ``realtime`` set, :meth:`spin` also sleeps,
so that simulated time runs at that multiple of wall time (for signal tests).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from navseq.geometry import Pose2D, compose, inverse, normalize_angle
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    GoalOutcome,
    NavEvent,
    ServerBack,
    ServerLost,
)
from navseq.navigators.registry import NavigatorDraft, NavigatorSetup
from navseq.navigators.settings import ScriptedNavigatorSettings


@dataclass(frozen=True)
class Succeed:
    """Drive to the goal and report SUCCEEDED on arrival (the default behaviour)."""


@dataclass(frozen=True)
class Finish:
    """Report ``status`` ``after`` seconds after the goal was sent; drive meanwhile.

    ``status`` is a stack's status name (``"ABORTED"``, ``"CANCELED"`` ...).
    ``REJECTED`` and ``RECALLED`` goals are never accepted, like in actionlib.
    """

    status: str
    after: float = 0.0
    text: str = ""


@dataclass(frozen=True)
class LoseServer:
    """``after`` s into the goal the server vanishes for ``duration`` s (None: for good).

    The loss is reported as ``ServerLost``, or as the goal's ``LOST`` status when
    ``as_goal_status``; either way ``ServerBack`` follows when the server returns.
    The robot stands still while the server is away.
    """

    after: float
    duration: float | None
    as_goal_status: bool = False


@dataclass(frozen=True)
class Hang:
    """Drive to the goal, then never report a result."""


@dataclass(frozen=True)
class Stall:
    """Stop moving ``after`` seconds into the goal, and never report a result."""

    after: float = 0.0


@dataclass(frozen=True)
class FalseSuccess:
    """Report SUCCEEDED ``after`` seconds into the goal without the robot moving at all.

    What move_base sometimes does with a fresh goal (ros-planning/navigation #949).
    """

    after: float = 0.0
    text: str = ""


Behaviour = Succeed | Finish | LoseServer | Hang | Stall | FalseSuccess

_UNACCEPTED = ("REJECTED", "RECALLED")
#: Status names a ``--scripted-script`` may end a goal with: actionlib's, and Nav2's
#: CANCELED.
SCRIPT_STATUSES = ("SUCCEEDED", "ABORTED", "REJECTED", "PREEMPTED", "RECALLED", "LOST", "CANCELED")


def scripted_done(goal_id: int, status: str, text: str = "") -> GoalDone:
    """How the double ends a goal with an actionlib status name."""
    outcome = {"SUCCEEDED": GoalOutcome.SUCCEEDED, "LOST": GoalOutcome.LOST}.get(
        status, GoalOutcome.FAILED
    )
    return GoalDone(goal_id, outcome, status, text)


_ARRIVED_YAW = 1e-3


@dataclass
class _ActiveGoal:
    goal: Goal
    behaviour: Behaviour
    sent_at: float


class ScriptedNavigator:
    """A navigation stack whose every goal does what the script says.

    ``speed`` is m/s, ``turn_rate`` rad/s, ``step`` the simulation step in seconds
    (feedback is sent once per step). ``report_distance`` puts the straight-line
    distance in feedback's ``distance_remaining``. ``server_available=False`` starts
    with no server at all (``wait_for_server`` says False).
    """

    def __init__(
        self,
        script: Iterable[Behaviour] = (),
        *,
        start: Pose2D | None = None,
        speed: float = 1.0,
        turn_rate: float = 2.0,
        step: float = 0.05,
        report_distance: bool = True,
        realtime: float | None = None,
        log_path: Path | str | None = None,
        server_available: bool = True,
    ):
        self.script: list[Behaviour] = list(script)
        self.speed = speed
        self.turn_rate = turn_rate
        self.step = step
        self.report_distance = report_distance
        self.realtime = realtime
        self.sent_goals: list[Goal] = []
        self.send_times: list[float] = []
        self.cancels: list[tuple[float, int | None]] = []  # (time, active goal id or None)
        self.costmap_clears: list[float] = []
        self._pose = start or Pose2D(0.0, 0.0, 0.0)
        self._odom_origin = self._pose  # odometry reads (0, 0, 0) where the robot starts
        self._t = 0.0
        self._events: list[NavEvent] = []
        self._active: _ActiveGoal | None = None
        self._server_down_until: float | None = None if server_available else math.inf
        self._log = open(log_path, "a", encoding="utf-8") if log_path is not None else None  # noqa: SIM115

    # ------------------------------------------------------------------ Navigator

    def now(self) -> float:
        return self._t

    def wait_for_server(self, timeout: float) -> bool:
        return self._server_down_until is None

    def send_goal(self, goal: Goal) -> None:
        self.sent_goals.append(goal)
        self.send_times.append(self._t)
        self._record("send_goal", goal_id=goal.goal_id, x=goal.pose.x, y=goal.pose.y)
        if self._server_down_until is not None:
            return  # nobody listening: the goal goes nowhere
        if self._active is not None:
            self._events.append(GoalDone.failed(self._active.goal.goal_id, "PREEMPTED"))
        index = len(self.sent_goals) - 1
        behaviour = self.script[index] if index < len(self.script) else Succeed()
        self._active = _ActiveGoal(goal, behaviour, self._t)
        if not (isinstance(behaviour, Finish) and behaviour.status in _UNACCEPTED):
            self._events.append(GoalAccepted(goal.goal_id))

    def cancel_goal(self) -> None:
        active_id = self._active.goal.goal_id if self._active else None
        self.cancels.append((self._t, active_id))
        self._record("cancel_goal", goal_id=active_id)
        if self._active is not None and self._server_down_until is None:
            self._events.append(GoalDone.failed(self._active.goal.goal_id, "PREEMPTED"))
        self._active = None

    def clear_costmaps(self) -> None:
        self.costmap_clears.append(self._t)
        self._record("clear_costmaps")

    def robot_pose(self) -> Pose2D | None:
        return self._pose

    def odometry_pose(self) -> Pose2D | None:
        return compose(inverse(self._odom_origin), self._pose)

    def poll(self) -> list[NavEvent]:
        events, self._events = self._events, []
        return events

    def spin(self, seconds: float) -> None:
        end = self._t + seconds
        while self._t < end - 1e-12:
            dt = min(self.step, end - self._t)
            self._advance(dt)
            if self.realtime:
                time.sleep(dt / self.realtime)

    def close(self) -> None:
        if self._active is not None:
            self.cancel_goal()
        if self._log is not None:
            self._log.close()
            self._log = None

    # ------------------------------------------------------------------ simulation

    def _advance(self, dt: float) -> None:
        self._t += dt
        if self._server_down_until is not None:
            if self._t >= self._server_down_until:
                self._server_down_until = None
                self._events.append(ServerBack())
            return
        active = self._active
        if active is None:
            return
        goal_id = active.goal.goal_id
        elapsed = self._t - active.sent_at
        behaviour = active.behaviour
        if isinstance(behaviour, LoseServer) and elapsed >= behaviour.after:
            down_for = math.inf if behaviour.duration is None else behaviour.duration
            self._server_down_until = self._t + down_for
            self._active = None
            if behaviour.as_goal_status:
                self._events.append(GoalDone.lost(goal_id))
            else:
                self._events.append(ServerLost("scripted server loss"))
            return
        if isinstance(behaviour, Finish) and elapsed >= behaviour.after:
            self._events.append(scripted_done(goal_id, behaviour.status, behaviour.text))
            self._active = None
            return
        if isinstance(behaviour, FalseSuccess):
            if elapsed >= behaviour.after:
                self._events.append(GoalDone.succeeded(goal_id, behaviour.text))
                self._active = None
            return  # the robot never moves
        stalled = isinstance(behaviour, Stall) and elapsed >= behaviour.after
        arrived = self._move_towards(active.goal.pose, 0.0 if stalled else dt)
        remaining = self._pose.distance_to(active.goal.pose) if self.report_distance else None
        self._events.append(GoalFeedback(goal_id, self._pose, remaining))
        if arrived and isinstance(behaviour, Succeed):
            self._events.append(GoalDone.succeeded(goal_id))
            self._active = None

    def _move_towards(self, target: Pose2D, dt: float) -> bool:
        """Drive straight to the target, then turn to its yaw; True once both are done."""
        pose = self._pose
        distance = pose.distance_to(target)
        if distance > 0.0:
            travel = min(distance, self.speed * dt)
            heading = math.atan2(target.y - pose.y, target.x - pose.x)
            if travel >= distance:
                x, y = target.x, target.y
            else:
                fraction = travel / distance
                x = pose.x + (target.x - pose.x) * fraction
                y = pose.y + (target.y - pose.y) * fraction
            self._pose = Pose2D(x, y, heading)
            return False
        error = normalize_angle(target.yaw - pose.yaw)
        if abs(error) > _ARRIVED_YAW:
            turn = math.copysign(min(abs(error), self.turn_rate * dt), error)
            self._pose = Pose2D(pose.x, pose.y, normalize_angle(pose.yaw + turn))
            return False
        return True

    def _record(self, call: str, **fields: Any) -> None:
        if self._log is not None:
            self._log.write(json.dumps({"t": round(self._t, 6), "call": call, **fields}) + "\n")
            self._log.flush()


def behaviours_of(script: str) -> list[Behaviour]:
    """``succeed,aborted@2,stall@1,hang,falsesuccess`` as behaviours (``--scripted-script``).

    A status name ends the goal with that status (``aborted@2``: ABORTED after 2 s);
    anything else is a ValueError (test-only input: an internal error, not a user's).
    """
    behaviours: list[Behaviour] = []
    for token in filter(None, (part.strip() for part in script.split(","))):
        name, _, after = token.partition("@")
        seconds = float(after) if after else 0.0
        if name == "succeed":
            behaviours.append(Succeed())
        elif name == "hang":
            behaviours.append(Hang())
        elif name == "stall":
            behaviours.append(Stall(after=seconds))
        elif name == "falsesuccess":
            behaviours.append(FalseSuccess(after=seconds))
        elif name.upper() in SCRIPT_STATUSES:
            behaviours.append(Finish(name.upper(), after=seconds))
        else:
            raise ValueError(f"{name!r} is no scripted behaviour or status")
    return behaviours


def create(settings: ScriptedNavigatorSettings, draft: NavigatorDraft) -> NavigatorSetup:
    """The ``scripted`` kind (hidden from ``--help``): the double, for the CLI's tests."""
    grid = draft.optional_map()
    start = draft.start

    def make_navigator() -> ScriptedNavigator:
        return ScriptedNavigator(
            behaviours_of(settings.scripted_script),
            start=start,
            speed=settings.scripted_speed,
            realtime=settings.scripted_realtime,
            log_path=settings.scripted_log,
        )

    return NavigatorSetup(
        make_navigator=make_navigator,
        info={"kind": "scripted", "speed": settings.scripted_speed},
        grid=grid,
    )


__all__ = [
    "Behaviour",
    "FalseSuccess",
    "Finish",
    "Hang",
    "LoseServer",
    "ScriptedNavigator",
    "Stall",
    "Succeed",
    "behaviours_of",
    "create",
    "scripted_done",
]
