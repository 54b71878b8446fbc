"""navseq studio's fleet view: live updates of all robots per second, drawn in the page.

Each case is served by ``navseq studio --fleet FLEET`` and driven in headless Chromium
(Debian's ``/usr/bin/chromium`` through Playwright): Run fleet at the chosen pace, then,
once the robots move, the page's fleet updates drawn (every robot's pose, waypoint and
state, the fleet's totals) are counted over ``--window`` wall seconds; the server's
snapshots are sent at most 20 a second. Cases: the example fleet (3 robots on the
TurtleBot3 arena) and ``--robots`` burgers on a generated warehouse sharing 3 random
waypoints per robot (seeded, ``warehouse_fleet``), each at 1x and 5x real time.
Target (issue 21): >= 10 updates/s of all robots' poses.

    .venv/bin/python benchmarks/bench_studio_fleet.py [--window 5] [--robots 10]
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = os.environ.get("NAVSEQ_CHROMIUM", "/usr/bin/chromium")


def warehouse_fleet(folder: Path, robots: int, seed: int = 7) -> Path:
    """A fleet file of ``robots`` burgers at roomy spots of a generated warehouse, sharing
    a mission of 3 waypoints per robot at other roomy spots."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_fleet import roomy_spots

    from navseq.sim.costmap import Costmap
    from navseq.sim.mapgen import save_map, warehouse_map
    from navseq.sim.profile import SimSettings

    grid = warehouse_map(seed)
    save_map(grid, folder / "warehouse.yaml")
    costmap = Costmap.from_grid(grid, SimSettings.of().costmap_params)
    spots = roomy_spots(costmap, 4 * robots, np.random.default_rng(seed))
    starts, goals = spots[:robots], spots[robots:]
    lines = ["navseq: 1", "map: warehouse.yaml", "defaults: {on_failure: skip}", "waypoints:"]
    lines += [f"  - {{x: {g.x:.2f}, y: {g.y:.2f}, yaw: 0}}" for g in goals]
    (folder / "mission.yaml").write_text("\n".join(lines) + "\n")
    fleet = ["navseq_fleet: 1", "mission: mission.yaml", "robots:"]
    fleet += [
        f"  - {{name: r{k}, start: {{x: {s.x:.2f}, y: {s.y:.2f}, yaw: 0}}}}"
        for k, s in enumerate(starts)
    ]
    path = folder / "fleet.yaml"
    path.write_text("\n".join(fleet) + "\n")
    return path


def updates_per_second(workspace: Path, fleet: str, speed: str, window: float) -> float:
    """The page's fleet updates drawn per wall second while the fleet runs at ``speed``."""
    from playwright.sync_api import sync_playwright

    process = subprocess.Popen(
        [sys.executable, "-m", "navseq", "studio", "--fleet", fleet, "--no-browser"],
        cwd=workspace,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert process.stdout is not None
        url = process.stdout.readline().split(": ", 1)[1].strip()
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
            try:
                page = browser.new_context(
                    viewport={"width": 1400, "height": 860}, bypass_csp=True
                ).new_page()
                page.goto(url)
                page.wait_for_selector("body[data-ready=true]", state="attached", timeout=60_000)
                page.wait_for_function("document.getElementById('fleet-file').value !== ''")
                page.locator("#speed").select_option(speed)
                page.get_by_test_id("fleet-run").click()
                page.wait_for_function(
                    "FLEET.data && FLEET.data.status === 'running' && FLEET.data.clock_s > 0.5",
                    timeout=120_000,
                )
                # Counted while the fleet runs only (a fast one may end inside the window).
                before = page.evaluate("FLEET.updates")
                started = last = time.monotonic()
                after = before
                while last - started < window:
                    time.sleep(0.25)
                    updates, status = page.evaluate("[FLEET.updates, FLEET.data.status]")
                    if status != "running":
                        break
                    after, last = updates, time.monotonic()
                page.get_by_test_id("fleet-stop").click()
                page.wait_for_function("FLEET.data.status !== 'running'", timeout=60_000)
                return (after - before) / (last - started) if last > started else float("nan")
            finally:
                browser.close()
    finally:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(60)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--window", type=float, default=5.0, help="wall seconds counted")
    parser.add_argument("--robots", type=int, default=10, help="robots on the warehouse")
    args = parser.parse_args()
    base = Path(tempfile.mkdtemp(prefix="navseq-bench-fleet-"))
    try:
        shutil.copytree(ROOT / "examples", base / "examples")
        shutil.copytree(ROOT / "maps", base / "maps")
        warehouse = base / "warehouse"
        warehouse.mkdir()
        warehouse_fleet(warehouse, args.robots)
        cases = {
            "arena, 3 robots": (base, "examples/fleet.yaml"),
            f"warehouse, {args.robots} robots": (warehouse, "fleet.yaml"),
        }
        table = Table(
            title=f"navseq studio, fleet live view (Chromium headless, {args.window:g} s)"
        )
        table.add_column("fleet")
        for speed in ("1x", "5x"):
            table.add_column(f"updates/s at {speed}", justify="right")
        table.add_column("target", justify="right")
        for name, (workspace, fleet) in cases.items():
            rates = [updates_per_second(workspace, fleet, s, args.window) for s in ("1", "5")]
            table.add_row(name, *(f"{rate:.1f}" for rate in rates), ">= 10")
        Console(width=160).print(table)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
