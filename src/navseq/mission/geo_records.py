"""A run's costmap filters and GPS datum as its journal header and report record them.

The filters a run drove with (``--keepout`` / ``--speed-mask`` in place of the
mission's ``filters:``, or the mission's own) and the datum its GPS waypoints were
converted with are part of what the run was: a ``--resume`` continues with the same
filters (:func:`filters_from_record`), refuses a datum other than the journaled one,
and ``navseq report`` draws the journaled zones. Plain JSON values, no map reading.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.costmap_filters import CostmapFilter, FilterType
from navseq.mission.geodesy import Datum


def filters_record(filters: tuple[CostmapFilter, ...]) -> list[dict[str, Any]]:
    """Each filter's mask (an absolute path) and filter info."""
    return [
        {
            "mask": str(Path(spec.mask).resolve()),
            "type": int(spec.type),
            "base": float(spec.base),
            "multiplier": float(spec.multiplier),
        }
        for spec in filters
    ]


def filters_from_record(value: Any, where: str) -> tuple[CostmapFilter, ...] | None:
    """The filters a journal recorded (None: it recorded none, an older journal).

    A damaged record is a NavseqError naming ``where``, never a crash.
    """
    if value is None:
        return None
    problem = "must be a list of {mask, type, base, multiplier}"
    if not isinstance(value, list):
        raise NavseqError(f"the journal's run option filters {problem}", source=where)
    filters = []
    for item in value:
        try:
            mask, kind = item["mask"], item["type"]
            base, multiplier = float(item["base"]), float(item["multiplier"])
            if not isinstance(mask, str) or type(kind) is not int:
                raise TypeError
            filters.append(
                CostmapFilter(Path(mask), FilterType(kind), base, multiplier, where=where)
            )
        except (KeyError, TypeError, ValueError):
            raise NavseqError(
                f"the journal's run option filters {problem}, got {item!r}", source=where
            ) from None
    return tuple(filters)


def datum_record(datum: Datum | None) -> dict[str, Any] | None:
    """The datum as degrees (navseq's unit for yaw) and metres; None without one."""
    if datum is None:
        return None
    return {
        "latitude": datum.point.latitude,
        "longitude": datum.point.longitude,
        "altitude": datum.point.altitude,
        "yaw_deg": round(math.degrees(datum.yaw_rad), 9),
    }


def same_datum(datum: Datum | None, recorded: Any) -> bool:
    """Whether ``datum`` is the one a journal recorded (up to the record's rounding)."""
    mine = datum_record(datum)
    if mine is None or recorded is None:
        return mine is None and recorded is None
    if not isinstance(recorded, dict):
        return False
    for key, value in mine.items():
        other = recorded.get(key)
        if value is None or other is None:
            if value is not other:
                return False
        elif not isinstance(other, int | float) or not math.isclose(
            float(value), float(other), rel_tol=0.0, abs_tol=1e-9
        ):
            return False
    return True


def describe_filters(filters: tuple[CostmapFilter, ...] | None) -> str:
    """``keepout.yaml (keepout), speed.yaml (speed)`` for a resume's note."""
    if not filters:
        return "none"
    return ", ".join(
        f"{spec.mask.name} ({'keepout' if spec.is_keepout else 'speed'})" for spec in filters
    )


__all__ = [
    "datum_record",
    "describe_filters",
    "filters_from_record",
    "filters_record",
    "same_datum",
]
