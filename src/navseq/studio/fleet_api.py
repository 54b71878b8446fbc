"""The studio's fleet endpoints (docs/studio.md, "Fleets"): the fleet files it may run,
a fleet run started, watched live and stopped, and a past fleet run replayed.

Handlers translate JSON to :mod:`navseq.studio.fleet_runs` and
:mod:`navseq.studio.fleet_replay` and back, with the studio's own error rules
(:func:`navseq.studio.app.api`: a 4xx answer with the CLI's messages, never a traceback).
"""

from __future__ import annotations

import asyncio
import json
import math
from collections.abc import AsyncIterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, Response, StreamingResponse
from starlette.routing import Route

from navseq.studio.fleet_runs import MAX_FLEETS_LISTED, StudioFleetRun, is_fleet_file
from navseq.studio.http import LIVE_PERIOD_S, MAX_REALTIME, ApiError, api, read_json
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.studio.app import Studio


def fleet_files(studio: Studio) -> dict[str, Any]:
    """Fleet files under the studio's folders (``GET /api/fleets``), and the one
    ``navseq studio --fleet`` chose."""
    roots = studio.roots
    found: set[Path] = set()
    for folder in roots.folders:
        for depth in ("*", "*/*", "*/*/*"):
            for path in folder.glob(depth):
                if len(found) >= MAX_FLEETS_LISTED:
                    break
                if (
                    path.suffix.lower() in (".yaml", ".yml")
                    and "navseq-out" not in path.parts
                    and path.is_file()
                    and roots.contains(path)
                    and is_fleet_file(path)
                ):
                    found.add(path.resolve())
    chosen = studio.fleets.fleet_path
    if chosen is not None:
        found.add(chosen.resolve())
    return {
        "fleets": sorted(roots.relative(path) for path in found),
        "chosen": None if chosen is None else roots.relative(chosen),
        "running": studio.fleets.busy,  # a page (re)loaded while it runs watches it
    }


def start_fleet_run(studio: Studio, body: dict[str, Any]) -> dict[str, Any]:
    """``POST /api/fleet/run``: ``{"fleet": path, "realtime": factor or null}``."""
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
    text = body.get("fleet")
    if text is None and studio.fleets.fleet_path is not None:
        fleet = studio.fleets.fleet_path
    else:
        if not isinstance(text, str):
            raise ApiError(400, "fleet: give the fleet file (e.g. fleet.yaml)")
        fleet = studio.roots.resolve(text, "fleet")
    if not fleet.is_file():
        raise ApiError(404, f"no such fleet file: {printable(studio.roots.relative(fleet))}")
    if studio.run is not None and studio.run.alive:
        raise ApiError(409, "a run is going on; stop it first")
    if studio.fleets.busy:
        raise ApiError(409, "a fleet run is going on; stop it first")
    run = studio.fleets.start(fleet, None if realtime is None else float(realtime))
    return {"folder": run.folder, "status": run.status}


def current_fleet_run(studio: Studio) -> StudioFleetRun:
    run = studio.fleets.run
    if run is None:
        raise ApiError(404, "no fleet run yet")
    return run


def fleet_replay(studio: Studio, folder_text: str | None) -> dict[str, Any]:
    """``GET /api/fleet/replay?folder=F``: a fleet run folder's timelines."""
    from navseq.studio.fleet_replay import FLEET_MANIFEST, fleet_replay_of

    if not folder_text:
        raise ApiError(400, "folder: give a fleet run folder (navseq-out/...)")
    roots = studio.run_roots
    folder = roots.resolve(folder_text, "folder")
    if not (folder / FLEET_MANIFEST).is_file():
        raise ApiError(
            404, f"not a fleet run folder (no {FLEET_MANIFEST}): {printable(folder_text)}"
        )
    return fleet_replay_of(
        folder,
        roots.relative(folder),
        studio.base_dir,
        may_read=roots.contains,
        shown_path=studio.roots.relative,
    )


def fleet_routes(studio: Studio) -> list[Route]:
    """The fleet endpoints, for :func:`navseq.studio.app.create_app`."""

    @api
    async def get_fleets(request: Request) -> Response:
        return JSONResponse(await run_in_threadpool(fleet_files, studio))

    @api
    async def post_run(request: Request) -> Response:
        body = await read_json(request)
        return JSONResponse(await run_in_threadpool(start_fleet_run, studio, body))

    @api
    async def get_run(request: Request) -> Response:
        run = current_fleet_run(studio)
        return JSONResponse(await run_in_threadpool(run.snapshot))

    @api
    async def stop_run(request: Request) -> Response:
        ok, message = current_fleet_run(studio).stop()
        return JSONResponse({"ok": ok, "message": message}, status_code=200 if ok else 409)

    @api
    async def run_events(request: Request) -> Response:
        run = current_fleet_run(studio)

        async def stream() -> AsyncIterator[str]:
            sent = None
            while True:
                done = run.done  # read before the snapshot: the last one sent is final
                snapshot = run.snapshot()
                if snapshot["version"] != sent:
                    sent = snapshot["version"]
                    yield f"data: {json.dumps(snapshot)}\n\n"
                if done or await request.is_disconnected():
                    return
                await asyncio.sleep(LIVE_PERIOD_S)

        return StreamingResponse(stream(), media_type="text/event-stream")

    @api
    async def get_replay(request: Request) -> Response:
        folder = request.query_params.get("folder")
        return JSONResponse(await run_in_threadpool(fleet_replay, studio, folder))

    return [
        Route("/api/fleets", get_fleets),
        Route("/api/fleet/run", post_run, methods=["POST"]),
        Route("/api/fleet/run", get_run),
        Route("/api/fleet/run/events", run_events),
        Route("/api/fleet/run/stop", stop_run, methods=["POST"]),
        Route("/api/fleet/replay", get_replay),
    ]


__all__ = ["fleet_files", "fleet_replay", "fleet_routes", "start_fleet_run"]
