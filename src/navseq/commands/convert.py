"""``navseq convert INPUT OUTPUT [--force]``: any supported mission format to navseq YAML,
or, for an OUTPUT ending in ``.launch``, to the tutorial's launch file (``p_seq`` /
``yea_seq``; what that format cannot hold is said on stderr).

Never overwrites an existing file unless ``--force`` is given.
"""

from __future__ import annotations

import argparse
from pathlib import Path


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


def run(args: argparse.Namespace) -> int:
    from navseq.errors import NavseqError
    from navseq.mission import load_mission, write_mission
    from navseq.text import printable

    mission = load_mission(args.input)
    if args.output.exists() and not args.force:
        raise NavseqError(
            "exists already; not overwriting it (use --force to replace it)",
            source=str(args.output),
        )
    if args.output.suffix.lower() == ".launch":
        import sys

        from navseq.mission.tutorial_export import write_tutorial_launch

        launch = write_tutorial_launch(mission, args.output, overwrite=args.force)
        if launch.left_out:
            print(
                f"navseq convert: the tutorial's format has no place for: "
                f"{printable('; '.join(launch.left_out))}",
                file=sys.stderr,
            )
    else:
        write_mission(mission, args.output, overwrite=args.force)
    count = len(mission.waypoints)
    print(
        f"wrote {printable(str(args.output))} ({count} waypoint{'s' if count != 1 else ''} "
        f"from {printable(str(args.input))})"
    )
    return 0
