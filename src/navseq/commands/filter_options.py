"""``--keepout MASK`` and ``--speed-mask MASK``: Nav2 costmap-filter masks given on the
command line, in place of the mission's ``filters:`` (run, validate, plan)."""

from __future__ import annotations

import argparse
from pathlib import Path

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


__all__ = ["add_filter_options", "filters_of"]
