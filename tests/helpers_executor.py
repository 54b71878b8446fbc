"""Helpers for executor tests: small missions and a hand-driven executor harness."""

from __future__ import annotations

from typing import Any, TypeVar

from navseq.executor import CancelGoal, ClearCostmaps, Command, MissionExecutor, SendGoal
from navseq.executor.commands import CancelRecovery, CancelTask, RunRecovery, StartTask
from navseq.executor.events import MissionEvent
from navseq.executor.resume import ResumePoint
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Policy, Waypoint
from navseq.mission.robot import RobotProfile
from navseq.navigators.base import (
    GoalFeedback,
    GoalPlan,
    RecoveryDone,
    ServerBack,
    ServerLost,
)
from navseq.navigators.scripted import scripted_done
from navseq.tasks.base import TaskDone

E = TypeVar("E")


def line_mission(
    count: int = 3,
    *,
    loops: int | None = 1,
    server_timeout: float | None = 60.0,
    **policy: Any,
) -> Mission:
    """``count`` waypoints 1 m apart along +x (1,0), (2,0), ..., all facing +x."""
    waypoints = tuple(Waypoint(float(i + 1), 0.0, name=f"p{i + 1}") for i in range(count))
    return Mission(
        waypoints=waypoints,
        defaults=Policy(**policy),
        loops=loops,
        server_timeout=server_timeout,
    )


class Harness:
    """Drives a :class:`MissionExecutor` by hand and keeps what it said and asked."""

    def __init__(
        self, mission: Mission, resume: ResumePoint | None = None, robot: RobotProfile | None = None
    ):
        self.executor = MissionExecutor(mission, resume=resume, robot=robot)
        self.events: list[MissionEvent] = []
        self.commands: list[Command] = []
        self.executor.add_listener(self.events.append)

    def _keep(self, commands: list[Command]) -> list[Command]:
        self.commands.extend(commands)
        return commands

    def start(self, t: float = 0.0) -> list[Command]:
        return self._keep(self.executor.start(t))

    @property
    def goal_id(self) -> int:
        """Id of the last goal the executor sent."""
        return self.goals()[-1].goal.goal_id

    def goals(self) -> list[SendGoal]:
        return [c for c in self.commands if isinstance(c, SendGoal)]

    def cancels(self) -> list[CancelGoal]:
        return [c for c in self.commands if isinstance(c, CancelGoal)]

    def clears(self) -> list[ClearCostmaps]:
        return [c for c in self.commands if isinstance(c, ClearCostmaps)]

    def done(
        self,
        status: str,
        t: float,
        goal_id: int | None = None,
        *,
        pose: Pose2D | None = None,
        text: str = "",
    ) -> list[Command]:
        gid = self.goal_id if goal_id is None else goal_id
        # Statuses by actionlib's names, ended the way the scripted double ends them.
        done = scripted_done(gid, status, text)
        return self._keep(self.executor.on_event(done, t, pose))

    def succeed(self, t: float, pose: Pose2D | None = None) -> list[Command]:
        return self.done("SUCCEEDED", t, pose=pose)

    def plan(self, t: float, path: list[tuple[float, float]]) -> list[Command]:
        return self._keep(self.executor.on_event(GoalPlan(self.goal_id, tuple(path)), t))

    def feedback(
        self, t: float, pose: Pose2D, remaining: float | None = None, goal_id: int | None = None
    ) -> list[Command]:
        gid = self.goal_id if goal_id is None else goal_id
        return self._keep(self.executor.on_event(GoalFeedback(gid, pose, remaining), t))

    def tick(
        self, t: float, pose: Pose2D | None = None, odom: Pose2D | None = None
    ) -> list[Command]:
        return self._keep(self.executor.on_tick(t, pose, odom))

    def server_lost(self, t: float) -> list[Command]:
        return self._keep(self.executor.on_event(ServerLost("test"), t))

    def server_back(self, t: float) -> list[Command]:
        return self._keep(self.executor.on_event(ServerBack(), t))

    def skip(self, t: float, reason: str = "skipped by operator") -> list[Command]:
        return self._keep(self.executor.skip(t, reason))

    def pause(self, t: float) -> list[Command]:
        return self._keep(self.executor.pause(t))

    def resume(self, t: float) -> list[Command]:
        return self._keep(self.executor.resume(t))

    def interrupt(self, t: float, reason: str) -> list[Command]:
        return self._keep(self.executor.interrupt(t, reason))

    def started_tasks(self) -> list[StartTask]:
        return [c for c in self.commands if isinstance(c, StartTask)]

    def cancelled_tasks(self) -> list[CancelTask]:
        return [c for c in self.commands if isinstance(c, CancelTask)]

    def task_done(
        self, t: float, succeeded: bool = True, detail: str = "", task_id: int | None = None
    ) -> list[Command]:
        """The last task started ends by itself (or the task ``task_id``)."""
        tid = self.started_tasks()[-1].task_id if task_id is None else task_id
        return self._keep(self.executor.on_task_done(TaskDone(tid, succeeded, detail), t))

    def recoveries_run(self) -> list[RunRecovery]:
        return [c for c in self.commands if isinstance(c, RunRecovery)]

    def recoveries_cancelled(self) -> list[CancelRecovery]:
        return [c for c in self.commands if isinstance(c, CancelRecovery)]

    def recovery_done(self, t: float, succeeded: bool = True, detail: str = "") -> list[Command]:
        """The last recovery started ends by itself, as the navigator reports it."""
        rid = self.recoveries_run()[-1].recovery_id
        return self._keep(self.executor.on_event(RecoveryDone(rid, succeeded, detail), t))

    def of_type(self, cls: type[E]) -> list[E]:
        return [e for e in self.events if isinstance(e, cls)]
