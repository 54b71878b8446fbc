"""``--keepout MASK`` and ``--speed-mask MASK``: Nav2 costmap-filter masks given on the
command line, in place of the mission's ``filters:`` (run, validate, plan); for the
simulator (``navseq sim``) also ``--filters MISSION``, a mission file's ``filters:``."""

from __future__ import annotations

import argparse
from pathlib import Path

from navseq.errors import NavseqError
from navseq.files import require_file
from navseq.mission.costmap_filters import CostmapFilter


def add_filter_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--keepout",
        type=Path,
        metavar="MASK",
        help="a Nav2 keepout mask (map_server YAML; occupied cells are keepout zones) "
        "instead of the mission's filters: (with --speed-mask, both)",
    )
    parser.add_argument(
        "--speed-mask",
        type=Path,
        metavar="MASK",
        help="a Nav2 speed mask (map_server YAML) with the filter info of Nav2's speed "
        "filter tutorial (type 1, base 100, multiplier -1: a cell of value v limits the "
        "speed to 100 - v percent) instead of the mission's filters:",
    )


def filters_of(args: argparse.Namespace) -> tuple[CostmapFilter, ...] | None:
    """The filters the options give (their files checked), None when neither is given."""
    given: list[CostmapFilter] = []
    if args.keepout is not None:
        require_file(args.keepout, "--keepout")
        given.append(CostmapFilter.keepout(args.keepout.resolve()))
    if args.speed_mask is not None:
        require_file(args.speed_mask, "--speed-mask")
        given.append(CostmapFilter.tutorial_speed(args.speed_mask.resolve()))
    return tuple(given) if given else None


def add_sim_filter_options(parser: argparse.ArgumentParser) -> None:
    """The simulator's masks: what its planner, controller and (ROS 2) filter topics use."""
    parser.add_argument(
        "--keepout",
        type=Path,
        metavar="MASK",
        help="a Nav2 keepout mask (map_server YAML; occupied cells are keepout zones): "
        "never planned through, a goal deep inside aborts, as with Nav2's KeepoutFilter",
    )
    parser.add_argument(
        "--speed-mask",
        type=Path,
        metavar="MASK",
        help="a Nav2 speed mask (map_server YAML) with the filter info of Nav2's speed "
        "filter tutorial (type 1, base 100, multiplier -1): the robot is slowed in its "
        "zones, as with Nav2's SpeedFilter",
    )
    parser.add_argument(
        "--filters",
        type=Path,
        metavar="MISSION",
        help="the costmap filters of a mission file's filters: section (each mask with its "
        "type, base and multiplier), e.g. examples/keepout.yaml; with --keepout or "
        "--speed-mask, all of them",
    )


def sim_filters_of(args: argparse.Namespace) -> tuple[CostmapFilter, ...]:
    """The simulator's filters: a mission's ``filters:`` (``--filters``), then the masks
    of ``--keepout`` and ``--speed-mask``; their files checked."""
    given: list[CostmapFilter] = []
    mission = getattr(args, "filters", None)
    if mission is not None:
        from navseq.mission.loader import load_mission

        require_file(mission, "--filters")
        filters = load_mission(mission).filters
        if not filters:
            raise NavseqError(
                "the mission has no filters: (a list of {mask, type, base, multiplier})",
                source=f"--filters {mission}",
            )
        given.extend(filters)
    if getattr(args, "keepout", None) is not None or getattr(args, "speed_mask", None):
        given.extend(filters_of(args) or ())
    return tuple(given)


__all__ = ["add_filter_options", "add_sim_filter_options", "filters_of", "sim_filters_of"]
