"""How a run ended, as a face needs it: the result, the exit status, the files."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from navseq.errors import NavseqError
    from navseq.executor.result import MissionResult
    from navseq.run.files import RunFiles

#: Every waypoint reached.
EXIT_OK = 0
#: The mission ended, but not every waypoint was reached.
EXIT_NOT_ALL_REACHED = 1
#: An output could not be written, or a sink stopped the run (disk full ...).
EXIT_OUTPUT_FAILED = 2


@dataclass(frozen=True)
class RunOutcome:
    """What a :class:`~navseq.run.session.Session` did.

    ``exit_status`` is the one the report states: 0 all reached, 1 not all, 2 an output
    failed, 128 + N stopped by signal N (``interrupted`` names it). ``folder`` and
    ``files`` are None when the request wanted no outputs; ``files.paths`` maps each
    written file's role (journal, report, picture) to its path, ``files.failed`` each
    one not written to why, ``files.outdated`` each written one that says something
    wrong (a later update failed). ``error`` is what a face should say and exit 2 with:
    a sink that stopped the run, or outputs that failed (its message says what is on
    disk and how to finish it). ``clock`` is the report's: how fast the navigator's
    clock ran against the wall clock.
    """

    result: MissionResult
    exit_status: int
    interrupted: str | None = None
    folder: Path | None = None
    files: RunFiles | None = None
    error: NavseqError | None = None
    # The sink that stopped the run (a journal on a full disk), when one did: then
    # ``error`` is this one, and the files' own failures are each worth saying.
    stopped_by: NavseqError | None = None
    clock: dict[str, float | None] = field(default_factory=dict)
    # Notes on the run that a face shows (the simulator's speed ...), one line each.
    notes: tuple[str, ...] = ()

    def path(self, role: str) -> Path | None:
        """The written file of ``role`` (``"report"``, ``"picture"``, ``"journal"``)."""
        if self.files is None or role in self.files.failed or role not in self.files.paths:
            return None
        return Path(self.files.paths[role])

    @property
    def report_path(self) -> Path | None:
        return self.path("report")

    @property
    def picture_path(self) -> Path | None:
        return self.path("picture")

    @property
    def journal_path(self) -> Path | None:
        return self.path("journal")

    @property
    def not_written(self) -> dict[str, str]:
        """Each wanted file not written (role -> why)."""
        return {} if self.files is None else dict(self.files.failed)


__all__ = ["EXIT_NOT_ALL_REACHED", "EXIT_OK", "EXIT_OUTPUT_FAILED", "RunOutcome"]
