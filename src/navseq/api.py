"""navseq's Python API: load, build and check a mission, run it, read the result.

Everything here is exported by :mod:`navseq` itself (``import navseq``) and calls the
same core functions as the ``navseq`` command line, so a mission behaves the same
whichever face runs it. See ``docs/api.md`` for examples.

Units are in the names: ``yaw_deg`` / ``yaw_rad``, ``_s`` seconds, ``_m`` metres;
``x`` and ``y`` are metres in the mission's frame. Input problems raise
:class:`~navseq.errors.NavseqError` (several at once: :class:`~navseq.errors.MissionErrors`,
whose ``errors`` lists them); the ``check_*`` / ``validate_*`` functions return them
as a list of :class:`Problem` instead.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Generator, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from navseq.errors import MissionErrors, NavseqError
from navseq.executor.events import MissionEvent
from navseq.executor.result import MissionResult
from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.mission.robot import RobotProfile

if TYPE_CHECKING:
    from navseq.navigators.base import Navigator
    from navseq.navigators.sim import SimNavigator
    from navseq.run import RunRequest, UseNavigator

#: A path given as text or as a :class:`~pathlib.Path`.
PathLike = str | os.PathLike[str]
#: A robot: a profile, a built-in name (``"turtlebot3_waffle"``) or a robot YAML file.
RobotLike = RobotProfile | str
#: Called with every mission event as it happens.
EventCallback = Callable[[MissionEvent], object]


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a mission, as ``navseq validate`` lists it.

    ``where`` is the place (``"mission.yaml:12"``, ``"param ~p_seq"``), ``subject``
    what it concerns (``"waypoint 3 'dock'"``), ``message`` what is wrong and how to
    fix it; ``str(problem)`` is the one line the CLI prints.
    """

    message: str
    where: str | None = None
    subject: str | None = None

    @classmethod
    def from_error(cls, error: NavseqError) -> Problem:
        return cls(error.message, error.source, error.subject)

    def __str__(self) -> str:
        return str(NavseqError(self.message, source=self.where, subject=self.subject))


def _problems(errors: list[NavseqError]) -> list[Problem]:
    found: list[Problem] = []
    for error in errors:
        if isinstance(error, MissionErrors):
            found += _problems(error.errors)
        else:
            found.append(Problem.from_error(error))
    return found


def load_mission(path: PathLike) -> Mission:
    """Read a mission file: navseq YAML, rosparam YAML, a roslaunch file, or CSV.

    Raises :class:`~navseq.errors.NavseqError` naming the file, line and field of
    every problem (:class:`~navseq.errors.MissionErrors` when there are several).
    """
    from navseq.files import require_file
    from navseq.mission.loader import load_mission as load

    path = Path(path)
    require_file(path, "mission")
    return load(path)


def validate_file(
    path: PathLike,
    *,
    map: PathLike | None = None,
    start: Pose2D | None = None,
    robot: RobotLike | None = None,
) -> list[Problem]:
    """Every problem of a mission file, as ``navseq validate`` finds them; [] if none.

    The file's own problems and, when a map is known (``map``, else the mission's
    ``map:``), each waypoint checked against it for ``robot`` (default: the mission's
    ``robot:``, else the TurtleBot3 burger). ``start`` (default: the mission's
    ``start:``) is checked too.
    """
    from navseq.commands.validate import mission_file_problems
    from navseq.files import require_file

    try:
        require_file(Path(path), "mission")
    except NavseqError as error:
        return [Problem.from_error(error)]
    _, errors = mission_file_problems(
        Path(path),
        map_path=Path(map) if map is not None else None,
        start=start,
        robot=robot,
    )
    return _problems(errors)


def check_mission(
    mission: Mission,
    *,
    map: PathLike | None = None,
    start: Pose2D | None = None,
    robot: RobotLike | None = None,
) -> list[Problem]:
    """Pre-flight: every waypoint of ``mission`` checked against a map; [] if all is well.

    ``map`` defaults to the mission's ``map:``; with neither there is nothing to check.
    A waypoint outside the map, in an obstacle, where the robot's footprint does not
    fit, or that cannot be reached from the one before is a problem. ``robot`` and
    ``start`` default to the mission's.
    """
    from navseq.commands.common import costmap_for_map, preflight_errors
    from navseq.mission.robot_format import choose_robot

    map_path = Path(map) if map is not None else mission.map
    if map_path is None:
        return []
    profile = choose_robot(robot, mission)
    try:
        from navseq.sim.filters import costmap_with_filters

        costmap = costmap_with_filters(costmap_for_map(map_path, profile), mission.filters)
    except NavseqError as error:
        return _problems([error])
    start = start if start is not None else mission.start
    return _problems(preflight_errors(mission, costmap, start, robot=profile))


def order_waypoints(
    mission: Mission,
    *,
    map: PathLike | None = None,
    robot: RobotLike | None = None,
    keep_last: bool = False,
    time_limit_s: float = 2.0,
) -> Mission:
    """``mission`` with its waypoints in the order the robot drives in the least time
    (turns at the waypoints included), as ``navseq plan --order shortest`` finds it;
    every other setting as it was.

    Lengths are the paths planned on ``map`` (default: the mission's ``map:``) for
    ``robot``, or straight lines without a map. The start pose, else waypoint 1, stays
    first; a patrol stays a closed tour; ``keep_last`` keeps the last waypoint last. The
    solver searches for ``time_limit_s``; an order no shorter than the mission's own
    leaves it as it is.
    """
    from navseq.commands.common import legs_on_map
    from navseq.mission.robot_format import choose_robot
    from navseq.route.order import shortest_order

    map_path = Path(map) if map is not None else mission.map
    profile = choose_robot(robot, mission)
    legs = legs_on_map(map_path, profile, filters=mission.filters)
    ordering = shortest_order(mission, legs, time_limit_s, keep_last=keep_last, robot=profile)
    return ordering.apply(mission)


def _no_files_request(
    mission: Mission,
    *,
    navigator: UseNavigator | None = None,
    map: PathLike | None = None,
    start: Pose2D | None = None,
    robot: RobotLike | None = None,
    preflight: bool = True,
    server_wait_s: float = 10.0,
) -> RunRequest:
    """The run service's request for a run of the API's: it writes no files."""
    from navseq.run import RunRequest

    return RunRequest(
        mission=mission,
        navigator=navigator,
        map=Path(map) if map is not None else None,
        start=start,
        robot=robot,
        preflight=preflight,
        outputs=None,
        server_wait=server_wait_s,
    )


def sim_navigator(
    mission: Mission,
    *,
    map: PathLike | None = None,
    start: Pose2D | None = None,
    robot: RobotLike | None = None,
    preflight: bool = True,
) -> SimNavigator:
    """A navigator on the embedded simulator, ready for ``mission``.

    ``map`` (default: the mission's ``map:``) is required. ``start`` (default: the
    mission's ``start:``, else the roomy point nearest the map origin) is where the
    simulated robot begins. With ``preflight`` (as ``navseq run`` does) the mission is
    checked against the map first and every problem is raised together as
    :class:`~navseq.errors.MissionErrors` before anything moves.
    """
    from navseq.navigators.sim import SimNavigator
    from navseq.run import prepare

    request = _no_files_request(mission, map=map, start=start, robot=robot, preflight=preflight)
    navigator = prepare(request).make_navigator()
    assert isinstance(navigator, SimNavigator)
    return navigator


def _run_in_service(request: RunRequest, on_event: EventCallback | None) -> MissionResult:
    """Prepare and run ``request`` with the process's signal handling (the main thread's:
    SIGINT, SIGTERM and SIGHUP stop the robot, then raise MissionInterrupted)."""
    from navseq.executor.runner import MissionInterrupted
    from navseq.run import prepare
    from navseq.signals import SignalGuard

    session = prepare(request)
    listeners = [] if on_event is None else [_EventCallback(on_event)]
    guard = SignalGuard()
    try:
        outcome = session.run(listeners, signals=guard)
    finally:
        guard.restore()
    if outcome.interrupted is not None:
        raise MissionInterrupted(outcome.interrupted, outcome.result)
    if outcome.stopped_by is not None:
        raise outcome.stopped_by
    return outcome.result


class _EventCallback:
    """A mission listener calling the user's ``on_event`` (whatever it returns)."""

    def __init__(self, on_event: EventCallback) -> None:
        self.on_event = on_event

    def __call__(self, event: MissionEvent) -> None:
        self.on_event(event)


def run_mission(
    mission: Mission,
    navigator: Navigator,
    *,
    on_event: EventCallback | None = None,
    robot: RobotLike | None = None,
    server_wait_s: float = 10.0,
) -> MissionResult:
    """Drive ``mission`` through ``navigator`` to the end and return its result.

    The loop ``navseq run`` runs: ``on_event`` gets every event as it happens. While
    it runs (in the main thread), SIGINT and SIGTERM stop the robot first and then
    raise :class:`~navseq.executor.runner.MissionInterrupted`, whose ``result`` says
    what was done; any other exception also cancels the active goal before it
    propagates. ``robot`` gives the arrival check's goal tolerance (default: the
    mission's ``robot:``). The navigator is not closed: call its ``close()``.
    """
    from navseq.run import UseNavigator

    given = UseNavigator(navigator, {"kind": type(navigator).__name__})
    # No pre-flight: the navigator is the caller's, and so is its map.
    request = _no_files_request(
        mission, navigator=given, robot=robot, preflight=False, server_wait_s=server_wait_s
    )
    return _run_in_service(request, on_event)


def simulate(
    mission: Mission,
    *,
    map: PathLike | None = None,
    start: Pose2D | None = None,
    robot: RobotLike | None = None,
    on_event: EventCallback | None = None,
    preflight: bool = True,
) -> MissionResult:
    """Run ``mission`` on the embedded simulator and return the result.

    The run service's run, as ``navseq run`` makes it: the same simulator, pre-flight
    check and executor, in simulated time (as fast as the CPU goes). Writes no files.
    """
    request = _no_files_request(mission, map=map, start=start, robot=robot, preflight=preflight)
    return _run_in_service(request, on_event)


class MissionRun:
    """A mission run as an iterator of its events, for a loop of your own.

    ::

        run = MissionRun(mission, navigator)
        for event in run:
            ...            # leaving the loop early (break) cancels the active goal
        print(run.result.success)

    Nothing moves until the iteration starts. No signal handlers are installed; an
    exception (Ctrl-C included) or a ``break`` cancels the goal the robot is driving
    to. :attr:`result` is the result once the loop has run to its end; it stays None
    when the loop was left early.
    """

    def __init__(
        self,
        mission: Mission,
        navigator: Navigator,
        *,
        robot: RobotLike | None = None,
        server_wait_s: float = 10.0,
    ) -> None:
        from navseq.mission.robot_format import choose_robot

        self.mission = mission
        self.navigator = navigator
        self.robot = choose_robot(robot, mission)
        self.server_wait_s = server_wait_s
        self.result: MissionResult | None = None
        self._events: Generator[MissionEvent, None, MissionResult] | None = None

    def __iter__(self) -> Iterator[MissionEvent]:
        from navseq.executor.runner import iter_mission

        if self._events is not None:
            raise RuntimeError("a MissionRun runs once; make a new one to run again")
        self._events = iter_mission(
            self.mission, self.navigator, robot=self.robot, server_wait=self.server_wait_s
        )
        try:
            self.result = yield from self._events
        finally:
            self._events.close()  # on break: cancels the goal (no-op once finished)
