"""Nav2 costmap filters as a mission names them: a mask file and its filter info.

Nav2 gives a costmap filter as a mask (a map_server YAML + image) and the parameters of
its ``costmap_filter_info_server``: ``type`` (0 keepout, 1 speed limit in percent of
the maximum speed, 2 speed limit in m/s), ``base`` and ``multiplier`` (a speed mask's
cell value ``v`` limits the speed to ``base + multiplier * v``; 0 means no limit). A
mission lists them under ``filters:``; navseq's simulator and pre-flight read the masks
(:mod:`navseq.sim.filters`). Plain data and its reader, no map reading here.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from navseq.errors import NavseqError
from navseq.mission.located import Located, describe


class FilterType(enum.IntEnum):
    """``costmap_filter_info_server``'s ``type``."""

    KEEPOUT = 0
    SPEED_PERCENT = 1
    SPEED_ABSOLUTE = 2


#: Nav2's speed-filter tutorial: a white cell (0) has no limit, a value v limits the
#: speed to 100 - v percent. ``--speed-mask`` uses it.
TUTORIAL_SPEED_BASE, TUTORIAL_SPEED_MULTIPLIER = 100.0, -1.0
FILTER_KEYS = ("mask", "type", "base", "multiplier")


@dataclass(frozen=True)
class CostmapFilter:
    """One filter: its mask file and filter info (``base``/``multiplier`` as Nav2's
    costmap_filter_info_server defaults them). ``where`` is where it was written."""

    mask: Path
    type: FilterType = FilterType.KEEPOUT
    base: float = 0.0
    multiplier: float = 1.0
    where: str | None = field(default=None, compare=False)

    @property
    def is_keepout(self) -> bool:
        return self.type is FilterType.KEEPOUT

    @classmethod
    def keepout(cls, mask: Path) -> CostmapFilter:
        return cls(mask, FilterType.KEEPOUT, where=str(mask))

    @classmethod
    def tutorial_speed(cls, mask: Path) -> CostmapFilter:
        """A speed mask with the filter info of Nav2's speed-filter tutorial."""
        return cls(
            mask,
            FilterType.SPEED_PERCENT,
            TUTORIAL_SPEED_BASE,
            TUTORIAL_SPEED_MULTIPLIER,
            where=str(mask),
        )


def read_filters(
    node: Located,
    subject: str,
    path_of: Callable[[Located, str], Path],
    number_of: Callable[[Located, str], float],
) -> tuple[CostmapFilter, ...]:
    """A ``filters:`` list of ``{mask, type, base, multiplier}`` mappings.

    ``path_of`` reads a file path (relative to the mission's folder), ``number_of`` a
    finite number: the mission reader's own, so messages read alike. Raises one
    NavseqError for the first problem, naming the item.
    """
    if not node.is_list:
        raise NavseqError(
            "must be a list of filters like {mask: keepout.yaml, type: 0}, "
            f"got {describe(node.value)}",
            source=node.where,
            subject=subject,
        )
    filters = []
    for number, item in enumerate(node.value, start=1):
        label = f"{subject}, item {number}"
        if not item.is_mapping:
            raise NavseqError(
                f"must be a mapping {{mask, type, base, multiplier}}, got {describe(item.value)}",
                source=item.where,
                subject=label,
            )
        unknown = [key for key in item.value if key not in FILTER_KEYS]
        if unknown:
            raise NavseqError(
                f"unknown key '{unknown[0]}' (known: {', '.join(FILTER_KEYS)})",
                source=item.where,
                subject=label,
            )
        mask = item.get("mask")
        if mask is None:
            raise NavseqError(
                "'mask' is missing: the filter mask's map_server YAML",
                source=item.where,
                subject=label,
            )
        filter_type = FilterType.KEEPOUT
        type_node = item.get("type")
        if type_node is not None:
            if type_node.value not in (0, 1, 2) or isinstance(type_node.value, bool):
                raise NavseqError(
                    "type is 0 (keepout), 1 (speed limit in percent) or 2 (speed limit "
                    "in m/s), as Nav2's costmap_filter_info_server; got "
                    f"{describe(type_node.value)}",
                    source=type_node.where,
                    subject=f"{label}, field type",
                )
            filter_type = FilterType(type_node.value)
        values = {}
        for key, default in (("base", 0.0), ("multiplier", 1.0)):
            entry = item.get(key)
            values[key] = default if entry is None else number_of(entry, f"{label}, field {key}")
        filters.append(
            CostmapFilter(
                path_of(mask, f"{label}, field mask"),
                filter_type,
                values["base"],
                values["multiplier"],
                where=item.where,
            )
        )
    return tuple(filters)


def filters_summary(filters: tuple[CostmapFilter, ...]) -> str:
    """``keepout zones of keepout.yaml, speed zones of speed.yaml`` (a simulator's ready line)."""
    return ", ".join(
        f"{'keepout' if spec.is_keepout else 'speed'} zones of {spec.mask.name}" for spec in filters
    )


__all__ = ["FILTER_KEYS", "CostmapFilter", "FilterType", "filters_summary", "read_filters"]
