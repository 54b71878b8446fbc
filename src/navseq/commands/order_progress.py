"""``navseq plan --order shortest``'s progress: the searches for the distances, then the solver.

Shown on stderr, and only when stderr is a terminal: a pipe or a log file gets nothing,
and ``--json`` output (on stdout) is never touched. The bar goes away when the order is
found (the route's table follows).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress, TaskID


class BarProgress:
    """An :class:`navseq.route.order.OrderProgress` on a rich progress display."""

    def __init__(self, progress: Progress) -> None:
        self._progress = progress
        self._searches: TaskID | None = None
        self._solver: TaskID | None = None

    def searching(self, done: int, total: int) -> None:
        if self._searches is None:
            self._searches = self._progress.add_task("distances", total=max(total, 1))
        self._progress.update(self._searches, completed=done, total=max(total, 1))

    def solving(self, best: float | None, limit_s: float) -> None:
        text = "solving" if best is None else f"solving (best so far {best:,.1f})"
        if self._solver is None:
            self._solver = self._progress.add_task(text, total=None)
        self._progress.update(self._solver, description=text)


@contextlib.contextmanager
def order_progress(console: Console | None = None) -> Iterator[BarProgress | None]:
    """A progress display on ``console`` (default: stderr) while the block runs, or None
    when that is no terminal."""
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        SpinnerColumn,
        TextColumn,
        TimeElapsedColumn,
    )

    console = console or Console(stderr=True)
    if not console.is_terminal:
        yield None
        return
    with Progress(
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=True,
    ) as progress:
        yield BarProgress(progress)


__all__ = ["BarProgress", "order_progress"]
