"""Writing a Mission as the tutorial's launch file, for users of the ``move_base_seq`` node.

The tutorial's node reads two private parameters, ``p_seq`` (flat x, y, z list in
metres) and ``yea_seq`` (one yaw per point, in degrees); its launch file sets them with
``<rosparam>`` inside its ``<node>``. That format holds nothing else, so what a navseq
mission says beyond positions and headings (names, loops, policies, start, map,
robot) cannot go with it: :func:`tutorial_launch_text` returns what was left out, so
that a face (``navseq convert``, the studio) tells the user instead of dropping it
silently. Reading the file back (:func:`navseq.mission.load_mission`) gives the same
positions and yaws.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from navseq.errors import NavseqError
from navseq.files import write_atomically
from navseq.mission.model import Mission
from navseq.mission.tutorial_format import POSITIONS_KEY, YAWS_KEY
from navseq.mission.writer import yaw_degrees_for_file

#: The tutorial's node, as its own launch file starts it.
TUTORIAL_PACKAGE = "simple_navigation_goals"
TUTORIAL_NODE_TYPE = "move_base_seq.py"
TUTORIAL_NODE_NAME = "move_base_seq"


@dataclass(frozen=True)
class TutorialLaunch:
    """The launch file's text and what of the mission it could not carry."""

    text: str
    left_out: tuple[str, ...]  # e.g. ("waypoint names", "loops: 3")


def tutorial_launch_text(
    mission: Mission,
    *,
    package: str = TUTORIAL_PACKAGE,
    node_type: str = TUTORIAL_NODE_TYPE,
    node_name: str = TUTORIAL_NODE_NAME,
) -> TutorialLaunch:
    """The mission as the tutorial's launch file (``p_seq`` / ``yea_seq``)."""
    positions: list[str] = []
    yaws: list[str] = []
    for waypoint in mission.waypoints:
        positions += [_number(waypoint.x), _number(waypoint.y), _number(waypoint.z)]
        yaws.append(_number(yaw_degrees_for_file(waypoint.yaw_rad)))
    left_out = _left_out(mission)
    note = ""
    if left_out:
        # A comment must not hold "--"; the items are navseq's own words, but be safe.
        items = "; ".join(left_out).replace("--", "- -")
        note = (
            "  <!-- written by navseq; the tutorial's format has no place for: "
            f"{escape(items)} -->\n"
        )
    text = (
        "<launch>\n"
        f"{note}"
        f"  <node pkg={quoteattr(package)} type={quoteattr(node_type)} "
        f'name={quoteattr(node_name)} output="screen">\n'
        f'    <rosparam param="{POSITIONS_KEY}">[{", ".join(positions)}]</rosparam>\n'
        f'    <rosparam param="{YAWS_KEY}">[{", ".join(yaws)}]</rosparam>\n'
        "  </node>\n"
        "</launch>\n"
    )
    return TutorialLaunch(text, tuple(left_out))


def write_tutorial_launch(
    mission: Mission, path: str | os.PathLike[str], overwrite: bool = False
) -> TutorialLaunch:
    """Write the tutorial's launch file for ``mission`` atomically; returns what was left out.

    Refuses to replace an existing file unless ``overwrite`` is true.
    """
    target = Path(path)
    source = str(target)
    if not mission.waypoints:
        raise NavseqError(
            "has no waypoints to write; the tutorial's p_seq needs one", source=source
        )
    if target.is_dir():
        raise NavseqError("is a folder; give the path of the launch file to write", source=source)
    if not target.parent.is_dir():
        raise NavseqError(f"the folder {target.parent} does not exist", source=source)
    if target.exists() and not overwrite:
        raise NavseqError("exists already; not overwriting it", source=source)
    launch = tutorial_launch_text(mission)
    try:
        write_atomically(target, launch.text, replace=overwrite)
    except FileExistsError:
        raise NavseqError("exists already; not overwriting it", source=source) from None
    except OSError as error:
        raise NavseqError(f"cannot be written: {error.strerror or error}", source=source) from None
    return launch


def _number(value: float | int) -> str:
    """The shortest text that reads back as exactly ``value`` (``1.0`` is ``1.0``)."""
    if isinstance(value, int):
        return str(value)
    return repr(float(value))


def _left_out(mission: Mission) -> list[str]:
    from navseq.mission.model import Policy

    left: list[str] = []
    if any(waypoint.name for waypoint in mission.waypoints):
        left.append("waypoint names")
    overridden = sorted({key for waypoint in mission.waypoints for key in waypoint.overrides})
    if overridden:
        left.append("per-waypoint " + ", ".join(overridden))
    if mission.defaults != Policy():
        left.append("defaults")
    if mission.loops != 1:
        left.append(f"loops: {'forever' if mission.loops is None else mission.loops}")
    if mission.start is not None:
        left.append("start")
    if mission.map is not None:
        left.append("map")
    if mission.robot is not None:
        left.append("robot")
    if mission.frame != "map":
        left.append(f"frame: {mission.frame} (the tutorial's node uses map)")
    return left


__all__ = [
    "TUTORIAL_NODE_NAME",
    "TUTORIAL_NODE_TYPE",
    "TUTORIAL_PACKAGE",
    "TutorialLaunch",
    "tutorial_launch_text",
    "write_tutorial_launch",
]
