"""navseq studio at mission sizes: page ready, drag, typed change, Order…, live run.

On the TurtleBot3 arena (384 x 384 cells) and a generated 2000 x 2000 map (5 x 4 seeded
warehouses from :mod:`navseq.sim.mapgen`, joined by doorways), with missions of 7, 300,
2000 and 5000 waypoints (``--sizes``; spread over the free space in a serpentine tour,
the 7 on the arena being the example's), each served by ``navseq studio`` and driven in
headless Chromium (Debian's ``/usr/bin/chromium`` through Playwright):

- **page ready, first load**: from navigating to the studio's URL, right after it
  started, until the page says it is ready (map image drawn, waypoints painted, list
  built); **later loads**: median of ``--repeat`` fresh pages;
- **plans shown**: until the first check's answer (pre-flight problems and every leg
  planned) is drawn;
- **drag -> problems drawn**: a waypoint dragged with the mouse to another free spot,
  from the button's release until the server's answer (problems, the legs planned
  again) is drawn, as Playwright sees it (its own round trips to the browser included);
  **timed in the page**: the same from the mouseup event to the frame after the answer
  is drawn; **drag, page redraw**: the page's own part of it (the edit and the redraw,
  before the answer);
- **typed change -> redrawn**: a new x typed in the waypoint form (its change event)
  until the next frame, everything redrawn; **-> checked**: until the check's answer
  is drawn;
- **check (server)**: ``POST /api/check`` of one waypoint moved, as the page sends it
  (that waypoint against the answer it holds; its answer: the legs that changed);
- **Order…**: ``shortest route`` chosen, until the new order is drawn, at most
  ``--order-limit`` s (then Cancel is pressed: "> limit");
- **live updates/s**: run updates the page drew per second while the mission ran on
  the simulator at real time (``1×``).

Targets (issue 12 and the scale issue): ready <= 1.5 s at 5000, drag -> problems
<= 150 ms, typed change <= 100 ms, Order… <= 3 s at 400 and <= 30 s at 2000, live
>= 10/s at 5000.

    .venv/bin/python benchmarks/bench_studio.py [--repeat 3] [--sizes 7,300,2000,5000]
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
    """``count`` roomy free spots of the map's main region, in a serpentine tour: the map
    cut in boxes (finer until ``count`` of them hold a free spot), one spot per box."""
    from scipy import ndimage

    from navseq.commands.common import costmap_for_map

    costmap = costmap_for_map(map_yaml)
    labels, _ = ndimage.label(costmap.free_mask(), structure=np.ones((3, 3), bool))
    main = np.bincount(labels[labels > 0]).argmax()
    # As roomy as the map allows for that many (5000 on the small arena: closer to walls).
    for clearance in (0.3, 0.2, 0.15, 0.1, 0.0):
        cells = np.argwhere(
            costmap.free_mask() & (costmap.clearance >= clearance) & (labels == main)
        )
        if len(cells) >= 2 * count:
            break
    if len(cells) < count:
        raise SystemExit(f"{map_yaml.name} has no room for {count} waypoints")
    rng = np.random.default_rng(seed)
    rows, cols = costmap.cost.shape
    side = int(np.ceil(np.sqrt(count)))
    while True:
        band, column = cells[:, 0] * side // rows, cells[:, 1] * side // cols
        # Serpentine: odd bands run right to left.
        key = band * side + np.where(band % 2 == 0, column, side - 1 - column)
        boxes = np.unique(key)
        if len(boxes) >= count or side >= max(rows, cols):
            break
        side = min(side + max(1, side // 8), max(rows, cols))
    order = np.argsort(key, kind="stable")
    sorted_keys = key[order]
    picked: list[tuple[float, float]] = []
    for box in boxes[:count]:
        lo, hi = np.searchsorted(sorted_keys, [box, box + 1])
        row, col = cells[order[lo + rng.integers(hi - lo)]]
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
    """A folder with ``mission.yaml``: the start pose on ``points[0]``, waypoints after."""
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


class Served:
    """``navseq studio MISSION --no-browser`` as a user starts it."""

    def __init__(self, mission: Path) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "navseq", "studio", str(mission), "--no-browser"],
            cwd=mission.parent,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        assert self.process.stdout is not None
        self.url = self.process.stdout.readline().split(": ", 1)[1].strip()
        self.base, _, self.token = self.url.partition("/?token=")

    def call(self, method: str, path: str, body: Any = None) -> Any:
        import urllib.request

        headers = {"x-navseq-token": self.token, "content-type": "application/json"}
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(self.base + path, data, headers, method=method)
        with urllib.request.urlopen(request, timeout=300) as answer:
            return json.load(answer)

    def close(self) -> None:
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def load(browser: Any, url: str) -> tuple[float, float, Any]:
    """(page ready, plans shown) in seconds from navigating to ``url`` in a fresh page
    (its own context: nothing cached by the browser), and the page."""
    # bypass_csp: Playwright evaluates the string expressions waited for with eval.
    context = browser.new_context(viewport={"width": 1400, "height": 860}, bypass_csp=True)
    page = context.new_page()
    began = time.perf_counter()
    page.goto(url)
    page.wait_for_selector("body[data-ready=true]", state="attached", timeout=120_000)
    ready = time.perf_counter() - began
    page.wait_for_selector("body[data-planned=true]", state="attached", timeout=600_000)
    return ready, time.perf_counter() - began, page


def checked_after(page: Any, action: Callable[[], None]) -> float:
    """Seconds from ``action`` until the page drew the answer of the check it sent."""
    before = page.evaluate("Number(document.body.dataset.checked || 0)")
    began = time.perf_counter()
    action()
    page.wait_for_function(
        f"Number(document.body.dataset.checked || 0) > {before}", timeout=120_000, polling=5
    )
    return time.perf_counter() - began


# In the page: from the button's release (the mouseup event) to the frame after the
# check's answer is drawn (data-checked set), without the harness's own round trips.
WATCH_DRAG = """() => new Promise((done) => {
    let released = null;
    const release = () => { released = performance.now(); };
    addEventListener("mouseup", release, { capture: true, once: true });
    const seen = new MutationObserver(() => {
        seen.disconnect();
        requestAnimationFrame(() => done(performance.now() - released));
    });
    seen.observe(document.body, { attributes: true, attributeFilter: ["data-checked"] });
})"""


def drags(page: Any, moves: list[tuple[float, float]]) -> tuple[float, float, float]:
    """Median (drag -> answer drawn, the page's own redraw of the drop, drag -> answer
    drawn as the page times it) in seconds: waypoint 3 dragged to each of ``moves`` with
    the mouse, the view centred on it first."""
    answered, redrawn, in_page = [], [], []
    for x, y in moves:
        page.evaluate(
            "() => { const w = S.doc.waypoints[2]; map.setView([w.y, w.x], map.getZoom(),"
            " { animate: false }); missionLayer.draw(); }"
        )
        box = page.get_by_test_id("map").bounding_box()
        mark = page.evaluate("missionLayer.drawn().marks[2]")
        target = page.evaluate(
            "([x, y]) => { const p = map.latLngToContainerPoint(L.latLng(y, x));"
            " return [p.x, p.y]; }",
            [x, y],
        )
        page.mouse.move(box["x"] + mark["x"], box["y"] + mark["y"])
        page.mouse.down()
        page.mouse.move(box["x"] + target[0], box["y"] + target[1], steps=4)
        page.evaluate("() => { window.dragTimed = (" + WATCH_DRAG + ")(); }")
        answered.append(checked_after(page, page.mouse.up))
        redrawn.append(page.evaluate("S.dragDropMs"))
        in_page.append(page.evaluate("window.dragTimed"))
    return (
        statistics.median(answered),
        statistics.median(redrawn) / 1e3,
        statistics.median(in_page) / 1e3,
    )


TYPE_X = """async (x) => {
    const input = document.getElementById("fields-x");
    input.value = String(x);
    const began = performance.now();
    input.dispatchEvent(new Event("change"));
    await new Promise((done) => requestAnimationFrame(() => done()));
    return performance.now() - began;
}"""


def typed_changes(page: Any, repeat: int) -> tuple[float, float]:
    """Median (typed x -> redrawn at the next frame, -> check drawn) in seconds."""
    page.get_by_test_id("waypoint-row").nth(2).click()
    x0 = page.evaluate("S.doc.waypoints[2].x")
    redrawn: list[float] = []
    checked: list[float] = []
    for k in range(repeat):

        def type_x(x: float = x0 + 0.01 * (k + 1)) -> None:
            redrawn.append(page.evaluate(TYPE_X, x) / 1e3)

        checked.append(checked_after(page, type_x))
    return statistics.median(redrawn), statistics.median(checked)


def check_latency(served: Served, moves: list[tuple[float, float]]) -> float:
    """Median seconds of ``POST /api/check`` with waypoint 3 moved to each of ``moves``,
    sent as the page sends it (that waypoint, against the answer whose draft and legs
    it holds)."""
    document = served.call("GET", "/api/mission")["mission"]
    base = served.call("POST", "/api/check", {"mission": document})["check"]
    times = []
    for x, y in moves:
        waypoint = {**document["waypoints"][2], "x": x + 0.05, "y": y}
        began = time.perf_counter()
        body = {"base": base, "changes": [[2, waypoint]]}
        base = served.call("POST", "/api/check", body)["check"]
        times.append(time.perf_counter() - began)
    return statistics.median(times)


def order_time(page: Any, limit: float) -> float:
    """Seconds until the page drew the shortest order; ``inf`` when it took over
    ``limit`` (Cancel pressed then: the page is given back), NaN when the server
    refused (its message printed)."""
    began = time.perf_counter()
    page.get_by_test_id("order").select_option("shortest")
    try:
        page.wait_for_function("!S.ordering", timeout=limit * 1e3, polling=20)
    except Exception:  # Playwright's timeout: cancel and say so
        page.get_by_test_id("order-cancel").click()
        page.wait_for_function(
            "document.getElementById('message').textContent.startsWith('ordering cancelled')"
        )
        return float("inf")
    took = time.perf_counter() - began
    said = str(page.locator("#message").inner_text())
    if said.startswith("waypoints put") or "already are" in said:
        return took
    print(f"Order… answered after {took:.1f} s: {said}", file=sys.stderr)
    return float("nan")


def live_rate(page: Any, seconds: float) -> float:
    """Run updates the page drew per second while the mission ran at 1x."""
    page.locator("#speed").select_option("1")
    page.get_by_test_id("run").click()
    page.wait_for_function(
        "document.querySelector('[data-testid=run-status]').dataset.status === 'running'",
        timeout=300_000,
    )
    first = page.evaluate("S.runUpdates")
    began = time.perf_counter()
    page.wait_for_timeout(seconds * 1e3)
    rate = (page.evaluate("S.runUpdates") - first) / (time.perf_counter() - began)
    page.get_by_test_id("stop").click()
    page.wait_for_function(
        "['stopped', 'completed', 'failed', 'error'].includes("
        "document.querySelector('[data-testid=run-status]').dataset.status)",
        timeout=60_000,
    )
    return float(rate)


def measure(
    browser: Any, mission: Path, moves: list[tuple[float, float]], args: argparse.Namespace
) -> dict[str, float]:
    """Every figure of one mission on one map (a studio started for it)."""
    figures: dict[str, float] = {}
    served = Served(mission)
    try:
        figures["first"], figures["first_plans"], page = load(browser, served.url)
        page.context.close()
        ready, planned = [], []
        for _ in range(args.repeat):
            shown, plans, page = load(browser, served.url)
            ready.append(shown)
            planned.append(plans)
            page.context.close()
        figures["ready"], figures["plans"] = statistics.median(ready), statistics.median(planned)
        figures["waypoints"] = page_count = 0.0
        shown, plans, page = load(browser, served.url)
        page_count = page.evaluate("S.doc.waypoints.length")
        figures["waypoints"] = float(page_count)
        figures["drag"], figures["drag_page"], figures["drag_in_page"] = drags(page, moves)
        figures["typed"], figures["typed_checked"] = typed_changes(page, args.repeat)
        figures["check"] = check_latency(served, moves)
        if page_count in args.order_sizes:
            page.keyboard.press("Escape")
            figures["order"] = order_time(page, args.order_limit)
        figures["live"] = live_rate(page, args.live_seconds)
        page.context.close()
    finally:
        served.close()
    return figures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="page loads, drags, typed changes")
    parser.add_argument("--sizes", default="7,300,2000,5000", help="waypoints per mission")
    parser.add_argument("--order-sizes", default="400,2000", help="missions Order… is timed on")
    parser.add_argument("--order-limit", type=float, default=60.0, help="seconds, then Cancel")
    parser.add_argument("--live-seconds", type=float, default=5.0)
    parser.add_argument("--maps", default="turtlebot3,warehouses", help="which maps")
    args = parser.parse_args()
    sizes = [int(n) for n in args.sizes.split(",")]
    args.order_sizes = {int(n) for n in args.order_sizes.split(",") if n}
    if not Path(CHROMIUM).exists():
        print(f"no Chromium at {CHROMIUM}: scripts/install-browser.sh", file=sys.stderr)
        return 2
    from playwright.sync_api import sync_playwright

    base = Path(tempfile.mkdtemp(prefix="navseq-bench-studio-"))
    try:
        shutil.copytree(ROOT / "maps", base / "maps")
        maps = {
            "turtlebot3": base / "maps/turtlebot3_world.yaml",
            "warehouses": save_map(big_map(), base / "maps/warehouses_2000.yaml"),
        }
        tb3_seven = [
            (-2.0, -0.5),
            (-0.55, -1.75),
            (1.75, -0.55),
            (0.55, 0.55),
            (0.0, 1.75),
            (-1.75, 0.55),
            (-0.55, -0.55),
            (-2.0, -0.5),
        ]
        cases: dict[str, tuple[Path, list[tuple[float, float]]]] = {}
        for map_name in args.maps.split(","):
            map_yaml = maps[map_name]
            counts = sorted(set(sizes) | (args.order_sizes - set(sizes)))
            for count in counts:
                if map_name == "turtlebot3" and count == 7:
                    points = tb3_seven
                else:
                    points = spread_waypoints(map_yaml, count + 1, seed=4)  # + the start
                mission = workspace(base, f"{map_name}-{count}", map_yaml, points)
                # Waypoint 3 dragged to a new free spot each time (its legs are planned
                # again: none comes from the leg cache), a few marker widths away.
                x, y = points[3]
                step = 0.6 if map_name == "warehouses" else 0.08
                moves: list[tuple[float, float]] = []
                k = 0
                while len(moves) < args.repeat:  # nearby spots may be one: farther then
                    spot = nearby_free(map_yaml, x, y, step * (k + 1), step * (k % 2))
                    k += 1
                    if spot not in moves and spot != (x, y):
                        moves.append(spot)
                cases[f"{map_name} {count}"] = (mission, moves)
        figures: dict[str, dict[str, float]] = {}
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
            for name, (mission, moves) in cases.items():
                print(f"measuring {name}…", file=sys.stderr, flush=True)
                figures[name] = measure(browser, mission, moves, args)
            browser.close()
        seconds: Callable[[float], str] = lambda v: f"{v:.2f}"  # noqa: E731
        millis: Callable[[float], str] = lambda v: f"{v * 1e3:.0f}"  # noqa: E731
        limit = args.order_limit
        rows: dict[str, tuple[str, str, Callable[[float], str]]] = {
            "waypoints": ("waypoints", "", lambda v: f"{v:.0f}"),
            "first": ("page ready, first load [s]", "<= 1.5", seconds),
            "ready": ("page ready, later loads [s]", "<= 1.5", seconds),
            "first_plans": ("plans shown, first load [s]", "", seconds),
            "plans": ("plans shown, later loads [s]", "", seconds),
            "drag": ("drag -> problems drawn [ms]", "<= 150", millis),
            "drag_in_page": ("  drag -> drawn, timed in the page [ms]", "", millis),
            "drag_page": ("  drag, page redraw [ms]", "", millis),
            "typed": ("typed change -> redrawn [ms]", "<= 100", millis),
            "typed_checked": ("typed change -> checked [ms]", "", millis),
            "check": ("check, server [ms]", "", millis),
            "order": (
                "Order… shortest [s]",
                "<= 3 (400), 30 (2000)",
                lambda v: (
                    f"> {limit:.0f}, cancelled"
                    if v == float("inf")
                    else "refused"
                    if v != v
                    else f"{v:.1f}"
                ),
            ),
            "live": ("live updates/s at 1x", ">= 10", lambda v: f"{v:.1f}"),
        }
        table = Table(title=f"navseq studio (median of {args.repeat}; Chromium headless)")
        table.add_column("measure")
        for name in cases:
            table.add_column(name.replace(" ", "\n"), justify="right")
        table.add_column("target", justify="right")
        for key, (label, target, shown) in rows.items():
            # escape: "[s]" would otherwise be taken as rich markup and vanish.
            row = (shown(figures[name][key]) if key in figures[name] else "" for name in cases)
            table.add_row(escape(label), *row, escape(target))
        Console(width=200).print(table)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
