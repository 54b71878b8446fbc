"""Past fleet runs: the folder ``navseq run --fleet`` (or the studio) left, replayed on one clock.

A fleet run folder holds ``fleet-run.json`` (the split, written before any robot moved),
``fleet-report.json`` once the run ended, and a folder per robot with a share: its
mission, journal and report, exactly a one-robot run's. Each robot's folder is replayed
by the one-robot replay (:func:`navseq.studio.replay.replay_of`: only journaled poses,
the waypoints' states folded by the live view's rules); the robots share the fleet's
simulated clock, so each robot's timeline is shifted by its journal's first time onto
the fleet's, and the page plays all of them with one slider. Each robot keeps the colour
``fleet.png`` gives it (its place in the fleet, matplotlib's ``C0``, ``C1`` ...).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.studio.security import FileRoots

FLEET_MANIFEST = "fleet-run.json"  # navseq.fleet.manifest.MANIFEST_NAME, read without the fleet
FLEET_REPORT = "fleet-report.json"
#: matplotlib's default colour cycle (``C0`` ... ``C9``, "tab10"): fleet.png's robot colours.
ROBOT_COLOURS = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)


def robot_colour(place: int) -> str:
    """The colour of the fleet's ``place``-th robot (from 0), as fleet.png draws it."""
    return ROBOT_COLOURS[place % len(ROBOT_COLOURS)]


def fleet_run_folders(searched: list[Path]) -> list[Path]:
    """Folders holding a fleet run (its ``fleet-run.json``), one or two levels under each
    of ``searched``."""
    found: set[Path] = set()
    for top in searched:
        if not top.is_dir():
            continue
        for manifest in [*top.glob(f"*/{FLEET_MANIFEST}"), *top.glob(f"*/*/{FLEET_MANIFEST}")]:
            found.add(manifest.parent.resolve())
    return sorted(found)


def fleet_runs_listed(
    searched: list[Path], singles: list[Path], roots: FileRoots
) -> tuple[list[dict[str, Any]], list[Path]]:
    """The runs list's fleet runs under ``searched`` (one line each, where ``roots`` may
    read them), and ``singles`` without their robots' folders."""
    fleets = [folder for folder in fleet_run_folders(searched) if roots.contains(folder)]
    members = set(fleets)
    listed = []
    for folder in fleets:
        try:
            listed.append(fleet_run_summary(folder, roots.relative(folder)))
        except OSError:  # removed while listed
            continue
    return listed, [folder for folder in singles if folder.resolve().parent not in members]


def read_json(path: Path) -> dict[str, Any] | None:
    """The JSON object in ``path`` (NaN as null), or None when it cannot be read."""
    try:
        loaded = json.loads(path.read_text(encoding="utf-8"), parse_constant=lambda _: None)
    except (OSError, ValueError):
        return None
    return loaded if isinstance(loaded, dict) else None


def _robot_names(folder: Path) -> list[str]:
    """The fleet's robots in the fleet's order (its colours), from the manifest's split."""
    manifest = read_json(folder / FLEET_MANIFEST)
    shares = manifest.get("shares") if manifest is not None else None
    if not isinstance(shares, dict):
        raise NavseqError(
            f"{printable(folder.name)}: {FLEET_MANIFEST} is missing or damaged: not a fleet run"
        )
    return [str(name) for name in shares]


def fleet_run_summary(folder: Path, shown: str) -> dict[str, Any]:
    """One line of the runs list for a whole fleet run: robots, and reached of all."""
    report = read_json(folder / FLEET_REPORT)
    robots = report.get("robots") if report is not None else None
    robots = robots if isinstance(robots, list) else []
    manifest = read_json(folder / FLEET_MANIFEST) or {}
    shares = manifest.get("shares")
    shares = shares if isinstance(shares, dict) else {}
    stamp = folder / FLEET_REPORT
    return {
        "folder": shown,
        "fleet": True,
        "robots": len(shares) or len(robots),
        "modified_s": (stamp if stamp.exists() else folder / FLEET_MANIFEST).stat().st_mtime,
        "reason": None if report is not None else "no fleet report (stopped before its end?)",
        "reached": report.get("reached") if report is not None else None,
        "visits": sum(int(row.get("waypoints") or 0) for row in robots) if robots else None,
    }


def fleet_replay_of(
    folder: Path,
    shown: str,
    base_dir: Path,
    may_read: Callable[[Path], bool] = lambda path: False,
    shown_path: Callable[[Path], str] = str,
) -> dict[str, Any]:
    """The fleet run in ``folder`` as one timeline per robot on the fleet's clock
    (docs/studio.md, ``GET /api/fleet/replay``).

    ``base_dir`` and ``may_read`` are :func:`~navseq.studio.replay.replay_of`'s;
    ``shown_path(path)``: the map as the page names it (only where ``may_read``).
    Raises NavseqError when the folder is not a fleet run or a robot's journal with a
    share cannot be read.
    """
    from navseq.studio.replay import JOURNAL_NAME, replay_of

    names = _robot_names(folder)
    report = read_json(folder / FLEET_REPORT)
    rows = {
        str(row.get("name")): row
        for row in (report or {}).get("robots", [])
        if isinstance(row, dict)
    }
    robots: list[dict[str, Any]] = []
    replays: list[dict[str, Any] | None] = []
    for name in names:
        own = folder / name
        replay = None
        if (own / JOURNAL_NAME).is_file():
            try:
                replay = replay_of(own, f"{shown}/{name}", base_dir, may_read)
            except NavseqError as error:
                raise NavseqError(f"robot '{printable(name)}': {error}") from None
        replays.append(replay)
    parked = _parked_robots(folder, may_read)
    starts = [r["clock_start_s"] for r in replays if r is not None and r["poses"]]
    origin = min(starts, default=0.0)
    duration = 0.0
    for place, (name, replay) in enumerate(zip(names, replays, strict=True)):
        robot: dict[str, Any] = {
            "name": name,
            "colour": robot_colour(place),
            "report": rows.get(name),
            "replay": None,
            # A robot with no share has no journal: it stayed where the fleet file put it.
            "parked": parked.get(name) if replay is None else None,
        }
        if replay is not None:
            shift = round(replay["clock_start_s"] - origin, 3)
            _shift(replay, shift)
            duration = max(duration, shift + replay["duration_s"])
            robot["replay"] = replay
        robots.append(robot)
    return {
        "folder": shown,
        "fleet": True,
        "map": _map_shown(report, may_read, shown_path),
        "report": report,
        "duration_s": round(duration, 3),
        "robots": robots,
    }


def _parked_robots(folder: Path, may_read: Callable[[Path], bool]) -> dict[str, dict[str, Any]]:
    """Each robot's start pose and footprint from the run's fleet file, when the studio
    may read it and it is the file that was run (its sha256 in ``fleet-run.json``)."""
    from navseq.fleet.fleet_format import inspect_fleet
    from navseq.fleet.manifest import file_digest

    manifest = read_json(folder / FLEET_MANIFEST) or {}
    text = manifest.get("fleet")
    if not isinstance(text, str):
        return {}
    path = Path(text)
    try:
        if not (may_read(path) and file_digest(path) == manifest.get("fleet_sha256")):
            return {}
        fleet, _ = inspect_fleet(path)
    except (NavseqError, OSError):
        return {}
    if fleet is None:
        return {}
    return {
        robot.name: {
            "pose": [robot.start.x, robot.start.y, math.degrees(robot.start.yaw)],
            "footprint_m": [[float(x), float(y)] for x, y in robot.profile.footprint],
        }
        for robot in fleet.robots
    }


def _shift(replay: dict[str, Any], seconds: float) -> None:
    """Lay a robot's timeline (times from its first event) on the fleet's clock."""
    if not seconds:
        return
    for pose in replay["poses"]:
        pose[0] = round(pose[0] + seconds, 3)
    for entry in (*replay["states"], *replay["plans"]):
        entry["t"] = round(entry["t"] + seconds, 3)


def _map_shown(
    report: dict[str, Any] | None,
    may_read: Callable[[Path], bool],
    shown_path: Callable[[Path], str],
) -> str | None:
    """The fleet's map as the page loads it, when the studio may read it."""
    text = report.get("map") if report is not None else None
    if not isinstance(text, str) or not text:
        return None
    path = Path(text)
    return shown_path(path) if path.is_absolute() and may_read(path) else None


__all__ = [
    "ROBOT_COLOURS",
    "fleet_replay_of",
    "fleet_run_folders",
    "fleet_run_summary",
    "fleet_runs_listed",
    "read_json",
    "robot_colour",
]
