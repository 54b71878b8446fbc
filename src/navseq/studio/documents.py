"""A mission as the page edits it: a JSON document, checked and planned by navseq's core.

The JSON document *is* a navseq mission file (docs/mission-format.md) with JSON
syntax: the same keys, the same units (metres, degrees, seconds), so there is one set
of rules for what a mission may hold — the loader's. A draft is checked by writing it
as navseq YAML (one line per waypoint, so a problem's line names its waypoint) and
handing that file to :func:`navseq.commands.validate.mission_file_problems`, the code
``navseq validate --map`` runs. Legs are planned by :mod:`navseq.route.legs`, as
``navseq plan`` plans them.
"""

from __future__ import annotations

import hashlib
import json
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from navseq.errors import MissionErrors, NavseqError
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.commands.validate import CostmapSource
    from navseq.mission.model import Mission
    from navseq.studio.security import FileRoots
    from navseq.tasks.options import TaskOptions

#: The units of the document's numbers, sent with every mission so no client guesses.
UNITS: dict[str, str] = {
    "x": "m",
    "y": "m",
    "z": "m",
    "yaw": "deg",
    "server_timeout": "s",
    "goal_timeout": "s",
    "stall_timeout": "s",
    "pass_through": "m",
    "dwell": "s",
    "xy_tolerance": "m",
    "yaw_tolerance": "deg",
}


class DraftRefused(NavseqError):
    """A draft that is not a mission document at all (HTTP 400/422, said in one line)."""


def version_of(path: Path) -> dict[str, Any]:
    """What identifies the file's content now: its SHA-256 (and mtime, for display)."""
    data = path.read_bytes()
    return {
        "sha256": hashlib.sha256(data).hexdigest(),
        "mtime_ns": path.stat().st_mtime_ns,
        "size": len(data),
    }


def document_of(mission: Mission, base_dir: Path) -> dict[str, Any]:
    """The mission as a JSON-ready document: what the mission writer would write.

    The map path is relative to ``base_dir`` (the mission file's folder), as in a file.
    GPS waypoints are given in map coordinates: the page draws and edits x/y.
    """
    from navseq.mission.writer import dump_mission_yaml

    # libyaml's safe loader when there is one: the writer's own text, read back; PyYAML's
    # pure-Python reader took 1.8 s on 3000 waypoints, the page's whole wait on opening.
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    text = dump_mission_yaml(mission, base_dir=base_dir, gps=False)
    document = yaml.load(text, Loader=loader)
    assert isinstance(document, dict)
    return document


def open_document(path: Path, base_dir: Path) -> tuple[dict[str, Any] | None, list[NavseqError]]:
    """The document of a mission file of any format, and the file's problems.

    A navseq YAML file with problems is still opened as written (its raw mapping), so
    that the user can fix it on the map; other formats with problems give None.
    """
    from navseq.mission import inspect_mission_file
    from navseq.mission.yaml_doc import refuse_deep_nesting

    mission, problems = inspect_mission_file(path)
    if mission is not None:
        return document_of(mission, base_dir), []
    if path.suffix.lower() in (".yaml", ".yml"):
        try:
            text = path.read_text(encoding="utf-8")
            refuse_deep_nesting(text, str(path))  # before PyYAML's composer recurses
            raw = yaml.safe_load(text)
        # ValueError: an integer longer than Python converts (the loader said so).
        except (yaml.YAMLError, NavseqError, OSError, ValueError, RecursionError):
            raw = None
        if isinstance(raw, dict) and "navseq" in raw:
            return json.loads(json.dumps(raw, default=str)), list(problems.errors)
    return None, list(problems.errors)


def empty_document(map_text: str | None) -> dict[str, Any]:
    """A new mission with no waypoints (on ``map_text``, relative to the mission folder)."""
    document: dict[str, Any] = {"navseq": 1, "frame": "map"}
    if map_text is not None:
        document["map"] = map_text
    document["loops"] = 1
    document["waypoints"] = []
    return document


@dataclass
class DraftText:
    """A draft written as navseq YAML, and which line holds what."""

    text: str
    waypoint_lines: dict[int, int] = field(default_factory=dict)  # line -> waypoint index
    key_lines: dict[int, str] = field(default_factory=dict)  # line -> top-level key


def draft_text(document: dict[str, Any]) -> DraftText:
    """The draft as YAML: one line per top-level key and per waypoint (JSON flow style).

    JSON is YAML, so every value is written exactly as the page sent it and the loader
    judges it; the line of each waypoint is known, so problems point at waypoints.
    """
    lines = ["# navseq studio draft"]
    drafted = DraftText("")
    for key, value in document.items():
        if key == "waypoints" and isinstance(value, list):
            lines.append("waypoints:")
            drafted.key_lines[len(lines)] = key
            for index, waypoint in enumerate(value):
                lines.append("  - " + json.dumps(waypoint, ensure_ascii=True))
                drafted.waypoint_lines[len(lines)] = index
            if not value:
                lines[-1] = "waypoints: []"
            continue
        lines.append(f"{json.dumps(str(key))}: {json.dumps(value, ensure_ascii=True)}")
        drafted.key_lines[len(lines)] = str(key)
    drafted.text = "\n".join(lines) + "\n"
    return drafted


@dataclass
class Problem:
    """One problem as the page lists it: the line the CLI prints, and what it is about."""

    text: str
    message: str
    subject: str | None
    waypoint: int | None  # 0-based index of the waypoint concerned
    key: str | None  # the top-level key concerned (start, defaults, map ...)
    # Where the waypoint (or start pose) concerned could go instead: the nearest spot where
    # the robot has room to turn (pre-flight's suggestion), for a one-click fix.
    fix: dict[str, float] | None = None

    def as_json(self) -> dict[str, Any]:
        return {
            "text": self.text,
            "message": self.message,
            "subject": self.subject,
            "waypoint": self.waypoint,
            "key": self.key,
            "fix": self.fix,
        }


def flatten(errors: list[NavseqError]) -> list[NavseqError]:
    found: list[NavseqError] = []
    for error in errors:
        found += flatten(error.errors) if isinstance(error, MissionErrors) else [error]
    return found


def problems_of(
    errors: list[NavseqError],
    *,
    drafted: DraftText | None = None,
    draft_path: Path | None = None,
    shown_as: str = "draft",
) -> list[Problem]:
    """``errors`` for the page; sources in the draft's temporary file become ``shown_as``."""
    from navseq.preflight import MisplacedError

    problems: list[Problem] = []
    for error in flatten(errors):
        source, waypoint, key = error.source, None, None
        if draft_path is not None and source is not None and source.startswith(str(draft_path)):
            _, _, line_text = source.rpartition(":")
            line = int(line_text) if line_text.isdigit() else None
            if drafted is not None and line is not None:
                waypoint = drafted.waypoint_lines.get(line)
                key = drafted.key_lines.get(line)
            source = shown_as
        if error.subject == "start":
            key = "start"
        shown = NavseqError(error.message, source=source, subject=error.subject)
        fix = None
        if isinstance(error, MisplacedError) and error.suggested is not None:
            fix = {"x": error.suggested[0], "y": error.suggested[1]}
        problems.append(Problem(str(shown), error.message, error.subject, waypoint, key, fix))
    return problems


@dataclass
class CheckedDraft:
    """A draft checked as ``navseq validate --map`` checks a file."""

    mission: Mission | None  # None when the file's own problems stop it reading
    problems: list[Problem]
    map_path: Path | None
    # The draft as it was written for the loader, and the (gone) file it was written to:
    # what problems' lines are mapped back with (navseq.studio.edits checks an edit).
    drafted: DraftText | None = None
    draft_path: Path | None = None


def check_draft(
    document: Any,
    *,
    roots: FileRoots,
    base_dir: Path,
    shown_as: str,
    costmaps: CostmapSource | None = None,
    tasks: TaskOptions | None = None,
) -> CheckedDraft:
    """Every problem of a draft document (file problems and pre-flight), and its mission.

    ``base_dir`` is the folder of the mission file the draft belongs to (its ``map:``
    is relative to it). Raises :class:`DraftRefused` for something that is not a
    navseq mission document, and :class:`NavseqError` for a map outside the studio's
    folders. ``costmaps`` recalls costmaps already built (the studio keeps one per map
    and robot), so that a check after an edit does not inflate the map again.
    """
    from navseq.commands.validate import mission_file_problems

    if not isinstance(document, dict):
        raise DraftRefused("the mission must be a JSON object (a navseq mission document)")
    if "navseq" not in document:
        raise DraftRefused("the mission document needs its format version: navseq: 1")
    document = dict(document)
    map_path: Path | None = None
    map_value = document.get("map")
    if isinstance(map_value, str):
        # Resolved (and refused outside the studio's folders) before anything reads it.
        map_path = roots.resolve(map_value, "map", base=base_dir)
        document["map"] = str(map_path)
    document["filters"] = _masks_resolved(document.get("filters"), roots, base_dir)
    if document["filters"] is None:
        del document["filters"]
    drafted = draft_text(document)
    with tempfile.TemporaryDirectory(prefix="navseq-studio-") as folder:
        path = Path(folder) / "draft.yaml"
        path.write_text(drafted.text, encoding="utf-8")
        mission, errors = mission_file_problems(path, costmaps=costmaps, tasks=tasks)
        problems = problems_of(errors, drafted=drafted, draft_path=path, shown_as=shown_as)
    return CheckedDraft(mission, problems, map_path, drafted, path)


def _masks_resolved(filters: Any, roots: FileRoots, base_dir: Path) -> Any:
    """The draft's costmap filters with each mask path resolved as the map's is (the
    draft is checked from a temporary folder); anything else as the page sent it."""
    if not isinstance(filters, list):
        return filters
    resolved = []
    for item in filters:
        if isinstance(item, dict) and isinstance(item.get("mask"), str):
            item = {**item, "mask": str(roots.resolve(item["mask"], "filters mask", base=base_dir))}
        resolved.append(item)
    return resolved


def shown_path(path: Path) -> str:
    return printable(str(path))


__all__ = [
    "UNITS",
    "CheckedDraft",
    "DraftRefused",
    "Problem",
    "check_draft",
    "document_of",
    "empty_document",
    "open_document",
    "version_of",
]


def not_a_navseq_mission(path: Path) -> str | None:
    """What the file at ``path`` is when it is not a navseq mission (a save over it would
    destroy it): ``"a map_server map"`` ..., or None for a navseq mission (or no file)."""
    from navseq.mission.loader import is_navseq_document
    from navseq.mission.problems import Problems
    from navseq.mission.reading import read_mission_text
    from navseq.mission.rosparam_format import find_mission_namespaces
    from navseq.mission.yaml_doc import parse_yaml

    if not path.exists():
        return None
    try:
        doc = parse_yaml(read_mission_text(path), str(path), Problems())
    except NavseqError:
        return "a file that is not YAML navseq can read"
    if doc is None or not doc.is_mapping:
        return "a YAML file that is not a navseq mission"
    if is_navseq_document(doc):
        return None
    keys = set(doc.value)
    if {"image", "resolution"} <= keys:
        return "a map_server map (its image and resolution)"
    if find_mission_namespaces(doc):
        return "a ROS parameter file (p_seq / yea_seq), which the studio imports but never writes"
    return "a YAML file that is not a navseq mission (no waypoints: or navseq: key)"
