"""The studio's HTTP plumbing shared by its endpoints (:mod:`navseq.studio.app`,
:mod:`navseq.studio.fleet_api`): the 4xx answer, the JSON body read with its limits, and
the wrapper that turns navseq's errors into answers the page shows — never a traceback.
"""

from __future__ import annotations

import json
from collections.abc import Awaitable, Callable
from typing import Any

from starlette.requests import Request
from starlette.responses import JSONResponse, Response

from navseq.errors import NavseqError
from navseq.extras import MissingExtra
from navseq.studio.documents import DraftRefused, problems_of

#: Largest request body taken (a mission of several thousand waypoints fits).
MAX_BODY_BYTES = 2_000_000
#: How often the live view is sent while a run goes on (s): at most 20 updates/s.
LIVE_PERIOD_S = 0.05
#: Pace choices the page offers: None is as fast as the CPU goes.
MAX_REALTIME = 1000.0


class ApiError(Exception):
    """An answer other than 200, with the JSON to send."""

    def __init__(self, status: int, message: str, **extra: Any) -> None:
        super().__init__(message)
        self.status = status
        self.body = {"error": message, **extra}


async def read_json(request: Request, limit: int = MAX_BODY_BYTES) -> dict[str, Any]:
    """The request's JSON object; 413 past ``limit`` bytes, 415 for a body not declared
    JSON (a cross-site form may send ``text/plain`` without asking), 400 for anything
    not JSON."""
    declared = request.headers.get("content-length")
    if declared is not None and declared.isdigit() and int(declared) > limit:
        raise ApiError(413, f"the request body is over the limit of {limit} bytes")
    declared_type = request.headers.get("content-type", "").split(";", 1)[0].strip().lower()
    if declared_type != "application/json":
        raise ApiError(415, "the request body must be JSON (content-type: application/json)")
    chunks: list[bytes] = []
    size = 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > limit:
            raise ApiError(413, f"the request body is over the limit of {limit} bytes")
        chunks.append(chunk)
    try:
        body = json.loads(b"".join(chunks).decode("utf-8"))
    except UnicodeDecodeError:
        raise ApiError(400, "the request body is not UTF-8 text") from None
    except (ValueError, RecursionError) as error:
        raise ApiError(400, f"the request body is not valid JSON: {error}") from None
    if not isinstance(body, dict):
        raise ApiError(400, "the request body must be a JSON object")
    return body


Handler = Callable[[Request], Awaitable[Response]]


def api(handler: Handler) -> Handler:
    """Turn the studio's errors into 4xx JSON answers (never a traceback to the page)."""

    async def wrapped(request: Request) -> Response:
        try:
            response = await handler(request)
        except ApiError as error:
            response = JSONResponse(error.body, status_code=error.status)
        except DraftRefused as error:
            response = JSONResponse({"error": str(error)}, status_code=400)
        except MissingExtra as error:  # not the draft's fault: the install lacks a part
            response = JSONResponse({"error": str(error)}, status_code=501)
        except NavseqError as error:
            problems = problems_of([error])
            response = JSONResponse(
                {"error": str(error), "problems": [problem.as_json() for problem in problems]},
                status_code=422,
            )
        response.headers["cache-control"] = "no-store"
        return response

    return wrapped


__all__ = [
    "LIVE_PERIOD_S",
    "MAX_BODY_BYTES",
    "MAX_REALTIME",
    "ApiError",
    "Handler",
    "api",
    "read_json",
]
