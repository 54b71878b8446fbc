"""The studio's HTTP API (documented in docs/studio.md) and its static page.

Every handler translates JSON to a call of navseq's core and back: the mission loader
and writer, ``navseq validate``'s :func:`~navseq.commands.validate.mission_file_problems`,
the planner, ``navseq run``'s setup and outputs. Bad input of any kind — bad JSON, a
body too big, a mission with problems, a path outside the studio's folders — is a
4xx answer carrying the same messages as the CLI; the server keeps serving.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import os
import threading
from collections import OrderedDict
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response, StreamingResponse
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from navseq.errors import NavseqError
from navseq.eta.incremental import IncrementalPrediction
from navseq.eta.memo import RememberedDrives
from navseq.executor.control import operator_reason
from navseq.extras import MissingExtra
from navseq.route.legs import LegPlanner, Legs, legs_after_edit, legs_of, route_summary
from navseq.studio.documents import (
    UNITS,
    CheckedDraft,
    check_draft,
    document_of,
    empty_document,
    not_a_navseq_mission,
    open_document,
    problems_of,
    version_of,
)
from navseq.studio.edits import (
    LastCheck,
    changed_legs,
    checked_after_edit,
    edited_document,
    edited_mission,
    legs_touching,
    moved_among,
    moved_waypoints,
)
from navseq.studio.http import LIVE_PERIOD_S, MAX_REALTIME, ApiError, Handler, api, read_json
from navseq.studio.http import MAX_BODY_BYTES as MAX_BODY_BYTES  # where tests look for it
from navseq.studio.mapview import MapView
from navseq.studio.ordering import OrderFailed, OrderJob, OrderJobs
from navseq.studio.security import (
    COOKIE_NAME,
    LOCAL_NAMES,
    RESPONSE_HEADERS,
    TOKEN_HEADER,
    FileRoots,
    host_allowed,
    token_matches,
)
from navseq.tasks.options import DEFAULT_SIMULATED_SECONDS, TaskOptions
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.mission.costmap_filters import CostmapFilter
    from navseq.mission.model import Mission
    from navseq.mission.robot import RobotProfile
    from navseq.route.order import OrderProgress
    from navseq.sim.costmap import Costmap
    from navseq.studio.runs import StudioRun

STATIC = Path(__file__).parent / "static"
#: What the page offers to import: every format navseq's loader reads.
MISSION_SUFFIXES = (".yaml", ".yml", ".launch", ".xml", ".csv")
#: Files listed at most for the import choice.
MAX_FILES_LISTED = 500
#: Check answers kept for drafts seen again (the opened mission on each page load, undo).
CHECK_ANSWERS_KEPT = 16
#: A check's answer as kept: the draft's robot, the answer, what an edit is checked from.
Kept = tuple["RobotProfile | None", dict[str, Any], LastCheck | None]
#: How much lower the warm-up's check runs than the page's requests (a nice value).
WARM_UP_NICENESS = 10
#: Seconds ``navseq studio``'s warm-up waits for the page's own first check.
WARM_UP_WAIT_FOR_PAGE_S = 3.0
#: Seconds the route solver searches for the page's "shortest order" (a click, not a batch).
ORDER_TIME_LIMIT_S = 1.0
#: ... or less: it stops once it found no better order for this long (on the bench's
#: missions of 100 to 200 waypoints its last better order came within 0.1 to 0.4 s of
#: a 1 s search, mostly in its first tenth: benchmarks/bench_route.py, docs/performance.md).
ORDER_SETTLE_S = 0.25


@dataclass
class StudioConfig:
    """What ``navseq studio`` was started with."""

    token: str
    roots: FileRoots
    mission_path: Path | None = None  # the mission file opened (may not exist yet)
    map_path: Path | None = None  # --map
    out_base: Path = field(default_factory=Path.cwd)  # navseq-out/ goes here
    hosts: frozenset[str] = LOCAL_NAMES  # what a request's Host may say (allowed_hosts)
    allow_run: bool = False  # --allow-run: runs may start the mission's run: programs
    fleet_path: Path | None = None  # --fleet: the fleet file the page runs (studio/fleet_*.py)


class Studio:
    """The studio's state: the opened mission, loaded maps, the run."""

    def __init__(self, config: StudioConfig) -> None:
        self.config = config
        self.roots = config.roots
        self._maps: dict[Path, tuple[tuple[int, ...], MapView]] = {}
        self._planners: dict[tuple[Path, RobotProfile], LegPlanner] = {}
        self._lock = threading.Lock()
        self._save_lock = threading.Lock()
        self._check_lock = threading.Lock()
        self._load_lock = threading.Lock()  # one reading of a map file at a time
        self._open_lock = threading.Lock()  # one reading of the mission file at a time
        # The opened file's answer, by (path, SHA-256, --map): not to be changed by callers.
        self._opened: tuple[tuple[Path, str, str | None], dict[str, Any]] | None = None
        self._answers: OrderedDict[tuple[str, tuple[int, ...]], Kept] = OrderedDict()
        # The draft and legs of the last answers, by their "check" number: a page names
        # the one it holds, is sent only the legs that differ from it, and may send an
        # edit as the waypoints it changed in that draft.
        self._held: OrderedDict[int, tuple[Any, list[dict[str, Any]], Kept]] = OrderedDict()
        # The legs the last check was worked out from and the positions it planned again.
        self._replanned: tuple[list[dict[str, Any]], list[int]] | None = None
        self._checks = 0  # answers worked out, numbering them
        self.robot: RobotProfile | None = None  # the last checked draft's robot
        self._last_check: LastCheck | None = None  # an edit is checked from it
        self._drives: dict[RobotProfile, tuple[LegPlanner, RememberedDrives]] = {}
        self.edits_checked = 0  # checks worked out from the last one, for tests and benchmarks
        self.page_checked = threading.Event()  # a page asked for its first check
        self.order_jobs = OrderJobs()
        self.run: StudioRun | None = None
        from navseq.studio.fleet_runs import FleetDesk

        self.fleets = FleetDesk(config.fleet_path, config.out_base)  # fleet runs (fleet_api)

    # -- where things are --------------------------------------------------------------

    @property
    def base_dir(self) -> Path:
        """The mission's folder: relative paths in the mission start there."""
        return self.roots.base

    @property
    def shown_name(self) -> str:
        path = self.config.mission_path
        return printable(path.name) if path is not None else "new mission"

    def map_view(self, path: Path) -> MapView:
        """The map at ``path`` (checked against the roots by the caller), reloaded if changed."""
        stamp = map_stamp(path)
        with self._lock:
            cached = self._maps.get(path)
            if cached is not None and cached[0] == stamp:
                return cached[1]
        with self._load_lock:  # a second request for it waits and finds it read
            with self._lock:
                cached = self._maps.get(path)
            if cached is not None and cached[0] == stamp:
                return cached[1]
            view = MapView.load(path)
            with self._lock:
                self._maps[path] = (stamp, view)
        return view

    def costmap(self, map_path: Path, robot: RobotProfile) -> Costmap:
        """The map's costmap for ``robot``, built once per (map, robot) and kept.

        Inflating a 2000 x 2000 map takes about a second; a check after each edit
        would otherwise pay it every time. A changed map file is read again.
        """
        try:
            view = self.map_view(map_path)
        except OSError:
            from navseq.commands.common import costmap_for_map

            return costmap_for_map(map_path, robot)  # says what is wrong with the file
        return view.costmap(robot)

    def planner(self, map_path: Path, robot: RobotProfile) -> LegPlanner:
        view = self.map_view(map_path)
        with self._lock:
            planner = self._planners.get((map_path, robot))
            if planner is None or planner.costmap.grid is not view.grid:
                planner = LegPlanner(view.costmap(robot))
                self._planners[(map_path, robot)] = planner
            return planner

    # -- the API's work (run in a worker thread) ---------------------------------------

    def mission(self) -> dict[str, Any]:
        path = self.config.mission_path
        map_text = (
            self.roots.relative(self.config.map_path) if self.config.map_path is not None else None
        )
        if path is None or not path.exists():
            return {
                "name": self.shown_name,
                "path": self.roots.relative(path) if path is not None else None,
                "exists": False,
                "version": None,
                "units": UNITS,
                "mission": empty_document(map_text),
                "problems": [],
                "allow_run": self.config.allow_run,
            }
        version = version_of(path)
        # The file read once per content: a page load of a 5000-waypoint mission waited
        # half a second for the loader (every load, and the warm-up's beside the first).
        key = (path, version["sha256"], map_text)
        with self._open_lock:
            if self._opened is not None and self._opened[0] == key:
                return {**self._opened[1], "version": version}
            document, errors = open_document(path, self.base_dir)
            if document is None:
                raise ApiError(
                    422,
                    f"{self.shown_name} cannot be opened",
                    problems=[problem.as_json() for problem in problems_of(errors)],
                )
            if map_text is not None:
                document["map"] = map_text  # --map wins, as for navseq validate --map
            answer = {
                "name": self.shown_name,
                "path": self.roots.relative(path),
                "exists": True,
                "version": version,
                "units": UNITS,
                "mission": document,
                "problems": [problem.as_json() for problem in problems_of(errors)],
                "allow_run": self.config.allow_run,
            }
            self._opened = (key, answer)
            return answer

    def map_info(self, map_text: str | None) -> dict[str, Any]:
        path = self._map_path(map_text)
        view = self.map_view(path)
        return {"map": self.roots.relative(path), **view.info()}

    def map_image(self, map_text: str | None, layer: str) -> bytes:
        from navseq.mission.robot import DEFAULT_PROFILE

        if layer not in ("map", "costmap", "zones"):
            raise ApiError(400, f"unknown layer {printable(layer)!r}; map, costmap or zones")
        view = self.map_view(self._map_path(map_text))
        if layer == "zones":
            return view.zones_image(self._mission_filters())
        return view.image(layer, self.robot or DEFAULT_PROFILE)

    def _mission_filters(self) -> tuple[CostmapFilter, ...]:
        """The mission file's costmap filters (none for a new or unreadable mission)."""
        from navseq.mission import inspect_mission_file

        path = self.config.mission_path
        if path is None or not path.is_file():
            return ()
        mission, _ = inspect_mission_file(path)
        return mission.filters if mission is not None else ()

    def _map_path(self, map_text: str | None) -> Path:
        if map_text:
            path = self.roots.resolve(map_text, "map")
        elif self.config.map_path is not None:
            path = self.config.map_path
        else:
            raise ApiError(404, "no map: give the mission a map: or start the studio with --map")
        if not path.is_file():
            raise ApiError(404, f"no such map file: {printable(self.roots.relative(path))}")
        return path

    def check(self, document: Any, base: Any = None, changes: Any = None) -> dict[str, Any]:
        """Problems and planned legs of a draft (``POST /api/check``).

        One check at a time: a check that comes while another builds a costmap or plans
        legs waits for it and then finds them made, instead of doing the same work
        beside it on the same cores (the page's first check and :meth:`warm_up`).

        Each answer is numbered (``check``). ``base``: the number of an answer whose legs
        the caller holds; when it is one of the last ones, the answer carries only the
        legs that differ from it (``legs_changed``: ``[position, leg]`` pairs, with
        ``base``) instead of ``legs`` — a drag at 5000 waypoints changes two legs of 5000.
        ``changes`` (``[[index, waypoint], ...]``, instead of ``document``): the draft is
        that answer's with those waypoints in their places (a drag: one waypoint sent,
        not 5000); 409 (``conflict: "base"``) when the studio no longer holds that
        answer's draft, and the caller sends the whole draft.
        """
        with self._check_lock:
            numbered = isinstance(base, int) and not isinstance(base, bool)
            held = self._held.get(base) if numbered else None
            edit: tuple[dict[str, Any], set[int]] | None = None
            same: Kept | None = None
            if changes is not None:
                document, edit = self._edited_document(held, changes)
                assert held is not None
                old, new = held[0]["waypoints"], document["waypoints"]
                if all(old[index] == new[index] for index in edit[1]):
                    # Nothing changed (a waypoint dropped where it was): that answer again.
                    document, edit, same = held[0], None, held[2]
            # An edit sent as its changes is not looked up by its text (that text, 180 kB
            # at 5000 waypoints, would be written out for it).
            key = None if edit is not None or same is not None else self._answer_key(document)
            self._replanned = None
            if same is not None:
                self.robot, answer, self._last_check = same
            elif key is not None and key in self._answers:
                self._answers.move_to_end(key)
                self.robot, answer, self._last_check = self._answers[key]
            else:
                answer = self._check(document, edit)
                self._checks += 1
                answer["check"] = self._checks
                if key is not None:
                    self._answers[key] = (self.robot, answer, self._last_check)
                    while len(self._answers) > CHECK_ANSWERS_KEPT:
                        self._answers.popitem(last=False)
            kept = (self.robot, answer, self._last_check)
            self._held[answer["check"]] = (document, answer["legs"], kept)
            self._held.move_to_end(answer["check"])
            while len(self._held) > CHECK_ANSWERS_KEPT:
                self._held.popitem(last=False)
            if held is None or len(held[1]) != len(answer["legs"]):
                return answer
            delta = {name: value for name, value in answer.items() if name != "legs"}
            delta["base"] = base
            replanned = self._replanned
            among = replanned[1] if replanned is not None and replanned[0] is held[1] else None
            delta["legs_changed"] = changed_legs(held[1], answer["legs"], among)
            return delta

    @staticmethod
    def _edited_document(
        held: tuple[Any, list[dict[str, Any]], Kept] | None, changes: Any
    ) -> tuple[dict[str, Any], tuple[dict[str, Any], set[int]]]:
        """The draft an edit sent as its changes makes of the held draft ``held``, and
        (that draft, the indices changed)."""
        if held is None or not isinstance(held[0], dict):
            raise ApiError(
                409,
                "the studio no longer holds the draft these changes apply to: send the "
                "whole mission",
                conflict="base",
            )
        try:
            document, indices = edited_document(held[0], changes)
        except ValueError as error:
            raise ApiError(400, str(error)) from None
        return document, (held[0], indices)

    def page_check(self, document: Any, base: Any = None, changes: Any = None) -> dict[str, Any]:
        """:meth:`check` asked for by a page (:meth:`warm_up` waits for the first)."""
        self.page_checked.set()
        return self.check(document, base, changes)

    def _answer_key(self, document: Any) -> tuple[str, tuple[int, ...]] | None:
        """What a check's answer depends on: the draft and its map file's stamp.

        The page's first check sends the opened mission as it is, which the warm-up (or
        the previous page load) checked already: its answer is sent again instead of
        running the pre-flight once more (150 ms on a 2000 x 2000 map, before the
        legs are drawn). None (no keeping) when the map cannot be named or read.
        """
        if not isinstance(document, dict):
            return None
        map_value = document.get("map")
        stamp: tuple[int, ...] = ()
        try:
            if isinstance(map_value, str):
                stamp = map_stamp(self.roots.resolve(map_value, "map"))
            # Not sorted: the page sends its keys in one order (another only misses).
            text = json.dumps(document, allow_nan=True)
        except (NavseqError, OSError, TypeError, ValueError, RecursionError):
            return None
        return text, stamp

    def _checked(
        self,
        document: Any,
        *,
        base_dir: Path | None = None,
        shown_as: str | None = None,
        tasks: TaskOptions | None = None,
    ) -> CheckedDraft:
        """The draft checked as ``navseq validate --map`` checks a file (``tasks``: as
        ``navseq validate`` with those task options checks it)."""
        return check_draft(
            document,
            roots=self.roots,
            base_dir=base_dir if base_dir is not None else self.base_dir,
            shown_as=shown_as if shown_as is not None else self.shown_name,
            costmaps=self.costmap,
            tasks=tasks,
        )

    def _readable(self, document: Any, doing: str, **where: Any) -> tuple[CheckedDraft, Mission]:
        """The draft checked and its mission; refused (422, with its problems) when it
        cannot be read."""
        checked = self._checked(document, **where)
        if checked.mission is None:
            raise ApiError(
                422,
                f"the mission has problems that stop it being read; fix them before {doing}",
                problems=[problem.as_json() for problem in checked.problems],
            )
        return checked, checked.mission

    def _check(
        self, document: Any, edit: tuple[dict[str, Any], set[int]] | None = None
    ) -> dict[str, Any]:
        from navseq.commands.common import choose_robot

        last, moved, checked = self._checked_edit(document, edit)
        answer: dict[str, Any] = {
            "problems": [problem.as_json() for problem in checked.problems],
            "readable": checked.mission is not None,
            "legs": [],
            "total_length_m": None,
            "estimated_duration": "",
        }
        mission = checked.mission
        self._last_check = None
        if mission is None:
            return answer
        robot = choose_robot(None, mission)
        self.robot = robot
        answer["robot"] = robot.name
        if checked.map_path is not None and checked.map_path.is_file():
            try:
                planner = self.planner(checked.map_path, robot)
            except NavseqError:
                return answer  # the map's own problem is in the list already
            if moved is not None and last is not None:
                legs = self._legs_after_edit(last.legs, mission, planner, moved)
                eta = last.eta.after_edit(mission, moved)
            else:
                legs = legs_of(mission, planner)
                eta = IncrementalPrediction(mission, planner, self.drives(planner, robot))
            answer["legs"] = legs
            answer.update(route_summary(legs, robot))
            answer.update(_expected_duration(eta))
            if isinstance(document, dict):
                context = (map_stamp(checked.map_path), planner)
                self._last_check = LastCheck(document, checked, context, legs, eta)
        return answer

    def _legs_after_edit(
        self, legs: list[dict[str, Any]], mission: Mission, planner: Legs, moved: set[int]
    ) -> list[dict[str, Any]]:
        """``legs_after_edit``, planning only the legs at the places of the moved
        waypoints' (walking all 5000 legs to find them took 5–30 ms of a drag)."""
        positions = legs_touching(legs, moved, mission)
        if positions is None:
            return legs_after_edit(legs, mission, planner, moved)
        edited = list(legs)
        replanned = legs_after_edit([legs[p] for p in positions], mission, planner, moved)
        for position, leg in zip(positions, replanned, strict=True):
            edited[position] = leg
        self._replanned = (legs, positions)
        return edited

    def _checked_edit(
        self, document: Any, edit: tuple[dict[str, Any], set[int]] | None = None
    ) -> tuple[LastCheck | None, set[int] | None, CheckedDraft]:
        """The last check, and the draft checked from it when it only moved some
        waypoints (:mod:`navseq.studio.edits`: those waypoints), else checked whole (None
        for them). ``edit``: the draft ``document`` was made from and the waypoints
        changed in it (an edit sent as its changes): when that draft is the last
        check's, only those waypoints are compared."""
        from navseq.commands.common import choose_robot, preflight_errors

        last = self._last_check
        if last is None or last.checked.map_path is None:
            return last, None, self._checked(document)
        if edit is not None and edit[0] is last.document:
            moved = moved_among(last.document, document, edit[1])
        else:
            moved = moved_waypoints(last.document, document)
        if moved is None or not moved:
            return last, None, self._checked(document)
        map_path = last.checked.map_path
        try:
            stamp = map_stamp(map_path)
        except OSError:
            return last, None, self._checked(document)
        mission = edited_mission(last, document, moved)
        if mission is None:
            return last, None, self._checked(document)
        robot = choose_robot(None, mission)
        if (stamp, self.planner(map_path, robot)) != last.context:
            return last, None, self._checked(document)
        costmap = self.costmap(map_path, robot)
        errors = preflight_errors(mission, costmap, mission.start, None, robot)
        self.edits_checked += 1
        return last, moved, checked_after_edit(last, mission, errors, self.shown_name)

    def drives(self, planner: LegPlanner, robot: RobotProfile) -> RememberedDrives:
        """The legs driven on paper on ``planner``'s costmap for ``robot``, kept."""
        with self._lock:
            kept = self._drives.get(robot)
            if kept is None or kept[0] is not planner:
                kept = (planner, RememberedDrives.on(planner, robot))
                self._drives[robot] = kept
            return kept[1]

    def save(self, body: dict[str, Any]) -> dict[str, Any]:
        from navseq.mission.writer import write_mission

        document = body.get("mission")
        path_text = body.get("path")
        if path_text is None and self.config.mission_path is not None:
            target = self.config.mission_path
        else:
            if not isinstance(path_text, str):
                raise ApiError(400, "path: give the mission file's name (e.g. mission.yaml)")
            target = self.roots.resolve(path_text, "path")
        if target.suffix.lower() not in (".yaml", ".yml"):
            raise ApiError(422, "path: a navseq mission is saved as .yaml or .yml")
        checked, mission = self._readable(
            document, "saving", base_dir=target.parent, shown_as=printable(target.name)
        )
        overwrite = body.get("overwrite") is True
        expected = body.get("version")
        with self._save_lock:
            exists = target.exists()
            if exists:
                if not target.is_file():
                    raise ApiError(409, f"{printable(target.name)} is not a regular file")
                other = not_a_navseq_mission(target)
                if other is not None:
                    raise ApiError(
                        409,
                        f"{printable(target.name)} is {other}, not a navseq mission: saving "
                        "would replace it; nothing was written. Save under another name",
                        conflict="not a mission",
                    )
                current = version_of(target)
                if isinstance(expected, dict) and expected.get("sha256") != current["sha256"]:
                    raise ApiError(
                        409,
                        f"{printable(target.name)} changed on disk since it was opened (another "
                        "tab or program saved it); nothing was written. Reload it, or save "
                        "under another name",
                        conflict="changed",
                        version=current,
                    )
                if not overwrite:
                    raise ApiError(
                        409,
                        f"{printable(target.name)} exists; confirm to replace it",
                        conflict="exists",
                        version=current,
                    )
            kept = exists and _save_keeping_the_file(target, document, mission)
            if not kept:
                write_mission(mission, target, overwrite=exists)
            version = version_of(target)
        return {
            "path": self.roots.relative(target),
            "version": version,
            "problems": [problem.as_json() for problem in checked.problems],
            # True: only what changed was written (comments, order, numbers kept).
            "kept_formatting": kept,
        }

    # -- files: import, export -----------------------------------------------------------

    def files(self) -> dict[str, Any]:
        """Mission files the page may import (any format the loader reads), under the roots."""
        found: set[Path] = set()
        for folder in self.roots.folders:
            for depth in ("*", "*/*", "*/*/*"):
                for path in folder.glob(depth):
                    if (
                        path.suffix.lower() in MISSION_SUFFIXES
                        and "navseq-out" not in path.parts
                        and path.is_file()
                        and self.roots.contains(path)
                    ):
                        found.add(path.resolve())
                    if len(found) >= MAX_FILES_LISTED:
                        break
        return {"missions": sorted(self.roots.relative(path) for path in found)}

    def import_file(self, body: dict[str, Any]) -> dict[str, Any]:
        """A mission file of any format (navseq YAML, launch, rosparam YAML, CSV) as a
        document, for the page to take in place of its waypoints (an undoable edit)."""
        path = self._existing_file(body.get("path"), "path")
        document, errors = open_document(path, self.base_dir)
        problems = [problem.as_json() for problem in problems_of(errors)]
        if document is None:
            raise ApiError(
                422,
                f"{printable(path.name)} cannot be imported: it has problems",
                problems=problems,
            )
        return {"path": self.roots.relative(path), "mission": document, "problems": problems}

    def order(self, body: dict[str, Any]) -> dict[str, Any]:
        """The draft's shortest visiting order (``POST /api/order``), as ``navseq plan
        --order shortest`` finds it on the draft's map (straight lines without one)."""
        return self._ordering(*self._order_request(body))

    def start_order(self, body: dict[str, Any]) -> dict[str, Any]:
        """:meth:`order` as a job (``POST /api/order/jobs``): its progress and answer
        from :meth:`order_job`, stopped by :meth:`cancel_order`. A draft that cannot be
        read is refused at once (422, with its problems)."""
        checked, mission, keep_last = self._order_request(body)

        def work(progress: OrderProgress) -> dict[str, Any]:
            try:
                return self._ordering(checked, mission, keep_last, progress)
            except ApiError as error:  # told to the page as POST /api/order tells it
                raise OrderFailed(error.status, error.body) from error
            except MissingExtra as error:
                raise OrderFailed(501, {"error": str(error)}) from error
            except NavseqError as error:
                problems = [problem.as_json() for problem in problems_of([error])]
                raise OrderFailed(422, {"error": str(error), "problems": problems}) from error

        return self.order_jobs.start(work).view()

    def order_job(self, number: str) -> dict[str, Any]:
        """``GET /api/order/jobs/N``: how far the job got, and its answer once done."""
        return self._order_job(number).view()

    def cancel_order(self, number: str) -> dict[str, Any]:
        """``POST /api/order/jobs/N/cancel``: no search started after this one."""
        job = self._order_job(number)
        job.cancel()
        return job.view()

    def _order_job(self, number: str) -> OrderJob:
        job = self.order_jobs.get(int(number)) if number.isdigit() else None
        if job is None:
            raise ApiError(404, f"no order job {printable(number)}")
        return job

    def _order_request(self, body: dict[str, Any]) -> tuple[CheckedDraft, Mission, bool]:
        keep_last = body.get("keep_last", False)
        if not isinstance(keep_last, bool):
            raise ApiError(400, "keep_last: true or false")
        checked, mission = self._readable(body.get("mission"), "ordering")
        return checked, mission, keep_last

    def _ordering(
        self,
        checked: CheckedDraft,
        mission: Mission,
        keep_last: bool,
        progress: OrderProgress | None = None,
    ) -> dict[str, Any]:
        from navseq.commands.common import choose_robot
        from navseq.route.legs import StraightLegs, route_length
        from navseq.route.order import shortest_order

        robot = choose_robot(None, mission)
        legs: Legs = StraightLegs()
        if checked.map_path is not None and checked.map_path.is_file():
            legs = self.planner(checked.map_path, robot)
        ordering = shortest_order(
            mission,
            legs,
            ORDER_TIME_LIMIT_S,
            keep_last=keep_last,
            robot=robot,
            progress=progress,
            settle_s=ORDER_SETTLE_S,
        )
        return {
            "order": list(ordering.order),
            "length_m": route_length(legs_of(ordering.apply(mission), legs)),
            "length_before_m": route_length(legs_of(mission, legs)),
        }

    def export_launch(self, body: dict[str, Any]) -> dict[str, Any]:
        """The draft as the tutorial's launch file (``p_seq`` / ``yea_seq``)."""
        from navseq.mission.tutorial_export import write_tutorial_launch

        path_text = body.get("path")
        if not isinstance(path_text, str):
            raise ApiError(400, "path: give the launch file's name (e.g. move_base_seq.launch)")
        target = self.roots.resolve(path_text, "path")
        if target.suffix.lower() not in (".launch", ".xml"):
            raise ApiError(422, "path: the tutorial's launch file is saved as .launch or .xml")
        _, mission = self._readable(body.get("mission"), "exporting")
        with self._save_lock:
            exists = target.exists()
            if exists and body.get("overwrite") is not True:
                raise ApiError(
                    409,
                    f"{printable(target.name)} exists; confirm to replace it",
                    conflict="exists",
                )
            launch = write_tutorial_launch(mission, target, overwrite=exists)
        return {"path": self.roots.relative(target), "left_out": list(launch.left_out)}

    def _existing_file(self, text: Any, what: str) -> Path:
        if not isinstance(text, str):
            raise ApiError(400, f"{what}: give a file name")
        path = self.roots.resolve(text, what)
        if not path.is_file():
            raise ApiError(404, f"no such file: {printable(self.roots.relative(path))}")
        return path

    # -- past runs ---------------------------------------------------------------------

    @property
    def run_roots(self) -> FileRoots:
        """Where run folders may be read: the studio's folders and its navseq-out/."""
        return FileRoots(
            [*self.roots.folders, self.config.out_base / "navseq-out"], self.config.out_base
        )

    def runs(self) -> dict[str, Any]:
        from navseq.studio.fleet_replay import fleet_runs_listed
        from navseq.studio.replay import run_folders, run_summary

        roots = self.run_roots
        searched = [self.config.out_base / "navseq-out"]
        searched += [folder / "navseq-out" for folder in self.roots.folders]
        singles = [folder for folder in run_folders(searched) if roots.contains(folder)]
        # A fleet run is one entry; its robots' folders are not listed as runs of their own.
        fleets, singles = fleet_runs_listed(searched, singles, roots)
        runs = fleets + [run_summary(folder, roots.relative(folder)) for folder in singles]
        return {"runs": sorted(runs, key=lambda run: run["modified_s"], reverse=True)}

    def replay(self, folder_text: str | None) -> dict[str, Any]:
        from navseq.studio.replay import replay_of

        if not folder_text:
            raise ApiError(400, "folder: give a run folder (navseq-out/...)")
        roots = self.run_roots
        folder = roots.resolve(folder_text, "folder")
        if not folder.is_dir():
            raise ApiError(404, f"no such run folder: {printable(folder_text)}")
        return replay_of(folder, roots.relative(folder), self.base_dir, may_read=roots.contains)

    def start_run(self, body: dict[str, Any]) -> dict[str, Any]:
        from navseq.studio.runs import StudioRun, StudioRunOrder

        realtime = body.get("realtime")
        if realtime is not None and not (
            isinstance(realtime, int | float)
            and not isinstance(realtime, bool)
            and math.isfinite(realtime)
            and 0 < realtime <= MAX_REALTIME
        ):
            raise ApiError(
                400, f"realtime: a factor above 0 and up to {MAX_REALTIME:g}, or null (fastest)"
            )
        simulate = body.get("simulate_tasks", False)
        if not isinstance(simulate, bool):
            raise ApiError(400, "simulate_tasks: true or false")
        # run: tasks only as the studio was started (--allow-run): never the page's call.
        tasks = TaskOptions(
            allow_run=self.config.allow_run,
            simulate_ros_s=DEFAULT_SIMULATED_SECONDS if simulate else None,
        )
        with self._lock:
            if self.run is not None and self.run.alive:
                raise ApiError(409, "a run is going on; stop it first")
            if self.fleets.busy:
                raise ApiError(409, "a fleet run is going on; stop it first")
        checked = self._checked(body.get("mission"), tasks=tasks)
        if checked.problems:
            # navseq run refuses them too (pre-flight); said here against the draft.
            raise ApiError(
                422,
                "the mission has problems; navseq run would not start it",
                problems=[problem.as_json() for problem in checked.problems],
            )
        assert checked.mission is not None
        stem = self.config.mission_path.stem if self.config.mission_path else "mission"
        run = StudioRun(
            StudioRunOrder(
                checked.mission, stem, None if realtime is None else float(realtime), tasks
            ),
            self.config.out_base,
        )
        run.start()  # NavseqError (pre-flight problems) -> 422 with them
        with self._lock:
            self.run = run
        return {"folder": run.view.folder, "status": run.view.status}

    def current_run(self) -> StudioRun:
        if self.run is None:
            raise ApiError(404, "no run yet")
        return self.run

    def warm_up(self, wait_for_page_s: float = 0.0) -> None:
        """Do what the page's first load asks for, ahead of it, in the order it asks:
        the opened mission, the map and its image first (the first paint waits for
        them), then the costmap and the opened mission's planned legs (its first check).
        Problems are the page's to show.

        The check waits up to ``wait_for_page_s`` for the page's own first check (sent
        once the page is painted), and runs at a lower priority: beside the page's first
        load it took the two cores the browser drew with (a page ready in 2.9 s instead
        of 0.8 s at 5000 waypoints on a 2000 x 2000 map).
        """
        try:
            opened = self.mission()
            if opened["mission"] is not None:
                try:
                    self.map_image(opened["mission"].get("map") or None, "map")
                finally:
                    self.page_checked.wait(wait_for_page_s)
                    _lower_this_threads_priority()
                    self.check(opened["mission"])
                    self._prepare_ordering(opened["mission"])
        except Exception:  # the same request from the page reports it
            pass

    def _prepare_ordering(self, document: Any) -> None:
        """What the first Order… of the opened mission needs before its searches (the
        coarse graph of a big map), made by the warm-up rather than in the user's wait."""
        from navseq.commands.common import choose_robot

        checked = self._checked(document)
        if checked.mission is None or checked.map_path is None or not checked.map_path.is_file():
            return
        planner = self.planner(checked.map_path, choose_robot(None, checked.mission))
        planner.prepare_ordering(len(checked.mission.waypoints) + 1)

    def close(self, reason: str = "the studio was stopped") -> None:
        """Cancel a running simulation and wait until its outputs are written."""
        run = self.run
        if run is not None:
            run.stop_and_wait(reason)
        self.fleets.close()


def _lower_this_threads_priority() -> None:
    """Make the calling thread (and the threads it starts) yield the CPU to the others:
    the page's requests and the browser come first. Linux only; elsewhere nothing."""
    with contextlib.suppress(AttributeError, OSError):
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), WARM_UP_NICENESS)


#: The image each map YAML names, by (YAML path): the YAML's (mtime, size) when read.
_MAP_IMAGES: dict[Path, tuple[tuple[int, int], Path | None]] = {}


def map_stamp(path: Path) -> tuple[int, ...]:
    """What changes when the map at ``path`` does: its YAML's and its image's mtimes.

    Raises OSError when the YAML cannot be read (the loader then says why).
    """
    status = path.stat()
    stamp = [status.st_mtime_ns]
    own = (status.st_mtime_ns, status.st_size)
    kept = _MAP_IMAGES.get(path)
    # The YAML read again only when it changed: a check asks for the stamp a few times.
    image_path = kept[1] if kept is not None and kept[0] == own else _image_named_by(path)
    _MAP_IMAGES[path] = (own, image_path)
    if image_path is not None:
        # A missing image: the loader says what is wrong; the YAML's stamp will do.
        with contextlib.suppress(OSError):
            stamp.append(image_path.stat().st_mtime_ns)
    return tuple(stamp)


def _image_named_by(path: Path) -> Path | None:
    """The image file a map YAML names (None when it cannot be read)."""
    try:
        import yaml

        from navseq.mission.yaml_doc import refuse_deep_nesting

        text = path.read_text(encoding="utf-8")
        refuse_deep_nesting(text, str(path))  # before PyYAML's composer recurses
        loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
        image = yaml.load(text, Loader=loader).get("image")
        return path.parent / str(image)
    except Exception:  # the loader says what is wrong with a bad map
        return None


def _save_keeping_the_file(target: Path, document: Any, mission: Mission) -> bool:
    """Write into ``target`` only what the page changed since the file was opened; False
    (nothing written) when that cannot give exactly ``mission``, so that the caller
    writes the mission whole instead."""
    from navseq.files import write_atomically
    from navseq.mission.loader import mission_from_yaml_text
    from navseq.studio.roundtrip import merged_mission_text

    if not isinstance(document, dict):
        return False
    before, _ = open_document(target, target.parent)
    if before is None:
        return False
    try:
        original = target.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    text = merged_mission_text(original, before, document)
    if text is None:
        return False
    try:
        merged = mission_from_yaml_text(text, str(target), target.parent)
    except NavseqError:
        return False
    # The merged file must read as the very mission the page meant, or it is not used.
    if merged is None or document_of(merged, target.parent) != document_of(mission, target.parent):
        return False
    write_atomically(target, text)
    return True


# --- HTTP ------------------------------------------------------------------------------


class TokenGate:
    """ASGI middleware: every request must carry the token (query, header or cookie)
    and name this machine as its host; every answer carries the security headers.

    State-changing requests from another origin are refused too, so that a page from
    elsewhere that somehow got the cookie sent cannot drive the studio.
    """

    def __init__(self, app: ASGIApp, token: str, hosts: frozenset[str] = LOCAL_NAMES) -> None:
        self.app = app
        self.token = token
        self.hosts = hosts

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        send = _with_security_headers(send)
        request = Request(scope)
        if not host_allowed(request.headers.get("host"), self.hosts):
            response: Response = JSONResponse(
                {
                    "error": "this navseq studio answers only requests for this machine's "
                    "address (open the URL it printed at start)"
                },
                status_code=403,
            )
            await response(scope, receive, send)
            return
        given = (
            request.query_params.get("token")
            or request.headers.get(TOKEN_HEADER)
            or request.cookies.get(COOKIE_NAME)
        )
        if not token_matches(given, self.token):
            response = JSONResponse(
                {"error": "this navseq studio needs its token: open the URL it printed at start"},
                status_code=403,
            )
            await response(scope, receive, send)
            return
        origin = request.headers.get("origin")
        if request.method not in ("GET", "HEAD") and origin is not None:
            host = request.headers.get("host", "")
            if origin.split("://", 1)[-1] != host:
                response = JSONResponse({"error": "cross-origin request refused"}, 403)
                await response(scope, receive, send)
                return
        await self.app(scope, receive, send)


def _with_security_headers(send: Send) -> Send:
    """``send``, adding :data:`RESPONSE_HEADERS` to the answer's start."""

    async def sending(message: Message) -> None:
        if message["type"] == "http.response.start":
            headers = list(message.get("headers", []))
            present = {name.lower() for name, _ in headers}
            for name, value in RESPONSE_HEADERS.items():
                if name.encode() not in present:
                    headers.append((name.encode(), value.encode()))
            message = {**message, "headers": headers}
        await send(message)

    return sending


def create_app(config: StudioConfig, studio: Studio | None = None) -> Starlette:
    """The studio as an ASGI app (``TestClient(create_app(...))`` in tests)."""
    studio = studio if studio is not None else Studio(config)

    async def index(request: Request) -> Response:
        response = FileResponse(STATIC / "index.html", headers={"cache-control": "no-store"})
        token = request.query_params.get("token")
        if token is not None and token_matches(token, config.token):
            response.set_cookie(COOKIE_NAME, token, httponly=True, samesite="strict")
        return response

    def answer(call: Callable[[], Any]) -> Handler:
        """A GET of the studio's ``call()``, answered as JSON (off the event loop)."""

        @api
        async def handler(request: Request) -> Response:
            return JSONResponse(await run_in_threadpool(call))

        return handler

    def answer_body(call: Callable[[dict[str, Any]], Any]) -> Handler:
        """A POST of a JSON object, given to the studio's ``call(body)``; JSON back."""

        @api
        async def handler(request: Request) -> Response:
            body = await read_json(request)
            return JSONResponse(await run_in_threadpool(call, body))

        return handler

    @api
    async def get_map(request: Request) -> Response:
        return JSONResponse(
            await run_in_threadpool(studio.map_info, request.query_params.get("map"))
        )

    @api
    async def get_map_image(request: Request) -> Response:
        png = await run_in_threadpool(
            studio.map_image,
            request.query_params.get("map"),
            request.query_params.get("layer", "map"),
        )
        return Response(png, media_type="image/png")

    @api
    async def order_job(request: Request) -> Response:
        return JSONResponse(studio.order_job(request.path_params["job"]))

    @api
    async def cancel_order(request: Request) -> Response:
        return JSONResponse(studio.cancel_order(request.path_params["job"]))

    @api
    async def get_replay(request: Request) -> Response:
        folder = request.query_params.get("folder")
        return JSONResponse(await run_in_threadpool(studio.replay, folder))

    @api
    async def get_run(request: Request) -> Response:
        return JSONResponse(studio.current_run().view.snapshot())

    @api
    async def run_request(request: Request) -> Response:
        kind = {"stop": "cancel", "pause": "pause", "resume": "resume", "skip": "skip"}.get(
            request.path_params["action"]
        )
        if kind is None:
            raise ApiError(404, "unknown run action; stop, pause, resume or skip")
        run = studio.current_run()
        # The operator's words as on every face, so that the report, the status and the
        # page tell a Stop from a failure ("cancelled by the operator (the studio)").
        reason = operator_reason(kind, "the studio")
        ok, message = await run_in_threadpool(run.operate, kind, reason)
        return JSONResponse({"ok": ok, "message": message}, status_code=200 if ok else 409)

    @api
    async def confirm_task(request: Request) -> Response:
        """The page's Confirm (``{"confirmed": true}``) or Refuse (false) of the input
        task the run waits at; 409 when none waits."""
        body = await read_json(request)
        confirmed = body.get("confirmed", True)
        if not isinstance(confirmed, bool):
            raise ApiError(400, "confirmed: true (Confirm) or false (Refuse)")
        run = studio.current_run()
        ok, message = await run_in_threadpool(run.confirm, confirmed)
        return JSONResponse({"ok": ok, "message": message}, status_code=200 if ok else 409)

    @api
    async def run_events(request: Request) -> Response:
        run = studio.current_run()

        async def stream() -> AsyncIterator[str]:
            sent = -1
            while True:
                snapshot = run.view.snapshot()
                if snapshot["version"] != sent or not run.view.done:
                    sent = snapshot["version"]
                    yield f"data: {json.dumps(snapshot)}\n\n"
                if run.view.done or await request.is_disconnected():
                    return
                await asyncio.sleep(LIVE_PERIOD_S)

        return StreamingResponse(stream(), media_type="text/event-stream")

    from navseq.studio.fleet_api import fleet_routes

    routes = [
        Route("/", index),
        Route("/api/mission", answer(studio.mission)),
        Route("/api/map", get_map),
        Route("/api/map/image", get_map_image),
        Route(
            "/api/check",
            answer_body(
                lambda body: studio.page_check(
                    body.get("mission"), body.get("base"), body.get("changes")
                )
            ),
            methods=["POST"],
        ),
        Route("/api/save", answer_body(studio.save), methods=["POST"]),
        Route("/api/files", answer(studio.files)),
        Route("/api/import", answer_body(studio.import_file), methods=["POST"]),
        Route("/api/export", answer_body(studio.export_launch), methods=["POST"]),
        Route("/api/order", answer_body(studio.order), methods=["POST"]),
        Route("/api/order/jobs", answer_body(studio.start_order), methods=["POST"]),
        Route("/api/order/jobs/{job}", order_job),
        Route("/api/order/jobs/{job}/cancel", cancel_order, methods=["POST"]),
        Route("/api/runs", answer(studio.runs)),
        Route("/api/replay", get_replay),
        Route("/api/run", answer_body(studio.start_run), methods=["POST"]),
        Route("/api/run", get_run),
        Route("/api/run/events", run_events),
        Route("/api/run/confirm", confirm_task, methods=["POST"]),
        Route("/api/run/{action}", run_request, methods=["POST"]),
        *fleet_routes(studio),
        Mount("/static", StaticFiles(directory=STATIC), name="static"),
    ]
    app = Starlette(routes=routes)
    app.state.studio = studio
    app.add_middleware(TokenGate, token=config.token, hosts=config.hosts)
    return app


def _expected_duration(prediction: IncrementalPrediction) -> dict[str, Any]:
    """The mission's expected duration and upper bound (navseq.eta), as ``navseq plan``
    says them; an edit's prediction works out only the visits it changed."""
    from navseq.eta.text import format_duration

    expected, upper = prediction.expected_s, prediction.upper_s
    if expected is None:  # a patrol that loops forever
        text = f"~{format_duration(prediction.loop_expected_s)} a loop"
    elif upper is None or not math.isfinite(upper):  # a task waits without a time limit
        text = f"~{format_duration(expected)} expected, no upper bound (a task has no timeout)"
    else:
        text = f"~{format_duration(expected)} expected, upper bound {format_duration(upper)}"
    return {
        "estimated_duration": text,
        "expected_duration_s": None if expected is None else round(expected, 1),
        "upper_bound_s": None if upper is None or not math.isfinite(upper) else round(upper, 1),
    }
