"""``navseq studio [MISSION] [--map MAP]``: make, check and run missions in the browser.

Serves the studio (``navseq.studio``) on 127.0.0.1 with a fresh token, prints
``navseq studio: http://127.0.0.1:PORT/?token=...`` as the first line on stdout and
opens the browser (unless ``--no-browser``). The page may read and write files only
under the mission's and the map's folders, or ``--root``. Ctrl-C stops it; a running
simulation is cancelled first and its report written. ``--allow-run``: runs started from
the page may start the mission's ``run:`` tasks' programs (the page itself cannot allow
that). See docs/studio.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "mission",
        type=Path,
        nargs="?",
        metavar="MISSION",
        help="mission file to open (navseq YAML, launch, rosparam YAML, CSV); a new file "
        "is created on the first save if it does not exist",
    )
    parser.add_argument(
        "--map",
        type=Path,
        metavar="MAP",
        help="map_server YAML to edit on (default: the mission's map:)",
    )
    parser.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default: 127.0.0.1)"
    )
    parser.add_argument(
        "--port", type=int, default=0, help="port to listen on (default: 0, a free one)"
    )
    parser.add_argument(
        "--no-browser", action="store_true", help="print the URL only; do not open a browser"
    )
    parser.add_argument(
        "--root",
        type=Path,
        metavar="DIR",
        help="the only folder the studio may read and write files under "
        "(default: the mission's and the map's folders)",
    )
    parser.add_argument(
        "--fleet",
        type=Path,
        metavar="FLEET",
        help="a fleet file to run from the page (all its robots on the embedded simulator, "
        "watched live); without MISSION its mission is opened",
    )
    parser.add_argument(
        "--allow-run",
        action="store_true",
        help="let the runs started from the page start the mission's run: tasks' programs "
        "(without it the page can never start a program)",
    )


def run(args: argparse.Namespace) -> int:
    import secrets

    from navseq.extras import require_extra

    require_extra("studio", "the studio")  # before the imports that need it

    from navseq.commands.common import require_file
    from navseq.errors import NavseqError
    from navseq.studio.app import StudioConfig
    from navseq.studio.security import FileRoots
    from navseq.studio.server import serve

    fleet: Path | None = getattr(args, "fleet", None)
    if fleet is not None:
        require_file(fleet, "--fleet")
    mission: Path | None = args.mission
    fleet_mission, fleet_map = _fleet_files(fleet) if fleet is not None else (None, None)
    # Without MISSION, the fleet's mission is opened in the editor (where --root allows).
    if (
        mission is None
        and fleet_mission is not None
        and (args.root is None or fleet_mission.is_relative_to(args.root.resolve()))
    ):
        mission = fleet_mission
    if mission is not None and mission.exists():
        require_file(mission, "MISSION")
    elif mission is not None and mission.suffix.lower() not in (".yaml", ".yml"):
        raise NavseqError(
            "does not exist; a new mission is saved as navseq YAML (.yaml)", source=str(mission)
        )
    if mission is not None and not mission.exists() and not mission.parent.is_dir():
        raise NavseqError(f"the folder {mission.parent} does not exist", source=str(mission))
    if args.map is not None:
        require_file(args.map, "--map")
    if not 0 <= args.port <= 65535:
        raise NavseqError("must be between 0 and 65535", source="--port")
    base = (mission.parent if mission is not None else Path.cwd()).resolve()
    if args.root is not None:
        if not args.root.is_dir():
            raise NavseqError("is not a folder", source=f"--root {args.root}")
        folders = [args.root]
    else:
        folders = [base]
        if fleet is not None:  # the fleet file and its map, for the page to read
            folders.append(fleet.resolve().parent)
            if fleet_map is not None:
                folders.append(fleet_map.parent)
        if args.map is not None:
            folders.append(args.map.resolve().parent)
        elif mission is not None and mission.exists():
            map_folder = _mission_map_folder(mission)
            if map_folder is not None:
                folders.append(map_folder)
    roots = FileRoots(folders, base)
    map_path = None
    if args.map is not None:
        map_path = roots.resolve(str(args.map.resolve()), "--map")
    elif mission is None and fleet_map is not None and roots.contains(fleet_map):
        map_path = fleet_map  # a fleet with its mission inline: the page shows its map
    if mission is not None:
        roots.resolve(str(mission.resolve()), "MISSION")  # refused outside --root
    if fleet is not None:
        roots.resolve(str(fleet.resolve()), "--fleet")  # refused outside --root
    from navseq.studio.security import allowed_hosts

    config = StudioConfig(
        token=secrets.token_urlsafe(24),
        roots=roots,
        mission_path=mission.resolve() if mission is not None else None,
        map_path=map_path,
        hosts=allowed_hosts(args.host),
        allow_run=args.allow_run,
        fleet_path=fleet.resolve() if fleet is not None else None,
    )
    return serve(config, args.host, args.port, open_browser=not args.no_browser)


def _fleet_files(fleet: Path) -> tuple[Path | None, Path | None]:
    """The fleet file's mission file (None: inline or unreadable) and its map, as far as
    the file reads; its problems are the page's to show when it is run."""
    from navseq.errors import NavseqError
    from navseq.fleet.fleet_format import inspect_fleet

    try:
        loaded, _ = inspect_fleet(fleet)
    except NavseqError:
        return None, None
    if loaded is None:
        return None, None
    mission = loaded.mission_path
    return (
        mission.resolve() if mission is not None and mission.is_file() else None,
        None if loaded.map is None else Path(loaded.map).resolve(),
    )


def _mission_map_folder(mission: Path) -> Path | None:
    """The folder of the map the mission names (its ``map:``), if it reads."""
    from navseq.errors import NavseqError
    from navseq.mission import inspect_mission_file

    try:
        loaded, problems = inspect_mission_file(mission)
    except NavseqError:
        return None
    if loaded is None and problems.salvage is not None:
        loaded = problems.salvage.mission
    if loaded is None or loaded.map is None:
        return None
    return Path(loaded.map).resolve().parent
