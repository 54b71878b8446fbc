"""Collecting every problem of a mission before giving up.

Loaders do not stop at the first mistake: ``navseq validate`` must list them all.
They record each problem in a :class:`Problems` list and keep going where that
makes sense, then :meth:`Problems.raise_if_any` turns the list into one exception.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from navseq.errors import MissionErrors, NavseqError


class Problems:
    """An ordered list of :class:`NavseqError`, one per thing the user wrote wrong."""

    def __init__(self) -> None:
        self.errors: list[NavseqError] = []

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
