"""What opennav_docking's ``docking_server`` does, on the simulated robot, without ROS.

The ROS 2 simulator node serves ``dock_robot`` and ``undock_robot``
(:mod:`navseq.ros2.docking_actions`); the rules live here so they can be read and tested
without rclpy. With nav2_bringup's ``docking_server`` parameters (one dock type,
``simple_charging_dock``: staging 0.7 m before the dock, docked within 0.05 m; approach
timeout 30 s; undock tolerances 0.05 m and 0.1 rad) a docking goal goes as in Nav2:

1. **the dock**: by id from the docks file (unknown: ``DOCK_NOT_IN_DB``), or a pose
   with a ``dock_type`` (empty: the only type; unknown: ``DOCK_NOT_VALID``). A robot
   still docked at the dock it last docked at (within the docking threshold) is not
   moved: the goal ends ABORTED with a default result (``success`` true, code 0), as
   Nav2's action server ends a goal its callback left unfinished;
2. **staging** (feedback ``NAV_TO_STAGING_POSE``): the staging pose is the dock pose
   moved ``staging_x_offset`` (-0.7 m) along the dock's heading; unless
   ``navigate_to_staging_pose`` is false or the robot is within
   ``dock_prestaging_tolerance`` (0.5 m) of it, a ``navigate_to_pose`` goal drives
   there — through the stand-in's own bt_navigator, as Nav2's docking server is a
   ``navigate_to_pose`` client, so another client's navigation goal preempts it. A
   failed navigation or one longer than ``max_staging_time``: ``FAILED_TO_STAGE``;
3. **perception** (``INITIAL_PERCEPTION``): the dock is where the docks file says.
   nav2_bringup's dock plugin takes the dock's pose from an external detector
   (``use_external_detection_pose``) on ``detected_dock_pose``; the stand-in plays that
   detector (:meth:`DockingServer.sighting`): while the robot perceives and approaches
   the dock it sees the dock relative to its true pose (``base_link``, no noise, no
   marker offsets), and the docking server's filtered estimate of it
   (``filtered_dock_pose``) is that sighting in the ``odom`` frame (nav2_bringup's
   ``fixed_frame``) through Nav2's pose filter (``filter_coef`` 0.1): with
   ``--odom-drift`` it carries the localisation's error, as a detection does;
4. **approach** (``CONTROLLING``): the robot drives to the dock pose at the docking
   controller's 0.15 m/s, turning toward it (a simple heading law, not Nav2's graceful
   controller), until it is within ``docking_threshold``. A footprint collision on the
   way, farther than ``dock_collision_threshold`` (0.3 m) from the dock, or no dock
   within ``dock_approach_timeout``: ``FAILED_TO_CONTROL``. Nav2 retries up to
   ``max_retries`` (3) from the staging pose; the stand-in does not retry
   (``num_retries`` stays 0). Each cycle the controller's projected trajectory
   (``docking_trajectory``: ``projection_time`` 5 s in ``simulation_step`` 0.1 s,
   :meth:`DockingServer.trajectory`) is the heading law run ahead from the robot, in
   ``base_link``, undocking too;
5. **charging** (``WAIT_FOR_CHARGE``): nav2_bringup's dock reads no battery, so docked
   is charging: SUCCEEDED, ``success`` true.

Undocking takes the dock type from the goal or the last docking (``DOCK_NOT_VALID``
when neither names a known type) and backs straight out to the staging pose 0.7 m
behind the robot (``undock_linear_tolerance`` / ``undock_angular_tolerance``); a
collision behind or ``max_undocking_time`` running out: ``FAILED_TO_CONTROL``. A robot
that is not docked is not moved: ABORTED with a default result, as in Nav2.

A new goal of either action ends a running one ABORTED (Nav2's docking server then
ends both); a cancel ends it CANCELED and the robot stops. Times are simulated seconds.
"""

from __future__ import annotations

import enum
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from navseq.geometry import Pose2D, compose, inverse, normalize_angle
from navseq.ros2.standin import Nav2StandIn, Navigator, NavTask, Outcome
from navseq.sim.docks import DOCK_TYPES, Dock


class DockState(enum.IntEnum):
    """``nav2_msgs/action/DockRobot`` feedback states."""

    NONE = 0
    NAV_TO_STAGING_POSE = 1
    INITIAL_PERCEPTION = 2
    CONTROLLING = 3
    WAIT_FOR_CHARGE = 4
    RETRY = 5


class DockError(enum.IntEnum):
    """``DockRobot`` / ``UndockRobot`` result codes (nav2_msgs, Jazzy)."""

    NONE = 0
    DOCK_NOT_IN_DB = 901
    DOCK_NOT_VALID = 902
    FAILED_TO_STAGE = 903
    FAILED_TO_DETECT_DOCK = 904
    FAILED_TO_CONTROL = 905
    FAILED_TO_CHARGE = 906
    UNKNOWN = 999


@dataclass(frozen=True)
class Sighting:
    """The dock as the detector sees it (in the robot's base frame) and the docking
    server's filtered estimate of it (in the odom frame)."""

    detected: Pose2D
    filtered: Pose2D


class PoseFilter:
    """Nav2's ``PoseFilter``: each measurement moves the estimate ``coef`` of the way to
    it; one after more than ``timeout`` seconds without any restarts it."""

    def __init__(self, coef: float = 0.1, timeout: float = 1.0) -> None:
        self.coef = coef
        self.timeout = timeout
        self.pose: Pose2D | None = None
        self._stamp = -math.inf

    def update(self, measurement: Pose2D, now: float) -> Pose2D:
        old = self.pose
        if old is None or now - self._stamp > self.timeout or not 0.0 < self.coef < 1.0:
            self.pose = measurement
        else:
            k = self.coef
            turn = normalize_angle(measurement.yaw - old.yaw)
            self.pose = Pose2D(
                old.x + k * (measurement.x - old.x),
                old.y + k * (measurement.y - old.y),
                normalize_angle(old.yaw + k * turn),
            )
        self._stamp = now
        return self.pose


@dataclass(frozen=True)
class DockingParams:
    """nav2_bringup's ``docking_server`` parameters (Jazzy ``nav2_params.yaml``)."""

    staging_x_offset: float = -0.7  # m, along the dock's heading
    docking_threshold: float = 0.05  # m
    dock_prestaging_tolerance: float = 0.5  # m
    dock_approach_timeout: float = 30.0  # s
    undock_linear_tolerance: float = 0.05  # m
    undock_angular_tolerance: float = 0.1  # rad
    dock_collision_threshold: float = 0.3  # m
    linear_speed: float = 0.15  # m/s: the controller's v_linear_min = v_linear_max
    heading_gain: float = 3.0  # 1/s: the controller's k_phi
    max_angular_speed: float = 1.0  # rad/s
    filter_coef: float = 0.1  # simple_charging_dock's
    external_detection_timeout: float = 1.0  # s
    projection_time: float = 5.0  # s: the controller's trajectory ahead
    simulation_step: float = 0.1  # s


@dataclass
class DockingGoal:
    """One ``dock_robot`` or ``undock_robot`` goal and how far it got."""

    undock: bool
    started: float
    dock: Dock | None = None
    deadline: float = math.inf  # staging (docking) or the whole undocking
    state: DockState = DockState.NONE
    states: list[DockState] = field(default_factory=list)  # every state entered, in order
    target: Pose2D | None = None  # where the docking controller drives
    staging: NavTask | None = None
    outcome: Outcome | None = None
    success: bool = False
    error_code: int = DockError.NONE
    error_msg: str = ""
    log: str = ""
    done: threading.Event = field(default_factory=threading.Event, repr=False)
    _approach_started: float = 0.0

    def enter(self, state: DockState) -> None:
        """Go to ``state`` (Nav2 publishes a feedback message at each)."""
        self.state = state
        self.states.append(state)

    def end(
        self, outcome: Outcome, code: int = DockError.NONE, text: str = "", *, success: bool
    ) -> None:
        if self.outcome is None:
            self.outcome, self.error_code, self.error_msg = outcome, int(code), text
            self.success = success
            self.done.set()


Collides = Callable[[Pose2D], bool]


class DockingServer:
    """opennav_docking on ``standin``'s robot; see the module docstring.

    :meth:`drives` and :meth:`step` make it one of the stand-in's drivers: the stand-in
    asks every step whether it drives the robot and, if so, commands what it returns.
    """

    def __init__(
        self, standin: Nav2StandIn, docks: Sequence[Dock], params: DockingParams | None = None
    ) -> None:
        self.standin = standin
        self.docks = {dock.name: dock for dock in docks}
        self.params = params or DockingParams()
        self.active: DockingGoal | None = None
        self.docked_at: Pose2D | None = None  # the dock pose of the last docking
        self.dock_type = ""  # the last docking's type, for undocking
        self.filter = PoseFilter(self.params.filter_coef, self.params.external_detection_timeout)

    # -- goals -----------------------------------------------------------------------

    def dock(
        self,
        now: float,
        *,
        dock_id: str | None,
        dock_pose: Pose2D | None = None,
        dock_type: str = "",
        navigate_to_staging: bool = True,
        max_staging_time: float = 1000.0,
    ) -> DockingGoal:
        """Start a docking goal (by ``dock_id``, else at ``dock_pose``)."""
        goal = self._start(DockingGoal(undock=False, started=now))
        self.filter.pose = None  # a new docking's estimate starts from its first sighting
        if dock_id is not None:
            dock = self.docks.get(dock_id)
            if dock is None:
                self._fail(goal, DockError.DOCK_NOT_IN_DB, "Dock ID requested is not in database!")
                return goal
        else:
            kind = self._plugin(dock_type)
            if kind is None or dock_pose is None:
                self._fail(goal, DockError.DOCK_NOT_VALID, "Dock requested has no valid plugin!")
                return goal
            dock = Dock("", kind, "map", dock_pose)
        goal.dock = dock
        robot = self.standin.world.robot.pose
        if self.docked_at is not None and self._near(robot, self.docked_at):
            goal.log = "Robot is already docked and/or charging (if applicable), no need to dock"
            self._leave(goal)
            return goal
        staging = self.staging_pose(dock.pose)
        goal.enter(DockState.NAV_TO_STAGING_POSE)
        if not navigate_to_staging or robot.distance_to(staging) < (
            self.params.dock_prestaging_tolerance
        ):
            self._approach(goal, now)
            return goal
        goal.deadline = now + max(0.0, max_staging_time)
        goal.staging = self.standin.navigate(Navigator.TO_POSE, [staging])
        return goal

    def undock(self, now: float, *, dock_type: str = "", max_time: float = 30.0) -> DockingGoal:
        goal = self._start(DockingGoal(undock=True, started=now, deadline=now + max_time))
        kind = self._plugin(dock_type or self.dock_type)
        if kind is None:
            self._fail(goal, DockError.DOCK_NOT_VALID, "No dock information to undock from!")
            return goal
        robot = self.standin.world.robot.pose
        if self.docked_at is None or not self._near(robot, self.docked_at):
            goal.log = "Robot is not in the dock, no need to undock"
            self._leave(goal)
            return goal
        goal.target = self.staging_pose(robot)
        goal.enter(DockState.CONTROLLING)
        return goal

    def cancel(self, goal: DockingGoal) -> None:
        """The client cancels ``goal``: it ends CANCELED, the robot stops."""
        if goal.staging is not None and goal.staging.ending is None:
            self.standin.cancel(goal.staging)
        goal.end(Outcome.CANCELED, success=False)
        if goal is self.active:
            self.active = None
            self.standin.world.body.command(0.0, 0.0)

    def abort_all(self, _now: float, why: str) -> None:
        if self.active is not None:
            self.active.end(Outcome.ABORTED, DockError.UNKNOWN, why, success=False)
            self.active = None

    def sighting(self, now: float, robot: Pose2D, odom: Pose2D) -> Sighting | None:
        """What the detector and the filter give while a docking perceives or approaches
        its dock (None otherwise); ``robot`` the true pose, ``odom`` the odometry's."""
        goal = self.active
        if (
            goal is None
            or goal.undock
            or goal.dock is None
            or goal.state not in (DockState.INITIAL_PERCEPTION, DockState.CONTROLLING)
        ):
            return None
        detected = compose(inverse(robot), goal.dock.pose)
        return Sighting(detected, self.filter.update(compose(odom, detected), now))

    def trajectory(self, robot: Pose2D) -> list[Pose2D] | None:
        """The controller's projected trajectory from the robot (in its base frame) while
        it drives to the dock or out of it; None otherwise."""
        goal = self.active
        if goal is None or goal.target is None or goal.state is not DockState.CONTROLLING:
            return None
        params = self.params
        target = compose(inverse(robot), goal.target)
        pose = Pose2D(0.0, 0.0, 0.0)
        poses = [pose]
        dt = params.simulation_step
        for _ in range(round(params.projection_time / dt)):
            if pose.distance_to(target) < params.docking_threshold:
                break
            v, w = self._toward(pose, target, backwards=goal.undock)
            yaw = pose.yaw + w * dt
            pose = Pose2D(pose.x + v * math.cos(yaw) * dt, pose.y + v * math.sin(yaw) * dt, yaw)
            poses.append(pose)
        return poses

    def staging_pose(self, pose: Pose2D) -> Pose2D:
        """``staging_x_offset`` along ``pose``'s heading (simple_charging_dock's rule)."""
        offset = self.params.staging_x_offset
        return Pose2D(
            pose.x + offset * math.cos(pose.yaw), pose.y + offset * math.sin(pose.yaw), pose.yaw
        )

    # -- simulation ------------------------------------------------------------------

    def drives(self, now: float) -> bool:
        """Whether the docking controller drives the robot this step (a staging
        navigation that ended moves the goal on first)."""
        goal = self.active
        if goal is None:
            return False
        if goal.staging is not None:
            self._watch_staging(goal, now)
            goal = self.active
        return goal is not None and goal.target is not None

    def step(self, now: float, pose: Pose2D, collides: Collides) -> tuple[float, float]:
        """One control cycle: the (v, w) to command; (0, 0) once the goal ended."""
        goal = self.active
        if goal is None or goal.target is None:
            return (0.0, 0.0)
        command = (
            self._undock_cycle(goal, now, pose, collides)
            if goal.undock
            else (self._dock_cycle(goal, now, pose, collides))
        )
        if goal.outcome is not None:
            self.active = None
            return (0.0, 0.0)
        return command

    # -- internals -------------------------------------------------------------------

    def _start(self, goal: DockingGoal) -> DockingGoal:
        previous = self.active
        if previous is not None:
            if previous.staging is not None and previous.staging.ending is None:
                self.standin.cancel(previous.staging)
            previous.end(Outcome.ABORTED, DockError.NONE, "preempted by a new goal", success=False)
        self.active = goal
        return goal

    def _plugin(self, dock_type: str) -> str | None:
        """findDockPlugin: the type asked for, or the only one when none is named."""
        if not dock_type:
            return DOCK_TYPES[0] if len(DOCK_TYPES) == 1 else None
        return dock_type if dock_type in DOCK_TYPES else None

    def _fail(self, goal: DockingGoal, code: DockError, text: str) -> None:
        goal.log = text
        goal.end(Outcome.ABORTED, code, text, success=False)
        if goal is self.active:
            self.active = None

    def _leave(self, goal: DockingGoal) -> None:
        """Nav2's callback returns without a result: ABORTED with the default result."""
        goal.end(Outcome.ABORTED, success=True)
        if goal is self.active:
            self.active = None

    def _near(self, robot: Pose2D, dock: Pose2D) -> bool:
        return robot.distance_to(dock) < self.params.docking_threshold

    def _watch_staging(self, goal: DockingGoal, now: float) -> None:
        task = goal.staging
        assert task is not None
        if task.ending is None:
            if now > goal.deadline:
                self.standin.cancel(task)
                self._fail(goal, DockError.FAILED_TO_STAGE, "Failed to navigate to staging pose")
            return
        goal.staging = None
        if task.ending.outcome is Outcome.SUCCEEDED:
            self._approach(goal, now)
        elif task.ending.outcome is Outcome.CANCELED:
            self._fail(
                goal, DockError.FAILED_TO_STAGE, "Navigation request to staging pose preempted."
            )
        else:
            self._fail(goal, DockError.FAILED_TO_STAGE, "Failed to navigate to staging pose")

    def _approach(self, goal: DockingGoal, now: float) -> None:
        assert goal.dock is not None
        goal.enter(DockState.INITIAL_PERCEPTION)  # the dock is where the file says
        goal.enter(DockState.CONTROLLING)
        goal.target = goal.dock.pose
        goal._approach_started = now

    def _dock_cycle(
        self, goal: DockingGoal, now: float, pose: Pose2D, collides: Collides
    ) -> tuple[float, float]:
        assert goal.target is not None and goal.dock is not None
        params = self.params
        if self._near(pose, goal.target):
            goal.enter(DockState.WAIT_FOR_CHARGE)  # docked is charging: no battery read
            self.docked_at, self.dock_type = goal.target, goal.dock.type
            goal.log = "Robot is charging!"
            goal.end(Outcome.SUCCEEDED, success=True)
            return (0.0, 0.0)
        if now - goal._approach_started > params.dock_approach_timeout:
            self._fail(
                goal,
                DockError.FAILED_TO_CONTROL,
                "Timed out approaching dock; dock nor charging (if applicable) detected",
            )
            return (0.0, 0.0)
        if self._blocked(pose, goal.target, collides, keep_clear=params.dock_collision_threshold):
            self._fail(goal, DockError.FAILED_TO_CONTROL, "Failed to get control")
            return (0.0, 0.0)
        return self._toward(pose, goal.target, backwards=False)

    def _undock_cycle(
        self, goal: DockingGoal, now: float, pose: Pose2D, collides: Collides
    ) -> tuple[float, float]:
        assert goal.target is not None
        params = self.params
        turn = math.remainder(goal.target.yaw - pose.yaw, math.tau)
        if (
            pose.distance_to(goal.target) < params.undock_linear_tolerance
            and abs(turn) < params.undock_angular_tolerance
        ):
            self.docked_at, self.dock_type = None, ""
            goal.log = "Robot has undocked!"
            goal.end(Outcome.SUCCEEDED, success=True)
            return (0.0, 0.0)
        if now > goal.deadline:
            self._fail(goal, DockError.FAILED_TO_CONTROL, "Undocking timed out")
            return (0.0, 0.0)
        if self._blocked(pose, goal.target, collides, keep_clear=0.0):
            self._fail(goal, DockError.FAILED_TO_CONTROL, "Failed to get control")
            return (0.0, 0.0)
        return self._toward(pose, goal.target, backwards=True)

    def _toward(self, pose: Pose2D, target: Pose2D, *, backwards: bool) -> tuple[float, float]:
        """Drive at the controller's speed toward ``target``, turning the robot's front
        (or back) to it; slower near it so that the last step does not overshoot."""
        params = self.params
        distance = pose.distance_to(target)
        bearing = math.atan2(target.y - pose.y, target.x - pose.x)
        facing = pose.yaw + (math.pi if backwards else 0.0)
        error = math.remainder(bearing - facing, math.tau)
        w = max(
            -params.max_angular_speed, min(params.max_angular_speed, params.heading_gain * error)
        )
        speed = min(params.linear_speed, distance) * max(0.0, math.cos(error))
        return (-speed if backwards else speed, w)

    def _blocked(
        self, pose: Pose2D, target: Pose2D, collides: Collides, *, keep_clear: float
    ) -> bool:
        """Whether the footprint collides on the straight way to ``target``, short of the
        last ``keep_clear`` metres (Nav2 ignores collisions that close to the dock)."""
        distance = pose.distance_to(target)
        steps = int((distance - keep_clear) / 0.05)
        for index in range(1, steps + 1):
            along = index * 0.05 / distance
            point = Pose2D(
                pose.x + (target.x - pose.x) * along,
                pose.y + (target.y - pose.y) * along,
                pose.yaw,
            )
            if collides(point):
                return True
        return False


__all__ = [
    "DockError",
    "DockState",
    "DockingGoal",
    "DockingParams",
    "DockingServer",
    "PoseFilter",
    "Sighting",
]
