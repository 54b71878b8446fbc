"""navseq studio in a real headless Chromium (Debian's ``chromium``, driven by Playwright).

``navseq studio`` runs as a subprocess, as a user starts it; the test reads the URL
from its first stdout line and uses the page as a user would: click, drag, save, run.
Skipped with a reason where Chromium or Playwright is missing
(``scripts/install-browser.sh`` installs Chromium; ``.ci/run`` runs it).

``NAVSEQ_UPDATE_SCREENSHOT=1`` writes the README's screenshot, docs/images/studio.png.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from navseq.mission import load_mission

REPO = Path(__file__).resolve().parents[1]
CHROMIUM = os.environ.get("NAVSEQ_CHROMIUM", "/usr/bin/chromium")
#: axe-core, from npm (tests/browser-deps, installed by scripts/install-browser.sh).
AXE = REPO / "tests/browser-deps/node_modules/axe-core/axe.min.js"
PILLAR = (1.0, 0.0)  # an occupied cell: the west face of the arena's middle east pillar
FREE_SPOT = (0.55, -1.2)

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _skip_reason() -> str | None:
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright is not installed (pip install playwright)"
    if not Path(CHROMIUM).exists():
        return f"no Chromium at {CHROMIUM} (scripts/install-browser.sh installs Debian's)"
    return None


def _skip_unless_there() -> None:
    reason = _skip_reason()
    if reason is not None:
        if os.environ.get("NAVSEQ_EXPECT_BROWSER") == "1":  # CI installed it: must not skip
            pytest.fail(reason)
        pytest.skip(reason)


@pytest.fixture(scope="module")
def chromium() -> Iterator[Any]:
    """One headless Chromium for the module's tests (it takes seconds to start); each
    test opens its pages in a context of its own (see :func:`new_page`), so no cookie,
    storage or dialog handler goes from one test to the next."""
    _skip_unless_there()
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        try:
            yield browser
        finally:
            browser.close()


def new_page(browser: Any, *, enforce_csp: bool = False) -> Any:
    """A page in a fresh browser context; closing the page's context closes it.

    Playwright evaluates the tests' string expressions (``wait_for_function``) with
    ``eval``, which the studio's Content-Security-Policy forbids: the harness bypasses
    the policy unless ``enforce_csp`` (the test that proves the page works under it).
    """
    context = browser.new_context(
        viewport={"width": 1400, "height": 860}, bypass_csp=not enforce_csp
    )
    return context.new_page()


@pytest.fixture
def studio(tmp_path: Path) -> Iterator[tuple[str, Path, subprocess.Popen[str]]]:
    _skip_unless_there()
    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "navseq",
            "studio",
            "examples/turtlebot3_world.yaml",
            "--no-browser",
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stdout is not None
    first = process.stdout.readline()
    assert first.startswith("navseq studio: http://127.0.0.1:"), first
    url = first.split(": ", 1)[1].strip()
    try:
        yield url, tmp_path, process
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
            try:
                process.wait(20)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


@pytest.fixture
def page(studio: tuple[str, Path, Any], chromium: Any) -> Iterator[Any]:
    url = studio[0]
    page = new_page(chromium)
    try:
        page.errors = []  # type: ignore[attr-defined]
        page.on(
            "console",
            lambda message: page.errors.append(message.text) if message.type == "error" else None,
        )
        page.on("pageerror", lambda error: page.errors.append(str(error)))
        page.goto(url)
        page.wait_for_selector("body[data-ready=true]", state="attached", timeout=20_000)
        # The tests below start from the opened mission checked and its legs drawn.
        page.wait_for_selector("body[data-planned=true]", state="attached", timeout=20_000)
        yield page
    finally:
        for context in chromium.contexts:  # a second tab too
            context.close()


def screen_point(page: Any, x: float, y: float) -> tuple[float, float]:
    """Where the world point (x, y) in metres is on the screen."""
    box = page.get_by_test_id("map").bounding_box()
    point = page.evaluate(
        "([x, y]) => { const p = map.latLngToContainerPoint(L.latLng(y, x)); return [p.x, p.y]; }",
        [x, y],
    )
    return box["x"] + point[0], box["y"] + point[1]


def drawn(page: Any) -> dict[str, Any]:
    """What the map's canvas painted last (``missionLayer.drawn()``): each waypoint's
    screen point in the map (``marks``), the start pose's, the replayed run's marks."""
    return dict(page.evaluate("missionLayer.drawn()"))


def marks(page: Any) -> int:
    """How many waypoints the map shows."""
    return len(drawn(page)["marks"])


def mark_point(page: Any, index: int) -> tuple[float, float]:
    """Where waypoint ``index``'s marker is on the screen."""
    box = page.get_by_test_id("map").bounding_box()
    mark = drawn(page)["marks"][index]
    assert mark["index"] == index
    return box["x"] + mark["x"], box["y"] + mark["y"]


def checked_after(page: Any, action: Any) -> None:
    """Do ``action`` and wait until the page's check of the change has come back."""
    before = page.evaluate("Number(document.body.dataset.checked || 0)")
    action()
    page.wait_for_function(f"Number(document.body.dataset.checked || 0) > {before}", timeout=10_000)


def test_make_check_save_and_run_a_mission_in_the_browser(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    _, workspace, process = studio
    assert page.get_by_test_id("map").is_visible()
    assert page.locator("[data-testid=map-image]").count() == 1
    assert marks(page) == 7
    assert page.get_by_test_id("waypoint-row").count() == 7
    assert page.get_by_test_id("problem").count() == 0

    # Click free space: an eighth waypoint, no problem.
    checked_after(page, lambda: page.mouse.click(*screen_point(page, *FREE_SPOT)))
    assert marks(page) == 8
    assert page.get_by_test_id("problem").count() == 0

    # Drag it onto a pillar: a problem names it, and saving is still allowed but marked.
    start = screen_point(page, *FREE_SPOT)
    target = screen_point(page, *PILLAR)

    def drag() -> None:
        page.mouse.move(*start)
        page.mouse.down()
        page.mouse.move(*target, steps=12)
        page.mouse.up()

    checked_after(page, drag)
    problems = page.get_by_test_id("problem")
    assert problems.count() == 1
    assert "waypoint 8" in problems.first.inner_text()
    assert "obstacle" in problems.first.inner_text() or "cannot turn" in problems.first.inner_text()
    assert "warn" in (page.get_by_test_id("save").get_attribute("class") or "")
    assert page.get_by_test_id("save").is_enabled()

    # Save: replacing the opened file is confirmed first.
    dialogs: list[str] = []

    def accept(dialog: Any) -> None:
        dialogs.append(dialog.message)
        dialog.accept()

    page.on("dialog", accept)
    page.get_by_test_id("save").click()
    page.wait_for_function("document.getElementById('message').textContent.startsWith('saved')")
    assert dialogs and "exists" in dialogs[0]
    saved = load_mission(workspace / "examples/turtlebot3_world.yaml")
    assert len(saved.waypoints) == 8
    assert saved.waypoints[7].x == pytest.approx(PILLAR[0], abs=0.03)
    assert saved.waypoints[7].y == pytest.approx(PILLAR[1], abs=0.03)
    assert saved.waypoints[0].name == "south-gate"

    # Undo the drag and the click: back to the 7 waypoints, which run.
    checked_after(page, lambda: page.keyboard.press("Control+z"))
    checked_after(page, lambda: page.keyboard.press("Control+z"))
    assert marks(page) == 7 and page.get_by_test_id("problem").count() == 0

    page.get_by_test_id("run").click()
    status = page.get_by_test_id("run-status")
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'completed'",
        timeout=60_000,
    )
    assert "7/7 reached" in status.inner_text()
    assert page.get_by_test_id("robot").count() == 1
    rows = page.get_by_test_id("waypoint-row").locator(".state").all_inner_texts()
    assert rows == ["reached"] * 7  # the list follows the run, row by row
    assert page.locator("#report-body tbody tr").count() == 8  # 7 visits + total
    runs = list((workspace / "navseq-out").iterdir())
    assert len(runs) == 1 and (runs[0] / "report.json").exists()

    shot = (
        REPO / "docs/images/studio.png"
        if os.environ.get("NAVSEQ_UPDATE_SCREENSHOT") == "1"
        else workspace / "studio.png"
    )
    page.get_by_test_id("waypoint-row").nth(1).click()  # a selected waypoint, its editor
    page.locator("#costmap-toggle").check()
    page.wait_for_function("[...document.images].every((image) => image.complete)")
    page.mouse.move(*screen_point(page, 0.9, -0.9))
    page.screenshot(path=str(shot))
    assert page.errors == []  # type: ignore[attr-defined]
    assert process.poll() is None  # still serving


def accept_dialogs(page: Any, answers: list[str] | None = None) -> list[str]:
    """Accept every dialog (confirm; a prompt with the next of ``answers``).

    Returns the messages seen; a later call on the same page adds answers to the queue.
    """
    if not hasattr(page, "dialog_answers"):
        page.dialog_answers = []
        page.dialogs_seen = []

        def handle(dialog: Any) -> None:
            page.dialogs_seen.append(dialog.message)
            if dialog.type == "prompt" and page.dialog_answers:
                dialog.accept(page.dialog_answers.pop(0))
            else:
                dialog.accept()

        page.on("dialog", handle)
    page.dialog_answers += answers or []
    return page.dialogs_seen  # type: ignore[no-any-return]


def message_of(page: Any, starts: str) -> str:
    page.wait_for_function(
        f"document.getElementById('message').textContent.startsWith({starts!r})", timeout=10_000
    )
    return str(page.locator("#message").inner_text())


def test_the_page_is_ready_before_the_first_check_and_plans_come_after(
    studio: tuple[str, Path, Any], chromium: Any
) -> None:
    """The first paint (map drawn, markers placed, the file's problems listed) does
    not wait for the pre-flight and the planned legs, which take seconds on a big map:
    here the check's answer is held back until the page says it is ready."""
    page = new_page(chromium)
    try:
        held: list[Any] = []
        page.route("**/api/check", lambda route: held.append(route))
        page.goto(studio[0])
        page.wait_for_selector("body[data-ready=true]", state="attached", timeout=20_000)
        assert page.get_by_test_id("map-image").count() == 1
        assert marks(page) == 7
        assert len(held) == 1  # asked at once, not answered yet
        assert page.evaluate("document.body.dataset.planned") is None
        assert page.locator(".leg-label").count() == 0
        assert "checking and planning" in page.locator("#route").inner_text()
        held[0].continue_()
        page.wait_for_selector("body[data-planned=true]", state="attached", timeout=20_000)
        assert page.locator(".leg-label").count() == 7  # every leg drawn with its length
        route = page.locator("#route").inner_text()
        assert "checking" not in route and " m · " in route
    finally:
        page.context.close()


def test_the_shortest_order_is_one_undoable_edit(page: Any, studio: tuple[str, Path, Any]) -> None:
    def names() -> list[str]:
        labels = page.get_by_test_id("waypoint-row").locator(".label").all_inner_texts()
        return [label.split(" (")[0] for label in labels]

    before = names()
    assert before[-1] == "home"
    checked_after(page, lambda: page.get_by_test_id("order").select_option("keep-last"))
    after = names()
    assert after != before and sorted(after) == sorted(before) and after[-1] == "home"
    assert "instead of" in page.locator("#message").inner_text()
    assert marks(page) == 7
    checked_after(page, lambda: page.keyboard.press("Control+z"))
    assert names() == before
    assert page.errors == []


def test_two_tabs_the_stale_save_is_refused_and_nothing_is_lost(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    url, workspace, _ = studio
    second = page.context.new_page()  # a second tab of the same browser session
    second.errors = []  # type: ignore[attr-defined]
    second.on("pageerror", lambda error: second.errors.append(str(error)))
    second.goto(url)
    second.wait_for_selector("body[data-planned=true]", state="attached", timeout=20_000)
    accept_dialogs(page)
    accept_dialogs(second)
    # Each tab adds its own waypoint; the first saves, then the second.
    checked_after(page, lambda: page.mouse.click(*screen_point(page, *FREE_SPOT)))
    checked_after(second, lambda: second.mouse.click(*screen_point(second, -0.55, 1.2)))
    checked_after(second, lambda: second.mouse.click(*screen_point(second, 0.55, 1.2)))
    page.get_by_test_id("save").click()
    message_of(page, "saved")
    second.get_by_test_id("save").click()
    said = message_of(second, "turtlebot3_world.yaml changed on disk")
    assert "nothing was written" in said
    assert "error" in (second.locator("#message").get_attribute("class") or "")
    saved = load_mission(workspace / "examples/turtlebot3_world.yaml")
    assert len(saved.waypoints) == 8  # the first tab's mission, whole
    assert saved.waypoints[7].x == pytest.approx(FREE_SPOT[0], abs=0.03)
    # The second tab keeps its edits: they can still be saved under another name.
    assert marks(second) == 9
    accept_dialogs(second, ["second-tab.yaml"])
    second.locator("#save-as").click()
    message_of(second, "saved second-tab.yaml")
    assert len(load_mission(workspace / "examples/second-tab.yaml").waypoints) == 9
    assert page.errors == [] and second.errors == []  # type: ignore[attr-defined]


def test_import_the_tutorials_launch_file_and_export_one(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    _, workspace, _ = studio
    accept_dialogs(page, ["tour.launch"])
    page.get_by_test_id("import").click()
    dialog = page.get_by_test_id("import-dialog")
    dialog.wait_for(state="visible")
    about = dialog.inner_text()
    for kind in ("navseq YAML", "tutorial launch file", "rosparam YAML", "CSV"):
        assert kind in about  # each format said
    files = page.get_by_test_id("import-file")
    launch = files.and_(page.locator("[data-path='tutorial_move_base_seq.launch']"))
    assert "launch file" in launch.inner_text()  # the choice lists every format, by its kind
    assert "CSV" in files.and_(page.locator("[data-path='recorded.csv']")).inner_text()
    # Escape closes it and gives the focus back to Import; Enter on a file imports it.
    assert page.evaluate("document.activeElement.dataset.testid") == "import-file"
    page.keyboard.press("Escape")
    assert not dialog.is_visible()
    assert page.evaluate("document.activeElement.id") == "import"
    page.keyboard.press("Enter")
    dialog.wait_for(state="visible")
    page.locator("[data-testid=import-file][data-path='tutorial_params.yaml']").focus()
    checked_after(page, lambda: page.keyboard.press("Enter"))
    assert not dialog.is_visible()
    assert marks(page) == 4
    size = page.evaluate("[map.getSize().x, map.getSize().y]")
    for mark in drawn(page)["marks"]:  # the view fits the imported waypoints
        assert 0 < mark["x"] < size[0] and 0 < mark["y"] < size[1]
    assert "imported 4 waypoints" in page.locator("#message").inner_text()
    # Still on the arena's map: its pre-flight runs on the imported points.
    assert page.locator("[data-testid=map-image]").count() == 1
    page.get_by_test_id("export").click()
    said = message_of(page, "exported tour.launch")
    exported = load_mission(workspace / "examples/tour.launch")
    tutorial = load_mission(workspace / "examples/tutorial_params.yaml")
    assert [(w.x, w.y, round(w.yaw_deg, 6)) for w in exported.waypoints] == [
        (w.x, w.y, round(w.yaw_deg, 6)) for w in tutorial.waypoints
    ]
    assert "no place for" in said and "map" in said
    # Undo brings the opened mission back.
    checked_after(page, lambda: page.keyboard.press("Control+z"))
    assert marks(page) == 7
    assert page.errors == []  # type: ignore[attr-defined]


def test_defaults_loops_and_a_start_pose_placed_and_turned_on_the_map(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    _, workspace, _ = studio
    accept_dialogs(page)
    # Defaults: three retries, skip on failure.
    retries = page.locator("#defaults input[name^=retries]")
    checked_after(page, lambda: (retries.fill("3"), retries.press("Enter")))
    failure = page.locator("#defaults select[name^=on_failure]")
    checked_after(page, lambda: failure.select_option("retry"))
    # Loops: a patrol of 2 draws the way back to the first waypoint as a leg.
    loops = page.locator("#settings input[name=loops]")
    checked_after(page, lambda: (loops.fill("2"), loops.press("Enter")))
    assert page.evaluate("S.legs.filter((leg) => leg.loop).length") == 1
    # The start pose: placed with a click, then turned with its handle to face +y.
    page.locator("#place-start").click()
    checked_after(page, lambda: page.mouse.click(*screen_point(page, -1.2, -1.2)))
    assert drawn(page)["start"] is not None
    handle = page.get_by_test_id("yaw-handle").bounding_box()
    centre = screen_point(page, -1.2, -1.2)

    def turn() -> None:
        page.mouse.move(handle["x"] + handle["width"] / 2, handle["y"] + handle["height"] / 2)
        page.mouse.down()
        page.mouse.move(centre[0], centre[1] - 40, steps=8)  # straight up on the screen
        page.mouse.up()

    checked_after(page, turn)
    page.get_by_test_id("save").click()
    message_of(page, "saved")
    saved = load_mission(workspace / "examples/turtlebot3_world.yaml")
    assert saved.defaults.retries == 3 and saved.defaults.on_failure.value == "retry"
    assert saved.loops == 2
    assert saved.start is not None
    assert (saved.start.x, saved.start.y) == pytest.approx((-1.2, -1.2), abs=0.03)
    assert saved.start.yaw == pytest.approx(math.pi / 2, abs=math.radians(3))
    assert page.errors == []  # type: ignore[attr-defined]


def test_the_defaults_recovery_is_typed_with_the_keyboard_checked_and_saved(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    """The defaults form has the mission's ``recovery:`` list, labelled, reached with Tab
    from the field before it; a bad entry is named by the check, a good list saves as
    the file writes it and comes back in the form when the file is opened again."""
    _, workspace, _ = studio
    _axe_or_skip()
    accept_dialogs(page)
    recovery = page.get_by_label("recovery", exact=True)
    assert recovery.input_value() == ""
    page.locator("#defaults select[name=clear_costmaps_on_retry]").focus()
    page.keyboard.press("Tab")
    assert page.evaluate("document.activeElement.id") == "defaults-recovery"
    checked_after(page, lambda: (page.keyboard.type("twirl: 90"), page.keyboard.press("Enter")))
    problems = page.get_by_test_id("problem")
    assert problems.count() == 1 and "unknown recovery 'twirl'" in problems.first.inner_text()
    page.keyboard.press("Control+a")
    checked_after(
        page,
        lambda: (
            page.keyboard.type("spin: 90, wait: 2, clear_costmaps"),
            page.keyboard.press("Tab"),
        ),
    )
    assert page.get_by_test_id("problem").count() == 0
    assert serious_violations(page) == []
    page.get_by_test_id("save").click()
    message_of(page, "saved")
    path = workspace / "examples/turtlebot3_world.yaml"
    assert "  recovery: [spin: 90, wait: 2, clear_costmaps]\n" in path.read_text()
    assert "# s for one attempt at a waypoint" in path.read_text()  # the rest kept
    recoveries = load_mission(path).defaults.recoveries
    assert [(r.kind, r.amount) for r in recoveries] == [
        ("spin", 90.0),
        ("wait", 2.0),
        ("clear_costmaps", None),
    ]
    page.reload()
    page.wait_for_selector("body[data-ready=true]", state="attached", timeout=20_000)
    assert recovery.input_value() == "spin: 90, wait: 2, clear_costmaps"
    assert page.errors == []  # type: ignore[attr-defined]


def test_a_past_run_replays_with_the_time_slider(page: Any, studio: tuple[str, Path, Any]) -> None:
    page.get_by_test_id("run").click()
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'completed'",
        timeout=60_000,
    )
    runs = page.get_by_test_id("runs")
    page.wait_for_function("document.getElementById('runs').options.length > 1")
    runs.select_option(index=1)
    page.wait_for_function("missionLayer.drawn().replayed.length === 7")
    slider = page.get_by_test_id("replay-time")
    duration = float(slider.get_attribute("max") or 0)
    assert duration > 10

    def at(t: float) -> list[str]:
        slider.evaluate(
            "(el, t) => { el.value = String(t); el.dispatchEvent(new Event('input')); }", t
        )
        return [str(mark["status"]) for mark in drawn(page)["replayed"]]

    assert at(0)[1:] == ["pending"] * 6  # the first is driving from t = 0
    middle = at(duration / 2)
    assert "reached" in middle and "pending" in middle
    assert page.get_by_test_id("replay-robot").count() == 1
    assert "/ " in page.get_by_test_id("replay-clock").inner_text()
    assert at(duration) == ["reached"] * 7
    assert page.errors == []  # type: ignore[attr-defined]


def test_the_page_works_under_its_content_security_policy(
    studio: tuple[str, Path, Any], chromium: Any
) -> None:
    """The studio's policy (scripts and styles from itself only, no eval, no frames) is
    enforced here: the page opens, checks and draws the mission without one violation."""
    page = new_page(chromium, enforce_csp=True)
    errors: list[str] = []
    page.on(
        "console", lambda message: errors.append(message.text) if message.type == "error" else None
    )
    page.on("pageerror", lambda error: errors.append(str(error)))
    try:
        page.goto(studio[0])
        page.wait_for_selector("body[data-planned=true]", state="attached", timeout=20_000)
        assert page.get_by_test_id("waypoint-row").count() == 7
        assert marks(page) == 7
        assert errors == []
    finally:
        page.context.close()


def test_closing_the_tab_with_unsaved_edits_asks_first_and_not_once_saved(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    seen: list[str] = []

    def answer(dialog: Any) -> None:
        seen.append(dialog.type)
        if dialog.type == "beforeunload":
            dialog.dismiss()  # stay on the page
        else:
            dialog.accept()  # Save's "replace it?"

    page.on("dialog", answer)
    checked_after(page, lambda: page.mouse.click(*screen_point(page, *FREE_SPOT)))
    page.close(run_before_unload=True)
    page.wait_for_timeout(500)
    assert seen == ["beforeunload"] and not page.is_closed()  # the edit is kept
    page.get_by_test_id("save").click()
    page.wait_for_selector("text=saved", timeout=10_000)
    seen.clear()
    with page.expect_event("close", timeout=5_000):
        page.close(run_before_unload=True)
    assert "beforeunload" not in seen  # saved: nothing to lose, nothing asked


def test_typing_in_a_field_keeps_the_focus_and_every_value(page: Any) -> None:
    """Enter or Tab in a field commits it without rebuilding the form under the user: the
    value typed next lands in the next field, as typed (the form was rebuilt at every
    change, dropping the focus and the following keys)."""
    page.get_by_test_id("waypoint-row").nth(1).click()
    x = page.locator("#fields input[name^='x ']")
    x.click()
    page.keyboard.press("Control+a")
    checked_after(page, lambda: (page.keyboard.type(str(FREE_SPOT[0])), page.keyboard.press("Tab")))
    assert page.evaluate("document.activeElement.id") == "fields-y"
    checked_after(
        page, lambda: (page.keyboard.type(str(FREE_SPOT[1])), page.keyboard.press("Enter"))
    )
    # Both values landed (the row and the form say so) and the focus stayed in y.
    row = page.get_by_test_id("waypoint-row").nth(1).locator(".label").inner_text()
    assert f"({FREE_SPOT[0]:.2f}, {FREE_SPOT[1]:.2f}," in row
    assert page.evaluate("document.activeElement.id") == "fields-y"
    assert x.input_value() == str(FREE_SPOT[0])
    # Typing on goes on in y: the next value lands too.
    page.keyboard.press("Control+a")
    checked_after(page, lambda: (page.keyboard.type("-1.1"), page.keyboard.press("Enter")))
    row = page.get_by_test_id("waypoint-row").nth(1).locator(".label").inner_text()
    assert f"({FREE_SPOT[0]:.2f}, -1.10," in row
    assert page.evaluate("document.activeElement.id") == "fields-y"
    assert page.errors == []  # type: ignore[attr-defined]


def _row_xy(page: Any, i: int) -> tuple[float, float]:
    """The (x, y) a waypoint's row shows."""
    label = page.get_by_test_id("waypoint-row").nth(i).locator(".label").inner_text()
    x, y = label.split("(")[1].split(",")[:2]
    return float(x), float(y)


def _focused(page: Any) -> str:
    return str(page.evaluate("document.activeElement.getAttribute('aria-label') || ''"))


def test_the_mission_is_edited_with_the_keyboard_alone(page: Any) -> None:
    """Rows and markers take the focus and Enter selects; the arrows move the selected
    waypoint (5 cm, Shift 50 cm), each press one undoable edit; ▲ ▼ ✕ say what they do;
    the focus stays where the user is through every redraw."""
    rows = page.get_by_test_id("waypoint-row")
    x0, y0 = _row_xy(page, 2)
    rows.nth(2).locator("button.pick").focus()
    page.keyboard.press("Enter")
    assert page.locator("#editor-title").inner_text() == "3"
    checked_after(page, lambda: page.keyboard.press("ArrowRight"))
    checked_after(page, lambda: page.keyboard.press("Shift+ArrowUp"))
    assert _row_xy(page, 2) == pytest.approx((x0 + 0.05, y0 + 0.5), abs=1e-9)
    assert page.evaluate("document.activeElement.dataset.focus") == "row-2"
    checked_after(page, lambda: page.keyboard.press("Control+z"))  # one press, one step
    assert _row_xy(page, 2) == pytest.approx((x0 + 0.05, y0), abs=1e-9)
    checked_after(page, lambda: page.keyboard.press("Control+Shift+z"))
    assert _row_xy(page, 2) == pytest.approx((x0 + 0.05, y0 + 0.5), abs=1e-9)

    # The map: with the focus on it, the arrows move the selected waypoint, and it keeps
    # the focus (the markers are painted on a canvas: the rows are their keyboard way).
    rows.nth(3).locator("button.pick").focus()
    page.keyboard.press("Enter")
    assert page.locator("#editor-title").inner_text() == "4"
    page.get_by_test_id("map").focus()
    x3, y3 = _row_xy(page, 3)
    checked_after(page, lambda: page.keyboard.press("ArrowDown"))
    assert _row_xy(page, 3) == pytest.approx((x3, y3 - 0.05), abs=1e-9)
    assert page.evaluate("document.activeElement.dataset.testid") == "map"
    assert drawn(page)["marks"][3]["selected"]

    # ▲ ▼ ✕ are named by what they do; the focus follows the moved waypoint.
    up = rows.nth(3).get_by_role("button", name="move waypoint 4 up")
    assert rows.nth(3).get_by_role("button", name="delete waypoint 4").count() == 1
    name = rows.nth(3).locator(".label").inner_text()
    up.focus()
    checked_after(page, lambda: page.keyboard.press("Enter"))
    assert rows.nth(2).locator(".label").inner_text() == name
    assert _focused(page) == "move waypoint 3 up"
    # Delete removes the selected waypoint; the focus goes to the row in its place.
    rows.nth(2).locator("button.pick").focus()
    checked_after(page, lambda: page.keyboard.press("Delete"))
    assert rows.count() == 6 and name not in rows.all_inner_texts()
    assert page.evaluate("document.activeElement.dataset.focus") == "row-2"

    # A waypoint added with a click on the map moves with the arrows at once (the click
    # focused the map, whose own arrows pan it: not while a waypoint is selected).
    checked_after(page, lambda: page.mouse.click(*screen_point(page, *FREE_SPOT)))
    checked_after(page, lambda: page.keyboard.press("ArrowLeft"))
    assert _row_xy(page, 6) == pytest.approx((FREE_SPOT[0] - 0.05, FREE_SPOT[1]), abs=1e-9)
    page.keyboard.press("Escape")  # deselects: the form closes
    assert page.locator("#editor").is_hidden()

    # Every input and choice on the page has a name (its label, or aria-label).
    unnamed = page.evaluate(
        "[...document.querySelectorAll('input, select')]"
        ".filter((el) => !el.labels.length && !el.getAttribute('aria-label')).map((el) => el.id)"
    )
    assert unnamed == []
    assert page.errors == []  # type: ignore[attr-defined]


def test_an_edit_goes_as_the_waypoint_it_changed_and_whole_when_the_studio_lost_its_draft(
    page: Any,
) -> None:
    """A moved waypoint is sent as itself against the draft of the answer the page
    holds, not as the whole draft; when the studio answers that it no longer holds that
    draft (409), the page sends the whole draft at once and draws its answer."""
    sent: list[dict[str, Any]] = []
    lost = {"once": True}

    def watch(route: Any) -> None:
        body = json.loads(route.request.post_data)
        sent.append(body)
        if "changes" in body and len(sent) == 2 and lost.pop("once", False):
            route.fulfill(
                status=409,
                content_type="application/json",
                body=json.dumps({"error": "no longer held", "conflict": "base"}),
            )
        else:
            route.continue_()

    page.route("**/api/check", watch)
    rows = page.get_by_test_id("waypoint-row")
    x2, y2 = _row_xy(page, 2)
    rows.nth(2).locator("button.pick").focus()
    page.keyboard.press("Enter")
    checked_after(page, lambda: page.keyboard.press("ArrowRight"))
    moved = page.evaluate("S.doc.waypoints[2]")
    assert list(sent[0]) == ["base", "changes"] and sent[0]["changes"] == [[2, moved]]
    held = page.evaluate("S.checkId")
    assert held is not None
    # The studio lost the draft: the next edit's changes are refused, the whole goes.
    checked_after(page, lambda: page.keyboard.press("ArrowUp"))
    page.wait_for_function(f"S.checkId !== null && S.checkId !== {held}", timeout=10_000)
    assert [sorted(body) for body in sent[1:]] == [["base", "changes"], ["base", "mission"]]
    assert sent[2]["mission"]["waypoints"][2] == page.evaluate("S.doc.waypoints[2]")
    assert _row_xy(page, 2) == pytest.approx((x2 + 0.05, y2 + 0.05), abs=1e-9)
    legs = page.evaluate("S.legs.filter((leg) => leg.to === 2 || leg.from === '2')")
    assert len(legs) == 2 and all(leg["points"] for leg in legs)
    # Nothing said to the user (the browser itself logs the 409 it was answered).
    assert "409" in page.errors[0] and page.errors[1:] == []
    assert page.locator("#message.error").count() == 0
    assert not page.locator("[data-testid=problem]").count()


def test_a_drop_whose_answer_is_late_is_drawn_before_it_and_again_with_it(page: Any) -> None:
    """After a drop the canvas waits for the check's answer (the list shows the new
    position at once), but not for long: an answer held back, the waypoint is drawn
    where it was dropped all the same; the answer, when it comes, is drawn with it."""
    held: list[Any] = []
    page.route("**/api/check", lambda route: held.append(route))
    start = mark_point(page, 3)
    page.mouse.move(*start)
    page.mouse.down()
    page.mouse.move(start[0] + 30, start[1] + 12, steps=4)
    page.mouse.up()
    dropped = page.evaluate("[S.doc.waypoints[3].x, S.doc.waypoints[3].y]")
    assert _row_xy(page, 3) == pytest.approx(dropped, abs=1e-9)
    page.wait_for_function("S.settling === null && S.drag === null", timeout=5_000)
    assert len(held) == 1  # no answer yet
    assert drawn(page)["marks"][3]["x"] == pytest.approx(
        page.evaluate("([x, y]) => map.latLngToContainerPoint(L.latLng(y, x)).x", dropped),
        abs=0.5,
    )
    checked_after(page, held[0].continue_)
    legs = page.evaluate("S.legs.filter((leg) => leg.to === 3)")
    assert legs[0]["points"][-1] == pytest.approx(dropped, abs=0.06)
    assert page.errors == []


def test_the_run_status_is_announced(page: Any) -> None:
    live = page.get_by_test_id("run-live")
    assert live.get_attribute("aria-live") == "polite"
    page.get_by_test_id("run").click()
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'completed'",
        timeout=60_000,
    )
    assert "completed" in live.inner_text() and "7/7 reached" in live.inner_text()
    assert page.errors == []  # type: ignore[attr-defined]


def _axe_or_skip() -> None:
    if not AXE.exists():
        reason = (
            f"no axe-core at {AXE.relative_to(REPO)} "
            "(scripts/install-browser.sh runs npm ci in tests/browser-deps)"
        )
        if os.environ.get("NAVSEQ_EXPECT_BROWSER") == "1":  # CI installed it: must not skip
            pytest.fail(reason)
        pytest.skip(reason)


def serious_violations(page: Any) -> list[str]:
    """axe-core's violations of impact serious or critical on the page as it is now, one
    line each: the rule, what it asks, and the elements concerned."""
    if not page.evaluate("typeof window.axe !== 'undefined'"):
        page.add_script_tag(path=str(AXE))  # the harness's contexts bypass the CSP
    found = page.evaluate(
        """async () => (await axe.run(document, { resultTypes: ["violations"] })).violations
            .filter((v) => v.impact === "serious" || v.impact === "critical")
            .map((v) => `${v.id} (${v.impact}): ${v.help}: `
                + v.nodes.slice(0, 5).map((n) => n.target.join(" ")).join(", "))"""
    )
    return list(found)


def test_no_serious_accessibility_violation_in_the_editor_a_run_and_a_replay(
    page: Any,
) -> None:
    """axe-core finds no serious or critical violation on the opened editor (a waypoint
    selected, its form shown; the Import dialog open), during a run and after it, and
    during a replay."""
    _axe_or_skip()
    page.get_by_test_id("waypoint-row").nth(1).click()
    assert serious_violations(page) == []
    page.get_by_test_id("import").click()  # the Import dialog, open
    page.get_by_test_id("import-dialog").wait_for(state="visible")
    assert serious_violations(page) == []
    page.keyboard.press("Escape")

    page.locator("#speed").select_option("1")
    page.get_by_test_id("run").click()
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'running'",
        timeout=30_000,
    )
    page.locator("#pause").click()  # held still while it is looked at
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'paused'",
        timeout=10_000,
    )
    assert serious_violations(page) == []
    page.get_by_test_id("stop").click()
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'stopped'",
        timeout=30_000,
    )
    assert "stopped" in page.get_by_test_id("run-live").inner_text()
    assert serious_violations(page) == []

    page.wait_for_function("document.getElementById('runs').options.length > 1")
    page.get_by_test_id("runs").select_option(index=1)
    page.wait_for_function("missionLayer.drawn().replayed.length === 7")
    assert serious_violations(page) == []
    assert page.errors == []  # type: ignore[attr-defined]


def test_a_dropped_file_opens_the_import_list_on_it(page: Any) -> None:
    """The studio imports files by their path under its folders, which a dropped file
    does not give: the drop opens the Import list, focused on the file of that name,
    and the page stays (the browser would otherwise leave it to show the file)."""
    page.evaluate(
        """() => {
            const dt = new DataTransfer();
            dt.items.add(new File(["x,y,z,qx,qy,qz,qw"], "recorded.csv", { type: "text/csv" }));
            document.getElementById("waypoints").dispatchEvent(
                new DragEvent("drop", { dataTransfer: dt, bubbles: true, cancelable: true }));
        }"""
    )
    dialog = page.get_by_test_id("import-dialog")
    dialog.wait_for(state="visible")
    assert "recorded.csv was dropped" in dialog.inner_text()
    page.wait_for_function("document.activeElement.dataset.path === 'recorded.csv'")
    checked_after(page, lambda: page.keyboard.press("Enter"))
    assert "imported" in page.locator("#message").inner_text()
    assert page.get_by_test_id("waypoint-row").count() > 0
    assert page.errors == []  # type: ignore[attr-defined]


def test_tasks_edited_confirmed_in_a_run_and_reported_at_once(
    page: Any, studio: tuple[str, Path, Any]
) -> None:
    """A waypoint gets an input task in its editor (its marker and row show it has
    tasks), the run stops there and says so, Confirm answers it, and the report is shown,
    in view, with the task, as soon as the run has written it; axe finds nothing serious
    on the task editor, the waiting task and the report."""
    _axe_or_skip()
    _, workspace, _ = studio
    page.get_by_test_id("waypoint-row").nth(1).click()
    tasks = page.get_by_test_id("wp-tasks")
    checked_after(page, lambda: tasks.get_by_test_id("task-add").select_option("input"))
    prompt = tasks.locator("input[id$='-prompt']")
    assert prompt.evaluate("(input) => input === document.activeElement")  # typed at once
    checked_after(page, lambda: (prompt.fill("Load the tray"), prompt.press("Enter")))
    assert tasks.get_by_test_id("task").inner_text().startswith("1. input: Load the tray")
    checked_after(page, lambda: tasks.get_by_test_id("task-add").select_option("wait"))
    assert tasks.get_by_test_id("task").count() == 2
    checked_after(page, lambda: tasks.get_by_label("move task 2 up").click())
    texts = tasks.locator(".task-text").all_inner_texts()
    assert texts == ["1. wait 5 s", "2. input: Load the tray"]
    checked_after(page, lambda: tasks.get_by_label("remove task 1").click())
    assert tasks.locator(".task-text").all_inner_texts() == ["1. input: Load the tray"]
    assert page.evaluate("missionLayer.drawn().marks[1].tasks") is True
    assert page.get_by_test_id("waypoint-row").nth(1).locator(".task-flag").count() == 1
    assert page.get_by_test_id("problem").all_inner_texts() == []
    page.get_by_test_id("legend").locator("summary").click()  # the legend, open
    assert page.get_by_test_id("legend").locator("li").count() >= 13
    assert serious_violations(page) == []

    page.get_by_test_id("run").click()
    confirm = page.get_by_test_id("task-confirm")
    confirm.wait_for(state="visible", timeout=60_000)
    assert page.get_by_test_id("run-task").inner_text() == (
        "waypoint 2: input — Load the tray (Confirm or Refuse)"
    )
    assert "waypoint 2: input — Load the tray" in page.get_by_test_id("run-live").inner_text()
    assert serious_violations(page) == []
    confirm.click()
    page.wait_for_function(
        "document.querySelector('[data-testid=report-task]') !== null", timeout=60_000
    )
    report = page.locator("#report")
    assert report.is_visible()
    box, aside = report.bounding_box(), page.locator("aside").bounding_box()
    assert aside["y"] <= box["y"] < aside["y"] + aside["height"]  # scrolled into view
    task_row = page.get_by_test_id("report-task").inner_text()
    assert "input" in task_row and "succeeded" in task_row and "confirmed in the studio" in task_row
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'completed'",
        timeout=60_000,
    )
    assert serious_violations(page) == []
    assert page.errors == []  # type: ignore[attr-defined]
    # The task is in the page's mission, not yet in the file: a save writes it.
    assert (
        load_mission(workspace / "examples/turtlebot3_world.yaml")
        .waypoints[1]
        .overrides.get("tasks")
        is None
    )


def _big_mission(folder: Path, count: int) -> Path:
    """A mission of ``count`` waypoints spread over the arena's free space (seeded), in
    serpentine order, with the start pose on the first waypoint's spot."""
    import json

    import numpy as np

    from navseq.commands.common import costmap_for_map

    map_yaml = folder / "maps/turtlebot3_world.yaml"
    costmap = costmap_for_map(map_yaml)
    cells = np.argwhere(costmap.free_mask() & (costmap.clearance >= 0.25))
    picked = cells[np.random.default_rng(7).choice(len(cells), count, replace=False)]
    points = [costmap.cell_to_world(int(row), int(col)) for row, col in picked]
    band = lambda p: int((p[1] + 3) // 0.25)  # noqa: E731
    points.sort(key=lambda p: (band(p), p[0] if band(p) % 2 == 0 else -p[0]))
    mission = {
        "navseq": 1,
        "map": "../maps/turtlebot3_world.yaml",
        "start": {"x": round(points[0][0], 2), "y": round(points[0][1], 2), "yaw": 0},
        "waypoints": [{"x": round(x, 2), "y": round(y, 2), "yaw": 0} for x, y in points],
    }
    path = folder / "examples/big.yaml"
    path.write_text(json.dumps(mission), encoding="utf-8")
    return path


def _overlaps(page: Any) -> list[str]:
    """Leg labels shown that overlap another label or a marker (its plate, as painted)."""
    return list(
        page.evaluate(
            """() => {
            const map = document.getElementById("map").getBoundingClientRect();
            const labels = [...document.querySelectorAll(".leg-label")].map((el) => {
                const r = el.getBoundingClientRect();
                return { text: el.textContent, x: r.left - map.left, y: r.top - map.top,
                         w: r.width, h: r.height };
            });
            const hit = (a, b) => a.x < b.x + b.w && b.x < a.x + a.w
                && a.y < b.y + b.h && b.y < a.y + a.h;
            const found = [];
            labels.forEach((a, k) => labels.slice(k + 1).forEach((b) => {
                if (hit(a, b)) found.push(`${a.text} over ${b.text}`);
            }));
            const drawn = missionLayer.drawn();
            for (const m of drawn.marks) {
                const plate = { x: m.x - m.half, y: m.y - m.r, w: 2 * m.half, h: 2 * m.r };
                for (const a of labels) {
                    if (hit(a, plate)) found.push(`${a.text} over waypoint ${m.index + 1}`);
                }
            }
            return found;
        }"""
        )
    )


def test_a_mission_of_2000_waypoints_opens_drags_and_labels_nothing_over_anything(
    chromium: Any, tmp_path: Path
) -> None:
    """2000 waypoints: the page opens with all of them on the map and a list that builds
    only the rows in sight (the last one reached by scrolling); a drag moves one and its
    legs are planned again; leg lengths are shown only where they cover no marker and
    no other label, at the whole-mission view and zoomed in; 4-digit numbers fit their
    plates; the start pose, on the first waypoint's spot, is still seen around it."""
    _skip_unless_there()
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    (tmp_path / "examples").mkdir()
    mission = _big_mission(tmp_path, 2000)
    process = subprocess.Popen(
        [sys.executable, "-m", "navseq", "studio", str(mission), "--no-browser"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    page = new_page(chromium)
    try:
        assert process.stdout is not None
        url = process.stdout.readline().split(": ", 1)[1].strip()
        errors: list[str] = []
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.goto(url)
        page.wait_for_selector("body[data-ready=true]", state="attached", timeout=60_000)
        assert marks(page) == 2000
        rows = page.get_by_test_id("waypoint-row")
        assert 0 < rows.count() < 100  # the rows in sight, not 2000
        assert rows.first.get_attribute("aria-setsize") == "2000"
        page.wait_for_selector("body[data-planned=true]", state="attached", timeout=120_000)
        assert page.evaluate("S.legs.length") == 2000  # the start's leg and 1999 more
        assert _overlaps(page) == []

        # Zoomed in on the middle: numbered plates, labels where they fit, none over anything.
        page.evaluate(
            "map.setView(map.getCenter(), map.getMaxZoom(), { animate: false });"
            " missionLayer.draw()"
        )
        assert not drawn(page)["compact"], page.evaluate("[map.getZoom(), map.getSize()]")
        assert page.locator(".leg-label").count() > 0
        assert _overlaps(page) == []

        # Waypoint 2000: its 4 digits fit its plate.
        last = page.evaluate(
            """() => { const w = S.doc.waypoints[1999];
            map.setView([w.y, w.x], map.getZoom(), { animate: false }); missionLayer.draw();
            const ctx = document.createElement("canvas").getContext("2d");
            ctx.font = "bold 11px system-ui, sans-serif";
            return [missionLayer.drawn().marks[1999].half, ctx.measureText("2000").width]; }"""
        )
        assert last[0] * 2 >= last[1] + 4

        # The start pose, on waypoint 1's spot: its ring shows around waypoint 1's plate.
        colours = page.evaluate(
            """() => { const s = S.doc.start;
            map.setView([s.y, s.x], map.getZoom(), { animate: false }); missionLayer.draw();
            const d = missionLayer.drawn();
            const c = document.querySelector("[data-testid=mission-canvas]");
            const ctx = c.getContext("2d"), k = c.width / c.clientWidth;
            const at = (x, y) => [
                ...ctx.getImageData(Math.round(x * k), Math.round(y * k), 1, 1).data];
            return { ring: at(d.start[0] - 15, d.start[1]),
                     plate: at(d.marks[0].x, d.marks[0].y + 7) }; }"""
        )
        assert max(colours["ring"][:3]) < 80 and colours["ring"][3] > 200  # #111827
        assert colours["plate"][2] > 150 and colours["plate"][0] < 100  # #2563eb, waypoint 1

        # Drag waypoint 10 a little: it moves, and its two legs are planned again.
        page.evaluate(
            "const w = S.doc.waypoints[9];"
            " map.setView([w.y, w.x], map.getZoom(), { animate: false }); missionLayer.draw();"
        )
        before = page.evaluate("[S.doc.waypoints[9].x, S.doc.waypoints[9].y]")
        bodies: list[str] = []
        page.on(
            "request",
            lambda r: bodies.append(r.post_data) if r.url.endswith("/api/check") else None,
        )
        start = mark_point(page, 9)
        page.mouse.move(*start)
        page.mouse.down()

        def drop() -> None:
            page.mouse.move(start[0] + 12, start[1] + 6, steps=4)
            page.mouse.up()

        checked_after(page, drop)
        after = page.evaluate("[S.doc.waypoints[9].x, S.doc.waypoints[9].y]")
        assert after != before and page.evaluate("S.doc.waypoints.length") == 2000
        legs = page.evaluate("S.legs.filter((leg) => leg.to === 9 || leg.from === '9')")
        assert len(legs) == 2
        into = legs[0] if legs[0]["to"] == 9 else legs[1]
        assert into["points"][-1] == pytest.approx(after, abs=0.06)
        # The answer carried those two legs only; the page patched its own 2000. It sent
        # the moved waypoint only, not the draft of 2000.
        assert page.evaluate("S.route.legs_changed.map(([position]) => position)") == [9, 10]
        assert [change[0] for change in json.loads(bodies[-1])["changes"]] == [9]
        assert len(bodies[-1]) < 200
        assert _overlaps(page) == []

        # Tab goes on through the rows past the first ones built (4 stops a row).
        rows.first.locator("button.pick").focus()
        for _ in range(4 * 60):
            page.keyboard.press("Tab")
        assert page.evaluate("document.activeElement.dataset.focus") == "row-60"
        assert rows.count() < 100

        # The list's last row is reached by scrolling its box.
        page.locator("#waypoint-box").evaluate("(el) => { el.scrollTop = el.scrollHeight; }")
        page.wait_for_function(
            "[...document.querySelectorAll('#waypoints .num')]"
            ".some((el) => el.textContent === '2000')"
        )
        assert rows.count() < 100
        assert errors == []
    finally:
        page.context.close()
        process.send_signal(signal.SIGINT)
        try:
            process.wait(20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def test_a_leg_with_no_path_is_drawn_named_and_left_out_of_the_total(page: Any) -> None:
    """A waypoint on a pillar: its leg has no path; the route line still gives the planned
    legs' total and names the leg left out, and the leg's label says why."""
    checked_after(page, lambda: page.mouse.click(*screen_point(page, *FREE_SPOT)))
    total = float(page.locator("#route").inner_text().split(" · ")[1].split(" m")[0])
    start = screen_point(page, *FREE_SPOT)
    target = screen_point(page, *PILLAR)

    def drag() -> None:
        page.mouse.move(*start)
        page.mouse.down()
        page.mouse.move(*target, steps=12)
        page.mouse.up()

    checked_after(page, drag)
    assert page.evaluate("S.legs.filter((leg) => leg.points === null).map((leg) => leg.to)") == [7]
    route = page.locator("#route").inner_text()
    assert "not counting 1 leg with no path (7→8" in route
    planned = float(route.split(" · ")[1].split(" m planned")[0])
    assert planned < total  # the seven planned legs, without the last one
    label = page.locator(".leg-label.no-path")
    assert label.count() == 1 and label.inner_text() == "no path"
    assert (label.get_attribute("title") or "").startswith("no path from waypoint 7 to waypoint 8")
    assert _overlaps(page) == []
    assert page.errors == []  # type: ignore[attr-defined]


def test_order_shows_the_time_spent_and_cancel_gives_the_page_back(page: Any) -> None:
    """While the server orders the waypoints the page counts the seconds; Cancel gives
    the page back at once and stops the job, and the waypoints stay as they were (the
    late answer is dropped)."""
    held: list[Any] = []
    page.route("**/api/order/jobs", lambda route: held.append(route))
    before = page.evaluate("JSON.stringify(S.doc.waypoints)")
    page.get_by_test_id("order").select_option("shortest")
    page.wait_for_function(
        "document.getElementById('message').textContent.includes('… 1 s')", timeout=10_000
    )
    assert "finding the shortest order of 7 waypoints" in page.locator("#message").inner_text()
    assert page.get_by_test_id("order").is_disabled()
    page.get_by_test_id("order-cancel").click()
    message_of(page, "ordering cancelled")
    assert page.get_by_test_id("order-cancel").is_hidden()
    assert page.get_by_test_id("order").is_enabled()
    with page.expect_request("**/api/order/jobs/*/cancel", timeout=10_000):
        held[0].continue_()  # the job starts late: it is stopped, nothing changes
    page.wait_for_timeout(300)
    assert page.evaluate("JSON.stringify(S.doc.waypoints)") == before
    assert page.get_by_test_id("waypoint-row").count() == 7
    assert page.errors == []  # type: ignore[attr-defined]


def test_a_misplaced_waypoint_is_moved_to_the_nearest_free_spot_in_one_click(page: Any) -> None:
    start = screen_point(page, *FREE_SPOT)
    checked_after(page, lambda: page.mouse.click(*start))
    target = screen_point(page, *PILLAR)

    def drag() -> None:
        page.mouse.move(*start)
        page.mouse.down()
        page.mouse.move(*target, steps=12)
        page.mouse.up()

    checked_after(page, drag)
    assert page.get_by_test_id("problem").count() == 1
    checked_after(page, lambda: page.get_by_test_id("fix").click())
    assert page.get_by_test_id("problem").count() == 0
    x, y = page.evaluate("[S.doc.waypoints[7].x, S.doc.waypoints[7].y]")
    assert math.dist((x, y), PILLAR) < 0.5
    checked_after(page, lambda: page.keyboard.press("Control+z"))  # one undoable edit
    assert page.get_by_test_id("problem").count() == 1
    assert page.errors == []  # type: ignore[attr-defined]
