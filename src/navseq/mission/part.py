"""Part of a mission: the waypoints a run drives when not all of them (``--from``,
``--to``, ``--only``).

A part is a mission of its own (the selected waypoints, in the file's order, with the
file's settings), so the executor, the journal and a resume need to know nothing about
it; :attr:`MissionPart.numbers` keeps each selected waypoint's position in the file, and
the part's :class:`Mission` carries them too (``Mission.number``), so that what a person
reads (progress, the executor's stop reason, the summary table, pre-flight messages)
numbers them as the file and a full run's table do; events, the journal and the report's
``index`` stay positions in the part. Pure Python: no ROS, no terminal.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.model import Mission
from navseq.text import printable

#: Names listed in a message about an unknown one; more would bury the message.
_NAMES_SHOWN = 12


@dataclass(frozen=True)
class PartSpec:
    """What the user asked for: ``--from N``, ``--to N`` (1-based, inclusive) or
    ``--only NAME_OR_NUMBER,...``; all None is the whole mission."""

    first: int | None = None
    last: int | None = None
    only: str | None = None

    @property
    def whole(self) -> bool:
        return self.first is None and self.last is None and self.only is None

    def describe(self) -> str:
        """The options as the user would type them: ``--from 3 --to 5``."""
        words = []
        if self.first is not None:
            words.append(f"--from {self.first}")
        if self.last is not None:
            words.append(f"--to {self.last}")
        if self.only is not None:
            words.append(f"--only {printable(self.only)}")
        return " ".join(words)

    def select(self, mission: Mission) -> MissionPart:
        """The part of ``mission`` asked for; a NavseqError naming the option otherwise."""
        count = len(mission.waypoints)
        numbers: list[int]
        if self.only is not None:
            if self.first is not None or self.last is not None:
                raise NavseqError(
                    "cannot be combined with --from or --to: give either --only or --from/--to",
                    source="--only",
                )
            numbers = _only(self.only, mission)
        else:
            first = 1 if self.first is None else _in_range(self.first, count, "--from")
            last = count if self.last is None else _in_range(self.last, count, "--to")
            if last < first:
                raise NavseqError(
                    f"waypoint {last} comes before --from {first}: --to must be at least --from",
                    source="--to",
                )
            numbers = list(range(first - 1, last))
        return MissionPart(self, tuple(numbers), count)


@dataclass(frozen=True)
class MissionPart:
    """The waypoints a run drives: 0-based positions in the file, in the file's order."""

    spec: PartSpec
    numbers: tuple[int, ...]
    of: int  # how many waypoints the file has

    def apply(self, mission: Mission) -> Mission:
        """The mission of the selected waypoints (the whole mission is returned as is)."""
        if self.spec.whole:
            return mission
        waypoints = tuple(mission.waypoints[number] for number in self.numbers)
        return dataclasses.replace(mission, waypoints=waypoints, numbers=self.numbers)

    def describe(self) -> str:
        """``waypoints 3-5 of 10, --from 3 --to 5``, for titles."""
        return f"{_ranges(self.numbers)} of {self.of}, {self.spec.describe()}"

    def to_report(self) -> dict[str, object]:
        """The report's ``part``: what was asked and the 1-based numbers that ran."""
        return {
            "from": self.spec.first,
            "to": self.spec.last,
            "only": self.spec.only,
            "numbers": [number + 1 for number in self.numbers],
            "of": self.of,
        }


def _in_range(number: int, count: int, option: str) -> int:
    if not 1 <= number <= count:
        raise NavseqError(
            f"there is no waypoint {number}: the mission's waypoints are numbered 1 to "
            f"{count} (as in the summary table)",
            source=option,
        )
    return number


def _only(text: str, mission: Mission) -> list[int]:
    """Positions of the waypoints named or numbered in ``text``, in the file's order.

    A token is a name when a waypoint has it (every waypoint with that name is picked),
    else a 1-based number.
    """
    count = len(mission.waypoints)
    tokens = [token.strip() for token in text.split(",")]
    if not any(tokens):
        raise NavseqError(
            "give waypoint names or numbers separated by commas, e.g. --only dock,3",
            source="--only",
        )
    by_name: dict[str, list[int]] = {}
    for index, waypoint in enumerate(mission.waypoints):
        if waypoint.name:
            by_name.setdefault(waypoint.name, []).append(index)
    picked: set[int] = set()
    unknown: list[str] = []
    for token in filter(None, tokens):
        if token in by_name:
            picked.update(by_name[token])
        elif token.isdigit() and 1 <= int(token) <= count:
            picked.add(int(token) - 1)
        else:
            unknown.append(token)
    if unknown:
        raise NavseqError(
            f"no waypoint is named or numbered {', '.join(map(repr, unknown))}: "
            + _known(by_name, count),
            source="--only",
        )
    return sorted(picked)


def _known(by_name: dict[str, list[int]], count: int) -> str:
    numbers = f"numbers go from 1 to {count}"
    if not by_name:
        return f"no waypoint has a name, and {numbers}"
    names = list(by_name)
    shown = ", ".join(printable(name) for name in names[:_NAMES_SHOWN])
    more = f" and {len(names) - _NAMES_SHOWN} more" if len(names) > _NAMES_SHOWN else ""
    return f"the names are {shown}{more}; {numbers}"


def _ranges(numbers: Sequence[int]) -> str:
    """``waypoints 3-5, 8`` for 0-based positions 2, 3, 4, 7."""
    spans: list[str] = []
    start = previous = None
    for number in [*numbers, None]:
        if number is not None and previous is not None and number == previous + 1:
            previous = number
            continue
        if start is not None and previous is not None:
            spans.append(f"{start + 1}" if start == previous else f"{start + 1}-{previous + 1}")
        start = previous = number
    word = "waypoint" if len(numbers) == 1 else "waypoints"
    return f"{word} {', '.join(spans)}"


#: The journal's run options that record the part, by PartSpec field.
PART_OPTIONS = {"first": "from_waypoint", "last": "to_waypoint", "only": "only"}


def part_from_options(options: Mapping[str, Any], source: str) -> PartSpec:
    """The part a journal's run options record (the whole mission if none)."""
    values: dict[str, Any] = {}
    for field_name, key in PART_OPTIONS.items():
        value = options.get(key)
        expected = str if field_name == "only" else int
        if value is not None and (not isinstance(value, expected) or isinstance(value, bool)):
            raise NavseqError(
                f"the journal's run option {key} is not valid: {value!r}", source=source
            )
        values[field_name] = value
    return PartSpec(**values)


def number_visits(report: dict[str, Any], part: MissionPart | None) -> None:
    """Give a report of a part the file's waypoint numbers and say which part ran.

    ``index`` stays the position in the part (as in events and the journal); ``number``
    becomes the waypoint's number in the mission file, as the summary table shows it.
    """
    report["part"] = None if part is None else part.to_report()
    if part is None:
        return
    for visit in report.get("visits", []):
        index = visit.get("index")
        if isinstance(index, int) and 0 <= index < len(part.numbers):
            visit["number"] = part.numbers[index] + 1
