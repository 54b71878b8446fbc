"""The fastest YAML path: list items written as one-line flow mappings, read by line.

A recorded patrol is a long run of lines like ``  - {name: wp7, x: 1.5, y: -2, yaw: 90}``.
libyaml turns each into nine parse events, and making those events into Python
objects was most of the time a 100 000-waypoint mission took to load (about two
seconds). Such a line says the same thing in any YAML reader when it holds nothing
but plain keys and plain words or numbers, so this module reads runs of them with a
regex instead:

1. :func:`find_runs` finds runs of consecutive lines at one indentation that are
   each a whole block-sequence item ``- {key: value, ...}`` of plain keys and values
   (letters, digits and ``_ . + -`` only: no quotes, anchors, tags, comments, nested
   collections). It replaces each run by one item, a :data:`SENTINEL` word, followed
   by blank lines, so every other line keeps its number.
2. The event reader (:mod:`navseq.mission.yaml_doc`) reads that shorter document
   and, where the sentinel shows up as a plain item of a block sequence on the run's
   first line and column, puts the run's items there (:meth:`Run.items`). Anywhere
   else (inside a block scalar, a quoted text, a flow list) it abandons this path.

A value whose YAML reading is not certain and cheap (see :func:`plain_value`), a
duplicate key or anything odd abandons this path for the whole document, which then
takes the event path: values, places and messages are the same either way
(``tests/test_yaml_fast_path.py`` compares all three paths).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from navseq.mission.located import Located

#: Stands for a run in the shortened document; a document that holds it anywhere is
#: not shortened.
SENTINEL = "__navseq_flow_run__"

#: Runs shorter than this are left to the event path: the bookkeeping costs more
#: than it saves, and short documents are quick anyway.
MIN_RUN = 8

_KEY = r"[A-Za-z_][A-Za-z0-9_]*"
_VALUE = r"[A-Za-z0-9_.+-]+"
_PAIR = re.compile(rf"({_KEY}): +({_VALUE})")
# Linear in the line's length whatever it holds, without possessive quantifiers (Python
# 3.10 has none): every repeat is followed by a character it cannot match (a key by
# ":", a value by " ", "," or "}", spaces by what is not a space), so a character given
# back fails at once, and a pair is repeated only after a comma (not "pairs, each ending
# at a comma" then a last one: the last pair would be read twice, and given back pair by
# pair when the line fails). tests/test_hostile_input.py runs megabyte lines.
_ITEM = re.compile(rf"( *)- \{{ *({_KEY}: +{_VALUE}(?: *, *{_KEY}: +{_VALUE})*) *\}} *")


class NotPlain(Exception):
    """A line of a run that the event path must read (see the module docstring)."""


@dataclass(frozen=True)
class Run:
    """Consecutive one-line flow-mapping items: where they start and what they hold."""

    first_line: int  # 0-based line index of the first item in the document
    column: int  # where the sentinel item's value starts (after "- ")
    bodies: tuple[str, ...]  # each line's pairs, "name: wp7, x: 1.5, ..."

    def items(
        self, place: Callable[[int], str], read_value: Callable[[str, int], Any]
    ) -> tuple[list[Located], int]:
        """The run's items as Located mappings, and how many YAML values they hold.

        ``place`` names a 0-based line (``mission.yaml:12``); ``read_value`` reads one
        plain scalar written on a 0-based line. Raises :class:`NotPlain` on a duplicate
        key.
        """
        items: list[Located] = []
        count = 0
        findall = _PAIR.findall
        for number, body in enumerate(self.bodies, self.first_line):
            pairs = findall(body)
            where = place(number)
            values = {key: Located(read_value(value, number), where) for key, value in pairs}
            if len(values) != len(pairs):
                raise NotPlain  # a duplicate key: the event path records the problem
            items.append(Located(values, where, dict.fromkeys(values, where)))
            count += 1 + 2 * len(pairs)  # the mapping, each key and each value
        return items, count


def find_runs(text: str) -> tuple[str, dict[int, Run]]:
    """The document with each run of one-line items shortened, and the runs by line.

    Returns ``(text, {})`` when there is no run long enough or the text holds the
    sentinel already.
    """
    if SENTINEL in text or "- {" not in text:
        return text, {}
    lines = text.split("\n")
    runs: dict[int, Run] = {}
    fullmatch = _ITEM.fullmatch
    index, total = 0, len(lines)
    while index < total:
        match = fullmatch(lines[index]) if "- {" in lines[index] else None
        if match is None:
            index += 1
            continue
        indent = match[1]
        bodies = [match[2]]
        end = index + 1
        while end < total:
            following = fullmatch(lines[end])
            if following is None or following[1] != indent:
                break
            bodies.append(following[2])
            end += 1
        if end - index >= MIN_RUN:
            runs[index] = Run(index, len(indent) + 2, tuple(bodies))
            lines[index] = f"{indent}- {SENTINEL}"
            lines[index + 1 : end] = [""] * (end - index - 1)
        index = end
    if not runs:
        return text, {}
    return "\n".join(lines), runs
