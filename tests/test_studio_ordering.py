"""The page's Order… as a job (navseq.studio.ordering): the same order as ``POST
/api/order``, its progress while it searches, and a Cancel that stops the searches."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

from starlette.testclient import TestClient

from navseq.studio.ordering import OrderJob, OrderJobs
from test_studio_api import client, opened, workspace  # noqa: F401 (fixtures)


def finished(studio_client: TestClient, job: dict[str, Any]) -> dict[str, Any]:
    """The job's view once it is no longer searching (within 60 s)."""
    deadline = time.monotonic() + 60
    while job["state"] in ("measuring", "solving"):
        assert time.monotonic() < deadline, job
        time.sleep(0.05)
        answer = studio_client.get(f"/api/order/jobs/{job['job']}")
        assert answer.status_code == 200
        job = answer.json()
    return job


def test_an_order_job_finds_the_order_that_the_order_request_finds(
    client: TestClient,  # noqa: F811
) -> None:
    document = opened(client)["mission"]
    at_once = client.post("/api/order", json={"mission": document, "keep_last": True}).json()
    started = client.post("/api/order/jobs", json={"mission": document, "keep_last": True})
    assert started.status_code == 200, started.text
    job = finished(client, started.json())
    assert job["state"] == "done"
    assert job["order"] == at_once["order"]
    assert job["length_m"] == at_once["length_m"]
    assert job["length_before_m"] == at_once["length_before_m"]


def test_an_order_job_of_a_draft_that_does_not_read_is_refused_at_once(
    client: TestClient,  # noqa: F811
) -> None:
    document = opened(client)["mission"]
    document["waypoints"][0]["x"] = "oops"
    refused = client.post("/api/order/jobs", json={"mission": document})
    assert refused.status_code == 422 and refused.json()["problems"]
    assert client.get("/api/order/jobs/99").status_code == 404
    assert client.post("/api/order/jobs/x/cancel").status_code == 404


def slow_searches(total: int, began: threading.Event, go_on: threading.Event) -> Any:
    """An ordering's work that reports ``total`` searches one by one, each waiting for
    ``go_on`` after the first; what it did is in its ``done`` list."""
    done: list[int] = []

    def work(progress: OrderJob) -> dict[str, Any]:
        for search in range(total):
            progress.searching(search, total)
            done.append(search)
            began.set()
            assert go_on.wait(10)
        return {"order": list(range(3))}

    work.done = done  # type: ignore[attr-defined]
    return work


def test_a_cancelled_order_job_starts_no_search_after_the_running_one() -> None:
    began, go_on = threading.Event(), threading.Event()
    work = slow_searches(100, began, go_on)
    job = OrderJobs().start(work)
    assert began.wait(10)
    view = job.view()
    assert view["state"] == "measuring" and view["searches"] == 100
    job.cancel()
    go_on.set()
    job.thread.join(10)
    assert job.view()["state"] == "cancelled"
    assert work.done == [0]  # the running search ended; none was started after it
    assert "order" not in job.view()


def test_a_new_order_job_cancels_the_one_before() -> None:
    began, go_on = threading.Event(), threading.Event()
    jobs = OrderJobs()
    first = jobs.start(slow_searches(100, began, go_on))
    assert began.wait(10)
    second = jobs.start(lambda progress: {"order": [0]})
    go_on.set()
    first.thread.join(10)
    second.thread.join(10)
    assert first.view()["state"] == "cancelled"
    assert second.view()["state"] == "done" and second.view()["order"] == [0]
    assert jobs.get(second.number) is second


def test_the_progress_of_a_real_ordering_is_shown(
    client: TestClient,  # noqa: F811
    workspace: Path,  # noqa: F811
) -> None:
    """The searches of a real ordering are counted in the job's view as they end."""
    document = opened(client)["mission"]
    seen: list[tuple[int, int]] = []
    studio = client.app.state.studio  # type: ignore[attr-defined]
    real_searching = OrderJob.searching

    def noting(self: OrderJob, done: int, total: int) -> None:
        seen.append((done, total))
        real_searching(self, done, total)

    OrderJob.searching = noting  # type: ignore[method-assign]
    try:
        job = finished(client, studio.start_order({"mission": document}))
    finally:
        OrderJob.searching = real_searching  # type: ignore[method-assign]
    assert job["state"] == "done"
    assert seen and seen[-1][0] == seen[-1][1] == job["searches"] == job["searches_done"]


def test_an_order_job_that_cannot_order_says_why_as_the_order_request_does(
    client: TestClient,  # noqa: F811
) -> None:
    document = opened(client)["mission"]
    document["waypoints"] = [{"x": 0.01 * k, "y": 0.0} for k in range(2001)]
    at_once = client.post("/api/order", json={"mission": document})
    assert at_once.status_code == 422
    job = finished(client, client.post("/api/order/jobs", json={"mission": document}).json())
    assert job["state"] == "failed"
    assert job["status"] == 422
    said = at_once.json()["error"]
    assert "takes at most 2000" in said
    # The same words (each names its own temporary copy of the draft first).
    assert job["failure"]["error"].split(": ", 1)[1] == said.split(": ", 1)[1]
