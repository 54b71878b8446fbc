"""A fleet in the studio page, in a real headless Chromium: run live from the page and
replayed from the runs list (``navseq studio --fleet examples/fleet.yaml``), each robot
in its colour with a text row of its own; axe-core finds nothing serious on either view.
Skipped as tests/test_studio_browser.py is where Chromium, Playwright or axe-core lack."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cli_support import navseq
from test_studio_browser import _axe_or_skip, _skip_unless_there, new_page, serious_violations

REPO = Path(__file__).resolve().parents[1]

pytestmark = [pytest.mark.browser, pytest.mark.slow]


@pytest.fixture
def fleet_page(tmp_path: Path) -> Iterator[tuple[Any, Path]]:
    """``navseq studio --fleet examples/fleet.yaml`` (its mission opened in the editor),
    and a page on it in a fresh headless Chromium."""
    _skip_unless_there()
    from playwright.sync_api import sync_playwright

    from test_studio_browser import CHROMIUM

    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    argv = [sys.executable, "-m", "navseq", "studio", "--fleet", "examples/fleet.yaml"]
    process = subprocess.Popen(
        [*argv, "--no-browser"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stdout is not None
        first = process.stdout.readline()
        assert first.startswith("navseq studio: http://127.0.0.1:"), first
        url = first.split(": ", 1)[1].strip()
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
            try:
                page = new_page(browser)
                page.errors = []
                page.on("pageerror", lambda error: page.errors.append(str(error)))
                page.on(
                    "console",
                    lambda m: page.errors.append(m.text) if m.type == "error" else None,
                )
                page.goto(url)
                page.wait_for_selector("body[data-ready=true]", state="attached", timeout=20_000)
                yield page, tmp_path
            finally:
                browser.close()
    finally:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def panel(page: Any) -> list[list[str]]:
    """The robots' rows as a screen reader reads them: robot, waypoint, state, counts."""
    rows = page.get_by_test_id("fleet-robot-row")
    return [
        [cell.strip() for cell in rows.nth(k).locator("th, td").all_inner_texts()]
        for k in range(rows.count())
    ]


def test_a_fleet_runs_live_from_the_page_with_a_text_row_per_robot(
    fleet_page: tuple[Any, Path],
) -> None:
    page, workspace = fleet_page
    _axe_or_skip()
    # --fleet chose the fleet; its mission is the one opened in the editor.
    page.wait_for_function("document.getElementById('fleet-file').value === 'fleet.yaml'")
    assert "turtlebot3_world.yaml" in page.locator("#mission-name").inner_text()
    page.locator("#speed").select_option("1")  # 1x: the run is seen going on
    page.get_by_test_id("fleet-run").click()
    page.wait_for_function(
        "FLEET.data && FLEET.data.status === 'running' && FLEET.data.clock_s > 1", timeout=30_000
    )
    assert page.get_by_test_id("fleet-robot").count() == 3
    rows = panel(page)
    assert [row[0] for row in rows] == ["alpha", "beta", "gamma"]
    assert any(row[2] == "driving" for row in rows), rows
    assert "makespan so far" in page.get_by_test_id("fleet-totals").inner_text()
    assert page.get_by_test_id("fleet-live").get_attribute("aria-live") == "polite"
    assert "alpha" in page.get_by_test_id("fleet-live").inner_text()
    assert page.get_by_test_id("fleet-stop").is_enabled()
    assert serious_violations(page) == []  # the live view, while it runs
    # The robots' names are buttons, reached with the keyboard: Enter shows one on the map.
    name = page.locator("#fleet-robots button.robot-name").first
    name.focus()
    assert page.evaluate("document.activeElement.textContent") == "alpha"
    page.keyboard.press("Enter")
    page.get_by_test_id("fleet-stop").click()
    page.wait_for_function("FLEET.data.status === 'stopped'", timeout=30_000)
    assert "stopped" in page.get_by_test_id("fleet-live").inner_text()
    assert [row[0] for row in panel(page)] == ["alpha", "beta", "gamma"]
    assert serious_violations(page) == []
    # Run again, fastest, to its end: every waypoint reached, the report's figures shown.
    page.locator("#speed").select_option("")
    page.get_by_test_id("fleet-run").click()
    page.wait_for_function("FLEET.data && FLEET.data.status === 'completed'", timeout=60_000)
    assert "7 reached, 0 skipped, 0 failed of 7" in page.get_by_test_id("fleet-totals").inner_text()
    assert all(row[2] == "done" for row in panel(page)), panel(page)
    assert sum(int(row[3]) for row in panel(page)) == 7
    folders = sorted((workspace / "navseq-out").glob("fleet-*/fleet-report.json"))
    assert len(folders) == 2  # the stopped run's and this one's
    assert page.errors == []


def test_a_fleet_run_replays_on_one_clock_drawing_only_journaled_poses(
    fleet_page: tuple[Any, Path],
) -> None:
    page, workspace = fleet_page
    _axe_or_skip()
    done = navseq(
        "run", "--fleet", "examples/fleet.yaml", "--out", "navseq-out/tour", cwd=workspace
    )
    assert done.returncode == 0, done.stderr
    page.locator("#runs-refresh").click()
    page.wait_for_function("document.getElementById('runs').options.length > 1")
    option = page.locator("#runs option[data-fleet=true]")
    assert option.count() == 1  # the robots' folders are not runs of their own
    assert "fleet of 3 robots" in option.inner_text() and "7/7 reached" in option.inner_text()
    page.get_by_test_id("runs").select_option(value="navseq-out/tour")
    page.get_by_test_id("fleet-replay").wait_for(state="visible")
    replay = page.evaluate("FLEET.data")
    poses = {robot["name"]: robot["replay"]["poses"] for robot in replay["robots"]}
    slider = page.get_by_test_id("fleet-time")
    duration = float(slider.get_attribute("max") or 0)
    assert duration == pytest.approx(replay["duration_s"]) and duration > 5

    def at(t: float) -> dict[str, Any]:
        slider.evaluate(
            "(el, t) => { el.value = String(t); el.dispatchEvent(new Event('input')); }", t
        )
        drawn: dict[str, Any] = page.evaluate("fleetDrawn()")
        assert drawn["t"] == pytest.approx(t)
        for robot in drawn["robots"]:
            journaled = [[x, y] for (pt, x, y, _) in poses[robot["name"]] if pt <= t + 1e-9]
            # The trail is the journaled poses up to t, the robot drawn beyond the last.
            assert robot["trail"] == journaled, robot["name"]
        return drawn

    start = at(0)
    assert [r["name"] for r in start["robots"]] == ["alpha", "beta", "gamma"]
    assert page.get_by_test_id("fleet-robot").count() == 3
    middle = at(duration / 2)
    states = [s for robot in middle["robots"] for s in robot["statuses"]]
    assert "reached" in states and ("pending" in states or "driving" in states)
    assert serious_violations(page) == []  # the replay view
    end = at(duration)
    assert all(set(robot["statuses"]) == {"reached"} for robot in end["robots"])
    assert "7 reached, 0 skipped, 0 failed of 7" in page.get_by_test_id("fleet-totals").inner_text()
    assert [row[2] for row in panel(page)] == ["done"] * 3
    # Play runs the one clock from the start.
    at(0)
    page.get_by_test_id("fleet-play").click()
    page.wait_for_function("Number(document.getElementById('fleet-time').value) > 1")
    page.get_by_test_id("fleet-play").click()
    page.get_by_test_id("fleet-close").click()
    assert page.get_by_test_id("fleet-robot").count() == 0
    assert page.errors == []
