"""navseq studio: page ready, drag -> problems latency and live updates, on two maps.

Side by side on the TurtleBot3 arena (384 x 384 cells) and a generated 2000 x 2000 map
(5 x 4 seeded warehouses from :mod:`navseq.sim.mapgen`, joined by doorways), each with a
mission of a dozen waypoints:

- **page ready**: from navigating to the studio's URL until the page says it is ready
  (map image drawn, markers placed), in headless Chromium (Debian's
  ``/usr/bin/chromium`` through Playwright), median of ``--repeat`` loads; the first
  load is the one right after ``navseq studio`` started (nothing made yet), the studio
  started ``--repeat`` times for it; later loads are fresh pages on a studio that
  served the page once already;
- **plans shown**: from navigating until the first check's answer (pre-flight
  problems and every leg planned) is drawn; before the page had ``data-planned`` it
  was ready only then, so it is its ready time;
- **before**: with ``--before REF`` (a git commit, e.g. ``main``) the studio of that
  commit is served too (its ``src/`` exported, the compiled A* copied in) and its page
  figures are put beside the current ones, measured on the same maps and run;
- **drag -> problems (page)**: a waypoint marker dragged with the mouse to another free
  spot, until the page has the server's answer (problems and planned legs) drawn;
- **check (server)**: ``POST /api/check`` of the mission with one waypoint moved,
  in process, with the costmap kept per (map, robot) as the studio does, and rebuilt on
  every check as the first slice did (the ratio is what the cache saves);
- **live updates/s at 1x**: server-sent events received per second while the mission
  runs on the simulator at real time (``realtime: 1``), and how many of them showed
  the robot moved.

Targets (issue 12): ready <= 1 s / 2 s, drag -> problems <= 150 ms / 500 ms, live >= 10/s.

    .venv/bin/python benchmarks/bench_studio.py [--repeat 5] [--live-seconds 6] [--before main]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from math import cos, sin
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from navseq.geometry import Pose2D
from navseq.sim.mapgen import save_map, warehouse_map
from navseq.sim.occupancy import OccupancyGrid

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = os.environ.get("NAVSEQ_CHROMIUM", "/usr/bin/chromium")
BIG = 2000
DOOR_CELLS = 30  # 1.5 m doorways between neighbouring warehouses


def big_map() -> OccupancyGrid:
    """2000 x 2000 cells (100 m x 100 m at 5 cm): warehouses side by side, doors between."""
    data = np.zeros((BIG, BIG), np.int8)
    tile_h, tile_w = warehouse_map(0).data.shape  # 400 x 600
    seed = 0
    for top in range(0, BIG, tile_h):
        for left in range(0, BIG, tile_w):
            tile = warehouse_map(seed).data
            seed += 1
            h, w = min(tile_h, BIG - top), min(tile_w, BIG - left)
            data[top : top + h, left : left + w] = tile[:h, :w]
    half = DOOR_CELLS // 2
    for top in range(tile_h, BIG, tile_h):  # doors in the walls between rows of tiles
        for middle in range(tile_w // 2, BIG, tile_w):
            data[top - 3 : top + 3, middle - half : middle + half] = 0
    for left in range(tile_w, BIG, tile_w):  # and between columns: at both cross aisles
        for top in range(0, BIG, tile_h):
            for aisle in (20, tile_h - 30):
                data[top + aisle - half : top + aisle + half, left - 3 : left + 3] = 0
    data[:2, :] = data[-2:, :] = 100
    data[:, :2] = data[:, -2:] = 100
    return OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0), "big")


def spread_waypoints(map_yaml: Path, count: int, seed: int) -> list[tuple[float, float]]:
    """``count`` roomy free spots of the map's main region, in a serpentine tour."""
    from scipy import ndimage

    from navseq.commands.common import costmap_for_map

    costmap = costmap_for_map(map_yaml)
    free = costmap.free_mask() & (costmap.clearance >= 0.5)
    labels, _ = ndimage.label(costmap.free_mask(), structure=np.ones((3, 3), bool))
    main = np.bincount(labels[labels > 0]).argmax()
    cells = np.argwhere(free & (labels == main))
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(count)))
    rows, cols = costmap.cost.shape
    picked: list[tuple[float, float]] = []
    for band in range(side):
        order = range(side) if band % 2 == 0 else range(side - 1, -1, -1)
        for column in order:
            if len(picked) == count:
                break
            in_box = cells[
                (cells[:, 0] * side // rows == band) & (cells[:, 1] * side // cols == column)
            ]
            if len(in_box):
                row, col = in_box[rng.integers(len(in_box))]
                x, y = costmap.cell_to_world(int(row), int(col))
                picked.append((round(x, 2), round(y, 2)))
    return picked


def nearby_free(map_yaml: Path, x: float, y: float, dx: float, dy: float) -> tuple[float, float]:
    """The roomy free spot nearest to (x + dx, y + dy): where the drag goes."""
    from navseq.commands.common import costmap_for_map

    costmap = costmap_for_map(map_yaml)
    cells = np.argwhere(costmap.free_mask() & (costmap.clearance >= 0.4))
    row, col = costmap.world_to_cell(x + dx, y + dy)
    nearest = cells[np.argmin(((cells - (row, col)) ** 2).sum(axis=1))]
    fx, fy = costmap.cell_to_world(int(nearest[0]), int(nearest[1]))
    return round(fx, 2), round(fy, 2)


def workspace(base: Path, name: str, map_yaml: Path, points: list[tuple[float, float]]) -> Path:
    folder = base / name
    folder.mkdir()
    mission = {
        "navseq": 1,
        "map": os.path.relpath(map_yaml, folder),
        "start": {"x": points[0][0], "y": points[0][1], "yaw": 0},
        "waypoints": [{"x": x, "y": y, "yaw": 0} for x, y in points[1:]],
    }
    path = folder / "mission.yaml"
    path.write_text(json.dumps(mission), encoding="utf-8")
    return path


# --- in process: the check's latency ---------------------------------------------------


def check_latency(mission: Path, moves: list[tuple[float, float]], cached: bool) -> float:
    """Median time of the studio's check after moving waypoint 2 to each of ``moves``."""
    from navseq.commands.common import costmap_for_map
    from navseq.studio.app import Studio, StudioConfig
    from navseq.studio.security import FileRoots

    roots = FileRoots([mission.parent, mission.parent.parent], mission.parent)
    studio = Studio(StudioConfig(token="t", roots=roots, mission_path=mission))
    if not cached:  # the first slice: validate's function inflated the map every time
        studio.costmap = lambda map_path, robot: costmap_for_map(map_path, robot)  # type: ignore[method-assign]
    document = studio.mission()["mission"]
    studio.check(document)  # the page's first check, on opening
    times = []
    for x, y in moves:
        document["waypoints"][2].update(x=x, y=y)
        began = time.perf_counter()
        answer = studio.check(document)
        times.append(time.perf_counter() - began)
        assert answer["legs"], answer
    return statistics.median(times)


# --- the real thing: navseq studio and a browser ----------------------------------------


class Served:
    """``navseq studio MISSION --no-browser`` as a user starts it."""

    def __init__(self, mission: Path, source: Path | None = None) -> None:
        env = dict(os.environ)
        if source is not None:  # another commit's navseq (--before)
            env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(source), env.get("PYTHONPATH")]))
        self.process = subprocess.Popen(
            [sys.executable, "-m", "navseq", "studio", str(mission), "--no-browser"],
            cwd=mission.parent,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        assert self.process.stdout is not None
        self.url = self.process.stdout.readline().split(": ", 1)[1].strip()
        self.base, _, self.token = self.url.partition("/?token=")

    def close(self) -> None:
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


# The first check's plans are drawn: data-planned, or (a page from before it had it)
# data-ready, which that page set only once the first check was drawn.
PLANS_SHOWN = (
    "document.body.dataset.planned === 'true' ||"
    " (typeof S.planned === 'undefined' && document.body.dataset.ready === 'true')"
)


def load(browser: Any, url: str) -> tuple[float, float, Any]:
    """(page ready, plans shown) in seconds from navigating to ``url`` in a fresh page
    (its own context: nothing cached by the browser), and the page."""
    page = browser.new_page(viewport={"width": 1400, "height": 860})
    began = time.perf_counter()
    page.goto(url)
    page.wait_for_selector("body[data-ready=true]", state="attached", timeout=60_000)
    ready = time.perf_counter() - began
    page.wait_for_function(PLANS_SHOWN, timeout=60_000, polling=10)
    return ready, time.perf_counter() - began, page


def first_loads(
    mission: Path, sources: dict[str, Path | None], repeat: int
) -> dict[str, dict[str, float]]:
    """Median (page ready, plans shown) of the first load right after ``navseq studio``
    started (nothing made yet: the map's PNG, costmap and plans are made then), each
    source's studio started ``repeat`` times, the sources in turn so that they share
    the machine's ups and downs."""
    from playwright.sync_api import sync_playwright

    ready: dict[str, list[float]] = {label: [] for label in sources}
    planned: dict[str, list[float]] = {label: [] for label in sources}
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        for _ in range(repeat):
            for label, source in sources.items():
                served = Served(mission, source)
                try:
                    shown, plans, page = load(browser, served.url)
                    page.close()
                finally:
                    served.close()
                ready[label].append(shown)
                planned[label].append(plans)
        browser.close()
    return {
        label: {
            "first": statistics.median(ready[label]),
            "first_plans": statistics.median(planned[label]),
        }
        for label in sources
    }


def page_figures(served: Served, moves: list[tuple[float, float]], repeat: int) -> dict[str, float]:
    """Seconds: median page ready and plans shown of later loads (after a first one,
    not counted), and median drag -> problems drawn (absent when ``moves`` is empty)."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        load(browser, served.url)[2].close()  # the first load: first_loads measures it
        ready, planned = [], []
        for _ in range(repeat):
            shown, plans, page = load(browser, served.url)
            ready.append(shown)
            planned.append(plans)
            if len(ready) < repeat:
                page.close()
        drags = []
        for x, y in moves:
            marker = page.get_by_test_id("waypoint-marker").nth(2).bounding_box()
            assert marker is not None
            start = (marker["x"] + marker["width"] / 2, marker["y"] + marker["height"] / 2)
            target = page.evaluate(
                "([x, y]) => { const p = map.latLngToContainerPoint(L.latLng(y, x));"
                " const b = document.getElementById('map').getBoundingClientRect();"
                " return [b.left + p.x, b.top + p.y]; }",
                [x, y],
            )
            before = page.evaluate("Number(document.body.dataset.checked || 0)")
            page.mouse.move(*start)
            page.mouse.down()
            page.mouse.move(*target, steps=4)
            began = time.perf_counter()
            page.mouse.up()  # the drag ends: the page sends the check
            page.wait_for_function(
                f"Number(document.body.dataset.checked || 0) > {before}", timeout=60_000
            )
            drags.append(time.perf_counter() - began)
        browser.close()
    figures = {"ready": statistics.median(ready), "plans": statistics.median(planned)}
    if drags:
        figures["drag"] = statistics.median(drags)
    return figures


def exported(ref: str, into: Path) -> Path:
    """``src/`` of git commit ``ref`` under ``into``, with this tree's compiled A*."""
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", ref, "src"], check=True, capture_output=True
    ).stdout
    into.mkdir(parents=True)
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    for built in (ROOT / "src/navseq/sim").glob("_astar*.so"):
        shutil.copy2(built, into / "src/navseq/sim" / built.name)
    return into / "src"


def live_rate(served: Served, seconds: float) -> tuple[float, float]:
    """(events/s, events/s in which the robot had moved) while running at 1x."""
    import urllib.request

    headers = {"x-navseq-token": served.token, "content-type": "application/json"}

    def call(method: str, path: str, body: Any = None) -> Any:
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(served.base + path, data, headers, method=method)
        return urllib.request.urlopen(request, timeout=60)

    with call("GET", "/api/mission") as answer:
        document = json.load(answer)["mission"]
    call("POST", "/api/run", {"mission": document, "realtime": 1}).close()
    events, moved, last_pose = 0, 0, None
    began = time.perf_counter()
    with call("GET", "/api/run/events") as stream:
        for raw in stream:
            line = raw.decode()
            if not line.startswith("data: "):
                continue
            state = json.loads(line[6:])
            if state["status"] == "starting":
                began = time.perf_counter()
                continue
            events += 1
            if state["pose"] != last_pose:
                moved += 1
            last_pose = state["pose"]
            if time.perf_counter() - began >= seconds:
                break
    elapsed = time.perf_counter() - began
    call("POST", "/api/run/stop", {}).close()
    return events / elapsed, moved / elapsed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5, help="page loads and drags per map")
    parser.add_argument("--live-seconds", type=float, default=6.0)
    parser.add_argument(
        "--before", metavar="REF", help="also measure the page loads of git commit REF"
    )
    args = parser.parse_args()
    if not Path(CHROMIUM).exists():
        print(f"no Chromium at {CHROMIUM}: scripts/install-browser.sh", file=sys.stderr)
        return 2
    base = Path(tempfile.mkdtemp(prefix="navseq-bench-studio-"))
    try:
        shutil.copytree(ROOT / "maps", base / "maps")
        big_yaml = save_map(big_map(), base / "maps/warehouses_2000.yaml")
        tb3_yaml = base / "maps/turtlebot3_world.yaml"
        tb3_points = [
            (-2.0, -0.5),
            (-0.55, -1.75),
            (1.75, -0.55),
            (0.55, 0.55),
            (0.0, 1.75),
            (-1.75, 0.55),
            (-0.55, -0.55),
            (-2.0, -0.5),
        ]
        cases: dict[str, tuple[Path, Path, list[tuple[float, float]]]] = {}
        for name, map_yaml, points in (
            ("turtlebot3_world 384x384", tb3_yaml, tb3_points),
            ("warehouses 2000x2000", big_yaml, spread_waypoints(big_yaml, 13, seed=4)),
        ):
            mission = workspace(base, name.split()[0], map_yaml, points)
            # Waypoint 3 (index 2) dragged to a new free spot each time, so that its two
            # legs are planned again every time (none comes from the leg cache).
            x, y = points[3]
            step = 0.6 if "2000" in name else 0.08  # several pixels at the fit zoom: a drag
            moves = [
                nearby_free(map_yaml, x, y, *(step * (k + 1) * f(2.4 * k) for f in (cos, sin)))
                for k in range(args.repeat)
            ]
            assert len(set(moves)) == len(moves), moves
            cases[name] = (mission, map_yaml, moves)

        before = exported(args.before, base / "before") if args.before else None
        figures: dict[str, dict[str, float]] = {name: {} for name in cases}
        for name, (mission, _, moves) in cases.items():
            rebuilt = check_latency(mission, moves, cached=False)
            cached = check_latency(mission, moves, cached=True)
            sources: dict[str, Path | None] = {"": None}
            if before is not None:
                sources["_before"] = before
            for suffix, measured in first_loads(mission, sources, args.repeat).items():
                figures[name].update({key + suffix: value for key, value in measured.items()})
            if before is not None:
                served = Served(mission, before)
                try:
                    old = page_figures(served, [], args.repeat)
                finally:
                    served.close()
                figures[name].update({f"{key}_before": value for key, value in old.items()})
            served = Served(mission)
            try:
                figures[name].update(page_figures(served, moves, args.repeat))
                live, moving = live_rate(served, args.live_seconds)
            finally:
                served.close()
            figures[name] |= {
                "rebuilt": rebuilt,
                "cached": cached,
                "live": live,
                "moving": moving,
            }
        seconds: Callable[[float], str] = lambda v: f"{v:.2f}"  # noqa: E731
        then = f"  before ({args.before})"
        targets = {
            "first": ("page ready, first load [s]", "<= 1 / 2", seconds),
            "first_before": (then, "", seconds),
            "ready": ("page ready, later loads [s]", "<= 1 / 2", seconds),
            "ready_before": (then, "", seconds),
            "first_plans": ("plans shown, first load [s]", "", seconds),
            "first_plans_before": (then, "", seconds),
            "plans": ("plans shown, later loads [s]", "", seconds),
            "plans_before": (then, "", seconds),
            "drag": (
                "drag -> problems drawn, page [ms]",
                "<= 150 / 500",
                lambda v: f"{v * 1e3:.0f}",
            ),
            "cached": ("check, costmap kept [ms]", "", lambda v: f"{v * 1e3:.0f}"),
            "rebuilt": ("check, costmap rebuilt (1st slice) [ms]", "", lambda v: f"{v * 1e3:.0f}"),
            "ratio": ("rebuilt / kept", "", lambda v: f"{v:.1f}x"),
            "live": ("live updates/s at 1x", ">= 10", lambda v: f"{v:.1f}"),
            "moving": ("  of which the robot moved /s", "", lambda v: f"{v:.1f}"),
        }
        for name in cases:
            figures[name]["ratio"] = figures[name]["rebuilt"] / figures[name]["cached"]
        table = Table(title=f"navseq studio (median of {args.repeat}; Chromium headless)")
        table.add_column("measure")
        for name in cases:
            table.add_column(name, justify="right")
        table.add_column("target", justify="right")
        for key, (label, target, shown) in targets.items():
            if key.endswith("_before") and before is None:
                continue
            format_: Callable[[float], str] = shown
            # escape: "[s]" would otherwise be taken as rich markup and vanish.
            row = (format_(figures[name][key]) for name in cases)
            table.add_row(escape(label), *row, escape(target))
        Console(width=120).print(table)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
