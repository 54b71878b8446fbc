"""A mission run made ready (:func:`prepare`) and run with the sinks a face gives it.

:func:`prepare` reads and checks everything the :class:`~navseq.run.request.RunRequest`
names (mission, map, start pose, the journal to resume) and builds the navigator
through the registry, which runs the pre-flight check; any problem is a
:class:`~navseq.errors.NavseqError` (where and what) raised before the robot moves and
before anything is written. :meth:`Session.run` then runs the mission with the face's
listeners, the journal and the recorder, and writes the report and the picture even
when the run is interrupted; its :class:`~navseq.run.outcome.RunOutcome` says how it
ended and what was written.

A session keeps all its state to itself, so several may run at once in one process
(a fleet, the studio's worker thread). It installs signal handlers only when the face
hands it a :class:`~navseq.signals.SignalGuard` (the process's main thread: the CLI).
"""

from __future__ import annotations

import contextlib
import dataclasses
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.navigators.registry import (
    NavigatorDraft,
    NavigatorKind,
    NavigatorSetup,
    kind_of,
    settings_from,
)
from navseq.navigators.settings import with_defaults
from navseq.run.outcome import EXIT_OUTPUT_FAILED, RunOutcome
from navseq.run.request import Outputs, RunRequest, UseNavigator
from navseq.run.resume import DEFAULT_KIND, continue_as_journaled, known_kind, read_resume

if TYPE_CHECKING:
    from navseq.eta.live import EtaEstimator
    from navseq.eta.predict import MissionPrediction
    from navseq.executor.control import MissionControl
    from navseq.executor.machine import MissionListener
    from navseq.executor.result import MissionResult
    from navseq.executor.resume import ResumePoint
    from navseq.geometry import Pose2D
    from navseq.journal.writer import JournalState, JournalWriter
    from navseq.mission.model import Mission
    from navseq.mission.part import MissionPart
    from navseq.mission.robot import RobotProfile
    from navseq.navigators.base import Navigator
    from navseq.run.runlock import RunLock
    from navseq.signals import SignalGuard
    from navseq.sim.occupancy import OccupancyGrid
    from navseq.sinks.recorder import RunRecorder
    from navseq.sinks.recording.sink import RecordingSink
    from navseq.tasks.ros_port import RosTypes
    from navseq.tasks.runner import TaskRunner

#: Called with each note on the run (one line) at the moment a face should show it.
NoteSink = Callable[[str], None]


@dataclass
class Session:
    """Everything checked and ready: what to run, on what, and where to write.

    Made by :func:`prepare`; ``request`` is the request as the session settled it (a
    resume's journaled options filled in, the navigator's settings resolved).
    """

    request: RunRequest
    mission: Mission
    make_navigator: Callable[[], Navigator]
    navigator_info: dict[str, Any]
    # What pre-flight, the planner, the simulator and the arrival check assume.
    robot: RobotProfile
    mission_path: Path | None = None  # None: the request gave a Mission, not a file
    digest: str | None = None
    kind: NavigatorKind | None = None  # None: the face's own navigator (UseNavigator)
    start: Pose2D | None = None
    start_source: str | None = None  # where ``start`` came from: "--start", "mission start:"
    grid: OccupancyGrid | None = None
    map_path: Path | None = None
    resume: ResumePoint | None = None
    journal: Path | None = None  # the journal to append to when resuming
    history: JournalState | None = None  # what that journal held before resuming
    notes: list[str] = field(default_factory=list)
    run_options: dict[str, Any] = field(default_factory=dict)  # journaled for a resume
    part: MissionPart | None = None  # the waypoints run, when not all of them
    # Extra mission listeners the navigator's setup made (ROS markers and status).
    listeners: list[MissionListener] = field(default_factory=list)
    # Runs the waypoints' tasks; None: one made for the run from ``request.tasks``. A
    # face that confirms input tasks itself (the API, the studio) gives its own.
    task_runner: TaskRunner | None = None
    # A navigator is made ready for one run (a ROS connection is closed after it).
    _started: bool = field(default=False, init=False, repr=False)
    _eta: EtaEstimator | None = field(default=None, init=False, repr=False)
    _eta_made: bool = field(default=False, init=False, repr=False)

    @property
    def records(self) -> bool:
        """Whether the run is recorded as MCAP (``--record``, or the mission's ``record:``)."""
        outputs = self.request.outputs
        if outputs is None:
            return False
        return outputs.record if outputs.record is not None else self.mission.record

    @property
    def numbers(self) -> list[int] | None:
        """The run's waypoints' numbers in the mission file, when it runs a part of it."""
        return list(self.part.numbers) if self.part is not None else None

    def eta(self) -> EtaEstimator | None:
        """The run's ETA (made once, before the robot moves): the mission predicted on the
        session's map from its start, kept up to date by the run's events. None when it
        cannot be predicted (see the notes)."""
        if not self._eta_made:
            self._eta_made = True
            from navseq.eta.live import EtaEstimator
            from navseq.eta.predict import predict_on_map

            try:
                prediction = predict_on_map(self.mission, self.grid, self.robot, self.start)
            except Exception as error:  # an ETA is never worth a run
                self.notes.append(f"no ETA for this run: {error}")
            else:
                from_pose = None
                if self.start is None:  # counted from the robot's first pose instead

                    def from_pose(pose: Pose2D) -> MissionPrediction:
                        return predict_on_map(self.mission, self.grid, self.robot, pose)

                self._eta = EtaEstimator(prediction, from_pose)
        return self._eta

    def run(
        self,
        listeners: Iterable[MissionListener] = (),
        *,
        control: MissionControl | None = None,
        signals: SignalGuard | None = None,
        on_note: NoteSink | None = None,
    ) -> RunOutcome:
        """Run the mission once; the outputs asked for are written however it ends.

        ``listeners`` get every mission event (a listener that is a context manager is
        entered just before the mission starts and left when it ends). ``control``
        carries operator requests from other threads (stop, pause, skip). ``signals``
        is the face's guard: armed while the robot moves, deferring from then on (the
        face restores it); without one no signal handler is touched. ``on_note`` gets
        the run's notes (what prepare settled, a lock taken over) before the robot
        moves. Raises NavseqError when the navigation server is not there or the
        folder is another live run's, and whatever else stops the run before it has a
        result (a signal while connecting); see :class:`RunOutcome` for the rest.
        """
        from navseq.signals import SignalGuard

        if self._started:
            raise RuntimeError("a Session runs once: prepare a new one to run again")
        self._started = True
        guard = signals if signals is not None else SignalGuard(install=False)
        say = on_note if on_note is not None else _ignore
        face = list(listeners)
        outputs = self.request.outputs
        if outputs is None:
            for note in self.notes:
                say(note)
            ran = self._drive(face, control, guard, lambda: None, None, say, None)
            return RunOutcome(
                ran.result,
                ran.exit_status,
                ran.interrupted,
                error=ran.error,
                stopped_by=ran.error,
                clock=ran.clock,
            )
        from navseq.run.files import remove_stale_temporaries
        from navseq.run.runlock import RunLock

        folder, created = self._output_folder(outputs)
        # One live run per folder: a second resume of the same journal is refused here,
        # before it writes anything or moves the robot.
        lock = RunLock(folder).acquire()
        try:
            remove_stale_temporaries(folder)  # of a run killed while it wrote its outputs
            return self._run_locked(face, control, guard, say, outputs, folder, lock)
        finally:
            lock.release()
            if created:
                _remove_if_unused(folder)

    # -- internals -----------------------------------------------------------------------

    def _output_folder(self, outputs: Outputs) -> tuple[Path, bool]:
        """The folder to write into, and whether this run created it."""
        from navseq.run.folder import create_run_folder, default_run_folder

        if outputs.folder is not None:
            existed = outputs.folder.exists()
            return create_run_folder(outputs.folder, fresh=False), not existed
        if self.journal is not None:  # a resumed run writes beside its journal
            return create_run_folder(self.journal.parent, fresh=False), False
        stem = self.mission_path.stem if self.mission_path is not None else "mission"
        return create_run_folder(default_run_folder(stem), fresh=True), True

    def _run_locked(
        self,
        face: list[MissionListener],
        control: MissionControl | None,
        guard: SignalGuard,
        say: NoteSink,
        outputs: Outputs,
        folder: Path,
        lock: RunLock,
    ) -> RunOutcome:
        from navseq.run.files import RunFiles, outputs_error, write_outputs
        from navseq.run.folder import reserve_file
        from navseq.run.products import import_picture_modules

        notes = list(self.notes)
        if lock.took_over is not None:
            notes.append(
                f"took over the lock of process {lock.took_over}, which is no longer running"
            )
        journal_path: Path | None = None
        if outputs.journal:
            # Resuming appends to the run's own journal; a new run starts a new one.
            journal_path = self.journal or reserve_file(folder, "journal.jsonl")
        fresh: JournalWriter | None = None
        recording = self._new_recording(outputs, folder)
        if recording is not None:
            face = [*face, recording]
        try:
            # A new journal gets its header at once, before the slow steps (the picture's
            # imports, the navigator's connection): a run killed during them used to
            # leave an empty journal, which neither a resume nor navseq report can read.
            if journal_path is not None and self.journal is None:
                fresh = self._new_journal(journal_path)
            for note in notes:
                say(note)
            if outputs.picture is not False:
                import_picture_modules()
            ran = self._drive(
                face,
                control,
                guard,
                # A resumed journal is continued once the navigator is there: a stack that
                # does not answer leaves the journal as it was.
                lambda: fresh if fresh is not None else self._continued_journal(journal_path),
                self._new_recorder(),
                say,
                folder,
            )
        except BaseException:
            # No result to report (e.g. no navigation server, or a signal before the run
            # began): leave no journal of nothing behind.
            if fresh is not None:
                fresh.close()
            if journal_path is not None and self.journal is None:
                _discard_unused(journal_path)
            if recording is not None and not recording.began:
                _discard_unused_recording(recording.path)
            raise
        files = RunFiles(paths={} if journal_path is None else {"journal": str(journal_path)})
        if recording is not None:
            if recording.error is None:
                files.paths["recording"] = str(recording.path)
            else:
                files.failed["recording"] = recording.error
        exit_status = write_outputs(
            folder,
            files,
            self._report_builder(ran) if outputs.report else None,
            None if outputs.picture is False else lambda: self._picture(ran),
            guard,
            ran.exit_status,
        )
        failure = outputs_error(files, folder, journal_path, exit_status)
        error = ran.error
        if error is None and failure is not None:
            error = NavseqError(failure)
        return RunOutcome(
            ran.result,
            exit_status,
            ran.interrupted,
            folder=folder,
            files=files,
            error=error,
            stopped_by=ran.error,
            clock=ran.clock,
        )

    def _new_recording(self, outputs: Outputs, folder: Path) -> RecordingSink | None:
        """The run's MCAP recording if one is asked for: ``run.mcap``, or the first free
        ``run-N.mcap`` (a resumed run records beside the first file)."""
        from navseq.run.folder import reserve_file
        from navseq.sinks.recording.sink import RecordingSink

        if not self.records:
            return None
        metadata = None
        if self.mission_path is not None and self.digest is not None:
            import datetime

            from navseq.sinks.recording.reading import run_metadata

            metadata = run_metadata(
                str(self.mission_path.resolve()),
                self.digest,
                datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                self.run_options,
            )
        return RecordingSink(
            reserve_file(folder, "run.mcap"),
            "ros1" if outputs.record_format == "ros1" else "ros2",
            self.mission,
            self.grid,
            numbers=self.numbers,
            run_metadata=metadata,
            published_topics=outputs.record_topics,
        )

    def _new_journal(self, journal_path: Path) -> JournalWriter:
        """A new run's journal, its header written."""
        from navseq.journal.writer import JournalWriter

        assert self.mission_path is not None and self.digest is not None  # RunRequest's rule
        # The absolute path, so that a resume works from any directory.
        source = str(self.mission_path.resolve())
        return JournalWriter(journal_path, source, self.digest, run_options=self.run_options)

    def _continued_journal(self, journal_path: Path | None) -> JournalWriter | None:
        from navseq.journal.writer import JournalWriter

        if journal_path is None or self.resume is None:
            return None
        return JournalWriter.resume(journal_path, self.resume, history=self.history)

    def _new_recorder(self) -> RunRecorder:
        """The run's recorder; a resumed run's starts with what its journal recorded.

        So the picture of a resumed run shows the whole mission: the path driven and the
        legs planned before the resume too, in one mission-time colouring.
        """
        from navseq.sinks.recorder import RunRecorder

        if self.history is None:
            return RunRecorder()
        return self.history.recorder  # what reading the journal replayed into it

    def _drive(
        self,
        face: list[MissionListener],
        control: MissionControl | None,
        guard: SignalGuard,
        open_journal: Callable[[], JournalWriter | None],
        recorder: RunRecorder | None,
        say: NoteSink,
        folder: Path | None,
    ) -> _Ran:
        """Run the mission; from the moment it ends, shutdown signals are only counted."""
        from navseq.executor.runner import MissionAborted, MissionInterrupted, run_mission
        from navseq.sinks.json_events import clock_record
        from navseq.tasks.ros_port import ros_port_of
        from navseq.tasks.runner import TaskRunner

        tasks = self.task_runner or TaskRunner(self.request.tasks, say=say)

        navigator = self.make_navigator()
        # ROS tasks on the navigator's own node; snapshots into the run folder (a
        # node's: the folder its parameters name).
        snapshots = self.request.tasks.snapshot_folder or folder
        tasks.attach(ros_port_of(navigator), snapshots, self._waypoint_name)
        error: NavseqError | None = None
        navigator_start, wall_start = navigator.now(), time.monotonic()
        try:
            journal = open_journal()
            # The ETA first: the face's sinks show the time to go the event leads to.
            eta = self.eta()
            mine = [sink for sink in (eta, journal, recorder) if sink is not None]
            _show_eta_on_status_topics([*face, *self.listeners], eta)
            with contextlib.ExitStack() as entered:
                for listener in face:
                    if isinstance(listener, contextlib.AbstractContextManager):
                        entered.enter_context(listener)
                if journal is not None:
                    entered.enter_context(journal)
                if self.records:  # its stack's topics, from now on (--record-topics)
                    from navseq.sinks.recording.sink import RecordingSink

                    for listener in face:
                        if isinstance(listener, RecordingSink):
                            listener.tap(navigator)
                try:
                    result = run_mission(
                        self.mission,
                        navigator,
                        [*mine, *face, *self.listeners],
                        resume=self.resume,
                        signals=guard,
                        robot=self.robot,
                        control=control,
                        tick=self.request.tick,
                        server_wait=self.request.server_wait,
                        tasks=tasks,
                    )
                    exit_status, interrupted = result.exit_code, None
                except MissionInterrupted as stop:
                    result, exit_status, interrupted = stop.result, stop.exit_code, stop.signal_name
                except MissionAborted as aborted:
                    # Stopped by an output that failed: report what happened, then exit 2.
                    result, exit_status, interrupted = aborted.result, EXIT_OUTPUT_FAILED, None
                    error = aborted
        finally:
            guard.defer()  # the goal is reached or cancelled: the report comes first now
            if self.kind is not None:  # a face's own navigator is closed by the face
                navigator.close()
        clock = clock_record(navigator.now() - navigator_start, time.monotonic() - wall_start)
        return _Ran(result, exit_status, interrupted, error, clock, navigator, recorder)

    def _waypoint_name(self, index: int) -> str | None:
        waypoints = self.mission.waypoints
        return waypoints[index].name if 0 <= index < len(waypoints) else None

    def _report_builder(self, ran: _Ran) -> Callable[[dict[str, str], int], dict[str, Any]]:
        from navseq.run.products import build_run_report

        def build(files: dict[str, str], exit_status: int) -> dict[str, Any]:
            return build_run_report(
                self,
                ran.result,
                files=files,
                exit_status=exit_status,
                interrupted=ran.interrupted,
                clock=ran.clock,
            )

        return build

    def _picture(self, ran: _Ran) -> bytes:
        from navseq.run.products import picture_png
        from navseq.sinks.recorder import RunRecorder

        recorder = ran.recorder if ran.recorder is not None else RunRecorder()
        return picture_png(self, ran.result, ran.navigator, recorder, ran.interrupted)


@dataclass(frozen=True)
class _Ran:
    """What driving the mission gave, before the outputs are written."""

    result: MissionResult
    exit_status: int
    interrupted: str | None
    error: NavseqError | None
    clock: dict[str, float | None]
    navigator: Navigator
    recorder: RunRecorder | None


def _show_eta_on_status_topics(listeners: list[MissionListener], eta: EtaEstimator | None) -> None:
    """The ROS status topics' progress messages carry the run's ETA."""
    from navseq.sinks.mission_status import StatusPublisher

    for listener in listeners:
        if isinstance(listener, StatusPublisher):
            listener.state.eta = eta


def _ignore(note: str) -> None:
    """A note nobody asked to see."""


def prepare(request: RunRequest) -> Session:
    """Read and check what ``request`` names, and make its navigator ready.

    Raises :class:`~navseq.errors.NavseqError` naming where and what on any problem (a
    mission file's line, ``--map``, the journal, the navigator's connection),
    :class:`~navseq.errors.MissionErrors` for pre-flight's problems, all at once, and
    :class:`~navseq.journal.state.NothingToResume` for a journal whose run is over.
    Nothing is written and nothing moves.
    """
    from navseq.files import require_file
    from navseq.journal.writer import mission_digest
    from navseq.mission import load_mission
    from navseq.mission.part import PartSpec
    from navseq.mission.robot_format import choose_robot
    from navseq.run.resume import run_options

    resume = history = None
    notes: list[str] = []
    start_given = request.start is not None  # by the request, not by a journal
    given_mission = request.mission
    mission_path = given_mission if isinstance(given_mission, Path) else None
    if request.resume is not None:
        mission_path, resume, history = read_resume(request.resume, mission_path)
        request, notes = continue_as_journaled(request, history)
    elif mission_path is not None:
        require_file(mission_path, "MISSION")
    if request.map is not None:
        require_file(request.map, "--map")
    request, kind = _settled_navigator(request)
    if kind is not None:
        _refuse_simulator_options(kind, request, start_given)
    if mission_path is not None:
        mission = load_mission(mission_path)
    else:
        assert given_mission is not None and not isinstance(given_mission, Path)
        mission = given_mission
    if request.loops is not None:
        loops = None if request.loops == "forever" else int(request.loops)
        mission = dataclasses.replace(mission, loops=loops)
    if request.filters is not None:
        mission = dataclasses.replace(mission, filters=request.filters)
    spec = PartSpec(request.first, request.last, request.only)
    part = None if spec.whole else spec.select(mission)
    if part is not None:
        mission = part.apply(mission)
    _refuse_tasks(mission, request, kind)
    _refuse_recoveries(mission, request, kind)
    if resume is not None:
        # Refuse a journal the mission cannot continue before anything is appended to it.
        from navseq.executor.machine import MissionExecutor
        from navseq.run.resume import refuse_another_datum

        assert history is not None
        refuse_another_datum(mission, history)

        MissionExecutor(mission, resume=resume)
    map_path = request.map if request.map is not None else mission.map
    start = request.start if request.start is not None else mission.start
    start_source = (
        "--start" if request.start is not None else "mission start:" if start is not None else None
    )
    draft = NavigatorDraft(
        mission=mission,
        map_path=map_path,
        start=start,
        start_source=start_source,
        robot=choose_robot(request.robot, mission),
        preflight=request.preflight,
        numbers=part.numbers if part is not None else None,
        realtime=request.realtime,
        robot_given=request.robot is not None or mission.robot is not None,
    )
    _check_recording(request.outputs, kind, mission)
    made = _navigator_setup(request, kind, draft)
    mission = draft.mission  # a kind may settle it (GPS waypoints through the stack's fromLL)
    session = Session(
        request=request,
        mission=mission,
        make_navigator=made.make_navigator,
        navigator_info=made.info,
        robot=draft.robot,
        mission_path=mission_path,
        digest=mission_digest(mission_path) if mission_path is not None else None,
        kind=kind,
        start=draft.start,
        start_source=draft.start_source,
        grid=made.grid,
        map_path=map_path,
        resume=resume,
        journal=request.resume,
        history=history,
        notes=[*notes, *made.notes],
        listeners=made.listeners,
        part=part,
    )
    if kind is not None:
        session.run_options = run_options(request, kind, mission, map_path, draft.start)
    return session


def _check_recording(
    outputs: Outputs | None, kind_of_run: NavigatorKind | None, mission: Mission
) -> None:
    """A recording that cannot be made (no mcap, ``--record-topics`` where it cannot
    work) is refused before the navigator connects and before anything is written."""
    if outputs is None:
        return
    records = outputs.record if outputs.record is not None else mission.record
    if records:
        from navseq.extras import require_extra

        require_extra("record", "recording the run (--record)")
    if not outputs.record_topics:
        return
    if not records:
        raise NavseqError("adds topics to a recording: add --record", source="--record-topics")
    kind = kind_of_run.name if kind_of_run is not None else "a face's own navigator"
    # Each stack's messages are recorded as published: in its own ROS's encoding.
    encodings = {"ros1": "ros1", "nav2": "ros2"}
    if kind not in encodings:
        raise NavseqError(
            "records a ROS navigation stack's topics as it publishes them, with "
            f"--navigator ros1 or nav2 only (not {kind}); the map, pose, odometry, /tf and "
            "plans are recorded with any navigator",
            source="--record-topics",
        )
    if (outputs.record_format or "ros2") != encodings[kind]:
        ros = "ROS 1" if kind == "ros1" else "ROS 2"
        raise NavseqError(
            f"records the {ros} stack's messages as they are published: add "
            f"--record-format {encodings[kind]}",
            source="--record-topics",
        )


def _settled_navigator(request: RunRequest) -> tuple[RunRequest, NavigatorKind | None]:
    """``request`` with its navigator's settings resolved, and their kind (None: the
    face's own navigator)."""
    navigator = request.navigator
    if isinstance(navigator, UseNavigator):
        return request, None
    if navigator is None:
        kind = known_kind(DEFAULT_KIND)
        navigator = settings_from(kind, dict(request.navigator_options))
    else:
        try:
            kind = kind_of(navigator)
        except KeyError:
            raise NavseqError(
                f"{type(navigator).__name__} are no navigator kind's settings",
                source="RunRequest.navigator",
            ) from None
    settled = dataclasses.replace(request, navigator=with_defaults(navigator))
    return settled, kind


def _refuse_simulator_options(kind: NavigatorKind, request: RunRequest, start_given: bool) -> None:
    """Options that only the embedded simulator can honour, refused for a real robot."""
    if not kind.places_robot and start_given:
        raise NavseqError(
            f"sets the simulated robot's start pose; with --navigator {kind.name} the "
            "robot is where it is. Leave --start out (set a robot's pose with RViz's 2D Pose "
            "Estimate, which publishes /initialpose)",
            source="--start",
        )
    if not kind.paced and request.realtime is not None:
        raise NavseqError(
            f"paces the embedded simulator; --navigator {kind.name} keeps its own "
            "time. Leave --realtime out",
            source="--realtime",
        )


def _refuse_tasks(mission: Mission, request: RunRequest, kind: NavigatorKind | None) -> None:
    """Tasks this run may not start (a program without --allow-run, a ROS task where
    there is no ROS), every one with its file:line, before anything moves."""
    from navseq.errors import MissionErrors
    from navseq.tasks.permissions import task_problems
    from navseq.tasks.ros_port import ros_port_of

    types: RosTypes | None
    if isinstance(request.navigator, UseNavigator):
        name, simulated = str(request.navigator.info["kind"]), False
        types = ros_port_of(request.navigator.navigator)
    else:
        assert kind is not None
        name, simulated = kind.name, not kind.ros
        types = kind.ros_types() if kind.ros else None
    problems = task_problems(
        mission,
        request.tasks,
        name,
        simulated=simulated,
        types=types,
        has_folder=request.outputs is not None or request.tasks.snapshot_folder is not None,
    )
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise MissionErrors(problems)


def _refuse_recoveries(mission: Mission, request: RunRequest, kind: NavigatorKind | None) -> None:
    """Recoveries the navigator cannot run (spin on move_base), each with its file:line,
    before anything moves."""
    from navseq.errors import MissionErrors
    from navseq.mission.recovery import RECOVERY_KINDS
    from navseq.navigators.base import RecoveryRunner
    from navseq.navigators.recovery_check import recovery_problems

    if isinstance(request.navigator, UseNavigator):
        name = str(request.navigator.info["kind"])
        given = request.navigator.navigator
        runs = isinstance(given, RecoveryRunner)
        # A navigator that runs only some kinds says which (the ros1 one: wait, clear).
        every = frozenset(RECOVERY_KINDS) if runs else frozenset()
        supported: frozenset[str] = frozenset(getattr(given, "recovery_kinds", every))
    else:
        assert kind is not None
        name, supported = kind.name, kind.recoveries
    problems = recovery_problems(mission, name, supported)
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise MissionErrors(problems)


def _navigator_setup(
    request: RunRequest, kind: NavigatorKind | None, draft: NavigatorDraft
) -> NavigatorSetup:
    navigator = request.navigator
    if kind is not None:
        assert navigator is not None and not isinstance(navigator, UseNavigator)
        return kind.create(navigator, draft)
    assert isinstance(navigator, UseNavigator)
    grid = navigator.grid
    if grid is not None:
        draft.check_map(grid)
    elif draft.preflight:  # without pre-flight the face's map is the face's business
        grid = draft.optional_map()
    given = navigator.navigator
    return NavigatorSetup(make_navigator=lambda: given, info=dict(navigator.info), grid=grid)


def _discard_unused(journal: Path) -> None:
    """Remove a journal that holds only its header."""
    try:
        if journal.exists() and len(journal.read_bytes().splitlines()) <= 1:
            journal.unlink()
    except OSError:
        pass  # tidying up only; the original error matters more


def _discard_unused_recording(path: Path) -> None:
    """Remove a recording of no event: the run did not start (no navigation server)."""
    with contextlib.suppress(OSError):  # tidying up only; the original error matters more
        path.unlink()


def _remove_if_unused(folder: Path) -> None:
    """Remove a folder this run created if nothing but its released lock is in it."""
    from navseq.run.runlock import LOCK_NAME

    try:
        if {entry.name for entry in folder.iterdir()} <= {LOCK_NAME}:
            (folder / LOCK_NAME).unlink(missing_ok=True)
            folder.rmdir()
    except OSError:
        pass  # tidying up only


__all__ = ["NoteSink", "Session", "prepare"]
