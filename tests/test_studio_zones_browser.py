"""The studio page's keepout / speed zones toggle, in a real headless Chromium: the
overlay the server draws (tests/test_studio_zones.py checks its pixels) shows on the map."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CHROMIUM = os.environ.get("NAVSEQ_CHROMIUM", "/usr/bin/chromium")

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _skip_unless_there() -> None:
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        reason: str | None = "Playwright is not installed (pip install playwright)"
    else:
        reason = None if Path(CHROMIUM).exists() else f"no Chromium at {CHROMIUM}"
    if reason is not None:
        if os.environ.get("NAVSEQ_EXPECT_BROWSER") == "1":
            pytest.fail(reason)
        pytest.skip(reason)


def test_the_zones_toggle_shows_the_missions_keepout_and_speed_zones(tmp_path: Path) -> None:
    _skip_unless_there()
    from playwright.sync_api import sync_playwright

    shutil.copytree(REPO / "examples", tmp_path / "examples")
    shutil.copytree(REPO / "maps", tmp_path / "maps")
    process = subprocess.Popen(
        [sys.executable, "-m", "navseq", "studio", "examples/keepout.yaml", "--no-browser"],
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
                page = browser.new_context(viewport={"width": 1400, "height": 860}).new_page()
                errors: list[str] = []
                page.on("pageerror", lambda error: errors.append(str(error)))
                page.goto(url)
                page.wait_for_selector("body[data-ready=true]", state="attached", timeout=20_000)
                assert page.get_by_test_id("zones-image").count() == 0
                page.locator("#zones-toggle").check()
                image = page.get_by_test_id("zones-image")
                image.wait_for(state="attached", timeout=10_000)
                loaded = image.evaluate(
                    "(img) => new Promise((done) => img.complete ? done(img.naturalWidth)"
                    " : img.addEventListener('load', () => done(img.naturalWidth)))"
                )
                assert loaded == 384  # the arena's map, cell for cell
                page.locator("#zones-toggle").uncheck()
                assert page.get_by_test_id("zones-image").count() == 0
                assert errors == []
            finally:
                browser.close()
    finally:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
