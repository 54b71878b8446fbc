"""What ``navseq run`` shows once the robot is stopped: the summary table and the files.

The files themselves are written by the run service (:mod:`navseq.run.files`); this is
the terminal's side: the final table, each file not written and why, and a standard
output whose reader went away (``navseq run --json | head -1``).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from navseq.text import printable

if TYPE_CHECKING:
    from navseq.executor.result import MissionResult
    from navseq.mission.model import Mission
    from navseq.run.files import RunFiles


def print_summary(
    mission: Mission,
    result: MissionResult,
    files: RunFiles,
    *,
    numbers: Sequence[int] | None = None,
    part: str | None = None,
    notes: Sequence[str] = (),
) -> None:
    """The final table, ``notes`` and the files, on stdout; a reader gone away is not an error.

    ``numbers`` and ``part``: see :func:`~navseq.sinks.summary.summary_table`.
    """
    from rich.console import Console

    from navseq.sinks.summary import print_table, summary_table

    try:
        console = Console()
        print_table(summary_table(mission, result, numbers=numbers, part=part), console)
        for note in notes:  # plain text: a path may hold [brackets], or a newline
            console.print(printable(note), highlight=False, markup=False)
        for role, path in files.paths.items():
            if role not in files.failed:
                console.print(f"{role:>8}: {printable(path)}", highlight=False, markup=False)
    except BrokenPipeError:
        silence_stdout()


def report_failures(files: RunFiles) -> None:
    """On stderr: each file not written and why, each written one that is out of date."""
    for role, why in files.failed.items():
        print(f"navseq run: {role}: {printable(why)}", file=sys.stderr)
    for role, wrong in files.outdated.items():
        print(f"navseq run: {role}: {printable(f'{files.paths[role]}: {wrong}')}", file=sys.stderr)


def silence_stdout() -> None:
    """Point stdout at /dev/null: its reader went away, and Python must not complain at exit."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


class StdoutGuard:
    """A listener wrapper: when stdout's reader goes away, the mission goes on silently.

    ``navseq run --json | head -1`` closes the pipe after one line. That is not a reason
    to stop a robot mid-mission or lose its report: output is dropped from then on
    (said once on stderr), and the run, the journal and the report carry on.
    """

    def __init__(self, listener: Callable[[Any], None]) -> None:
        self._listener = listener
        self.closed = False

    def __enter__(self) -> StdoutGuard:
        """Enters the listener it guards (a live display starts), if that is one to enter."""
        enter = getattr(self._listener, "__enter__", None)
        if enter is not None:
            enter()
        return self

    def __exit__(self, *exc: object) -> None:
        leave = getattr(self._listener, "__exit__", None)
        if leave is not None:
            leave(*exc)

    def __call__(self, event: Any) -> None:
        if self.closed:
            return
        try:
            self._listener(event)
        except BrokenPipeError:
            self.closed = True
            silence_stdout()
            print(
                "navseq run: standard output was closed; the mission goes on and the "
                "report is written as usual",
                file=sys.stderr,
            )


__all__ = [
    "StdoutGuard",
    "print_summary",
    "report_failures",
    "silence_stdout",
]
