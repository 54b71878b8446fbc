"""``navseq convert INPUT OUTPUT [--force] [--to FORMAT]``: any supported mission format to
navseq YAML, or, for an OUTPUT ending in ``.launch``, to the tutorial's launch file (``p_seq``
/ ``yea_seq``), or with ``--to nav2-panel`` to the waypoint file of Nav2's RViz panel; what
the chosen format cannot hold is said on stderr.

Never overwrites an existing file unless ``--force`` is given.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from navseq.mission.model import Mission


def configure(parser: argparse.ArgumentParser) -> None:
    # The one-line summary (``navseq --help``) names the usual output only; the command's
    # own help says that the output's name picks the format.
    parser.description = (
        "write any supported mission format as navseq YAML, or, for an OUTPUT ending in "
        ".launch, as the tutorial's launch file (p_seq / yea_seq for move_base_seq)"
    )
    parser.add_argument(
        "input",
        type=Path,
        metavar="INPUT",
        help="mission file (navseq YAML, launch, rosparam, CSV)",
    )
    parser.add_argument(
        "output",
        type=Path,
        metavar="OUTPUT",
        help="file to write: navseq YAML, or, for a name ending in .launch, the "
        "tutorial's launch file (p_seq / yea_seq; what that format cannot hold, such as "
        "names and policies, is said on stderr)",
    )
    parser.add_argument("--force", action="store_true", help="overwrite OUTPUT if it exists")
    parser.add_argument(
        "--to",
        choices=sorted(_WRITERS),
        default=None,
        help="the format to write (default: by OUTPUT's name: tutorial-launch for .launch, "
        "navseq otherwise); nav2-panel is the waypoint file Nav2's RViz panel loads",
    )


def run(args: argparse.Namespace) -> int:
    from navseq.errors import NavseqError
    from navseq.mission import load_mission
    from navseq.text import printable

    mission = load_mission(args.input)
    if args.output.exists() and not args.force:
        raise NavseqError(
            "exists already; not overwriting it (use --force to replace it)",
            source=str(args.output),
        )
    target = args.to or ("tutorial-launch" if args.output.suffix.lower() == ".launch" else "navseq")
    left_out = _WRITERS[target](mission, args.output, args.force)
    if left_out:
        import sys

        print(
            f"navseq convert: the {_FORMAT_NAMES[target]} has no place for: "
            f"{printable('; '.join(left_out))}",
            file=sys.stderr,
        )
    count = len(mission.waypoints)
    print(
        f"wrote {printable(str(args.output))} ({count} waypoint{'s' if count != 1 else ''} "
        f"from {printable(str(args.input))})"
    )
    return 0


# --- the formats convert writes: name -> writer (mission, path, overwrite) -> what it left out


def _write_navseq(mission: Mission, path: Path, overwrite: bool) -> list[str]:
    from navseq.mission import write_mission

    write_mission(mission, path, overwrite=overwrite)
    return []


def _write_tutorial_launch(mission: Mission, path: Path, overwrite: bool) -> list[str]:
    from navseq.mission.tutorial_export import write_tutorial_launch

    return list(write_tutorial_launch(mission, path, overwrite=overwrite).left_out)


def _write_nav2_panel(mission: Mission, path: Path, overwrite: bool) -> list[str]:
    from navseq.mission.nav2_waypoints_format import write_nav2_panel

    return write_nav2_panel(mission, path, overwrite=overwrite)


_WRITERS: dict[str, Callable[[Mission, Path, bool], list[str]]] = {
    "navseq": _write_navseq,
    "tutorial-launch": _write_tutorial_launch,
    "nav2-panel": _write_nav2_panel,
}
_FORMAT_NAMES = {
    "navseq": "navseq format",
    "tutorial-launch": "tutorial's format",
    "nav2-panel": "Nav2 RViz panel's format",
}
