"""Collecting every problem of a mission before giving up.

Loaders do not stop at the first mistake: ``navseq validate`` must list them all.
They record each problem in a :class:`Problems` list and keep going where that
makes sense, then :meth:`Problems.raise_if_any` turns the list into one exception.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass

from navseq.errors import MissionErrors, NavseqError
from navseq.mission.model import Mission


@dataclass(frozen=True)
class Salvage:
    """The part of a faulty mission that could still be read.

    ``navseq validate`` checks it against the map too, so that one run lists the
    file's problems and the map's. ``numbers`` gives each kept waypoint's index in
    the file (0-based), so messages name waypoints as the user numbered them.
    """

    mission: Mission
    numbers: tuple[int, ...]


class Problems:
    """An ordered list of :class:`NavseqError`, one per thing the user wrote wrong."""

    def __init__(self) -> None:
        self.errors: list[NavseqError] = []
        self.salvage: Salvage | None = None  # set by readers that can keep a partial mission

    def add(self, message: str, *, source: str | None, subject: str | None = None) -> None:
        self.errors.append(NavseqError(message, source=source, subject=subject))

    def record(self, error: NavseqError) -> None:
        """Keep an error raised by a helper; a MissionErrors contributes each of its errors."""
        if isinstance(error, MissionErrors):
            self.errors.extend(error.errors)
        else:
            self.errors.append(error)

    def __len__(self) -> int:
        return len(self.errors)

    def raise_if_any(self) -> None:
        """Raise the single problem as it is, or several together as MissionErrors."""
        if len(self.errors) == 1:
            raise self.errors[0]
        if self.errors:
            raise MissionErrors(self.errors)


def closest_hint(word: str, known: Iterable[str]) -> str:
    """`` (did you mean 'goal_timeout'?)`` for a likely typo, else the list of known words."""
    candidates = list(known)
    match = difflib.get_close_matches(word, candidates, n=1, cutoff=0.6)
    if match:
        return f" (did you mean '{match[0]}'?)"
    return " (known: " + ", ".join(candidates) + ")"
