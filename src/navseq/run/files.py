"""A run's report and picture on disk: written whole, under a free name, in order.

The order is the promise: the report first, then the picture. Each file is written
complete under a name nothing else has (``report.json``, else ``report-2.json`` ...)
through a temporary file, so no empty or half file is ever seen, and nothing the user
has is replaced. Shutdown signals that arrive meanwhile are counted by
:class:`~navseq.signals.SignalGuard` (deferring), not obeyed: the report is always
written, and states exactly the exit status the run ends with. Only an operator who
signals twice more while the picture is drawn gives the picture up.
"""

from __future__ import annotations

import errno
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from navseq.signals import SignalGuard

#: Attempts at a free name (``report-2.json`` ...) before giving up.
MAX_NAME_ATTEMPTS = 1000
#: The files a run (or ``navseq report``) writes atomically into its folder.
OUTPUT_NAMES = re.compile(r"report(?:-[0-9]+)?\.json|mission(?:-[0-9]+)?\.png")


@dataclass
class RunFiles:
    """The files of one run: role -> path, the roles that could not be written, and
    those written complete but out of date (a later update failed)."""

    paths: dict[str, str] = field(default_factory=dict)
    failed: dict[str, str] = field(default_factory=dict)  # role -> why
    outdated: dict[str, str] = field(default_factory=dict)  # role -> what it says wrongly


def free_name(folder: Path, name: str, start: int = 1) -> Path:
    """``folder/name``, or ``stem-N.ext`` for the first N from ``start`` not taken."""
    stem, dot, suffix = name.rpartition(".")
    if not dot:
        stem, suffix = name, ""
    for number in range(start, start + MAX_NAME_ATTEMPTS):
        candidate = folder / (name if number == 1 else f"{stem}-{number}{dot}{suffix}")
        if not candidate.exists() and not candidate.is_symlink():
            return candidate
    raise NavseqError(f"no free name for {name} in {MAX_NAME_ATTEMPTS} tries", source=str(folder))


def remove_stale_temporaries(folder: Path) -> list[Path]:
    """Remove the report's and picture's temporaries a killed run left in its ``folder``.

    ``kill -9`` while a report or picture was being written leaves its temporary
    (``.report.json.1a2b3c4d.tmp``) beside the outputs, where every later run or
    rebuild in the folder would leave it too. Call this holding the folder's run lock
    (:mod:`navseq.run.runlock`): no other run writes there then, and a temporary that a
    live process still holds locked is left alone anyway
    (:func:`navseq.files.remove_stale_temporaries`). Only our outputs' temporaries
    are touched, never another file of the folder.
    """
    from navseq.files import remove_stale_temporaries as remove

    return remove(folder, OUTPUT_NAMES)


def write_new_file(folder: Path, name: str, render: Callable[[Path], str | bytes]) -> Path:
    """Write ``render(path)`` to a free name in ``folder``; never replaces a file.

    ``render`` gets the path the file will have (a report names its own path). OSError
    (disk full, permissions) becomes a :class:`NavseqError` naming the file.
    """
    from navseq.files import write_atomically

    number = 1
    while True:
        path = free_name(folder, name, number)
        data = render(path)
        try:
            write_atomically(path, data, replace=False)
            return path
        except FileExistsError:
            number = _number_of(path, name) + 1  # someone took it meanwhile: the next one
        except OSError as error:
            raise output_error(path, error) from None


def output_error(path: Path, error: OSError) -> NavseqError:
    """A clear message for a file that could not be written (disk full, permissions)."""
    why = error.strerror or str(error)
    if error.errno == errno.ENOSPC:
        why = "the disk is full"
    return NavseqError(f"cannot write it: {why}", source=str(path))


def _number_of(path: Path, name: str) -> int:
    stem = name.rpartition(".")[0] or name
    tail = path.name[len(stem) :].lstrip("-").split(".")[0]
    return int(tail) if tail.isdigit() else 1


def write_outputs(
    folder: Path,
    files: RunFiles,
    build_report: Callable[[dict[str, str], int], dict[str, Any]] | None,
    render_picture: Callable[[], bytes] | None,
    signals: SignalGuard | None,
    exit_code: int,
) -> int:
    """The report, then the picture; returns the exit status the report states.

    ``build_report(paths, exit_code)`` makes the report given every file's path (the
    picture's name is chosen first so that the report can name it); ``render_picture()``
    the PNG, or None for no picture (``--no-picture``: the report names none);
    ``build_report`` None writes no report. A picture
    given up by the operator or that cannot be written (disk full; the run's status
    becomes 2) is not named by the report, which is written again to say why, if it can be.
    """
    from navseq.signals import StepAbandoned
    from navseq.sinks.report import report_json

    if render_picture is not None:
        picture_path = free_name(folder, "mission.png")
        files.paths["picture"] = str(picture_path)

    def report_text(path: Path) -> str:
        files.paths["report"] = str(path)
        assert build_report is not None
        report = build_report(dict(files.paths), exit_code)
        if files.failed:
            report["files_not_written"] = dict(files.failed)
        # Text, not bytes: write_atomically escapes what UTF-8 cannot hold (a file name's
        # undecodable bytes) so that JSON reads it back.
        return report_json(report)

    report_path: Path | None = None
    if build_report is not None:
        try:
            report_path = write_new_file(folder, "report.json", report_text)
        except NavseqError as error:
            files.failed["report"] = str(error)
    if render_picture is None:
        return exit_code
    stated_exit_code = exit_code  # what the report just written says
    try:
        if signals is not None:
            with signals.abortable():
                png = render_picture()
        else:
            png = render_picture()
        files.paths["picture"] = str(write_new_file(folder, picture_path.name, lambda _: png))
    except StepAbandoned as stop:
        files.failed["picture"] = f"not drawn: given up on {stop} while drawing"
    except NavseqError as error:
        files.failed["picture"] = str(error)
        exit_code = 2
    if "picture" in files.failed and report_path is not None:
        # The report named the picture before it was drawn: it must not name a file
        # that is not there.
        from navseq.files import write_atomically

        del files.paths["picture"]
        try:
            write_atomically(report_path, report_text(report_path))
        except OSError as again:
            # The report on disk is whole and valid, only out of date: say that, not
            # that there is none (a user would rebuild or distrust a good file).
            why = output_error(report_path, again).message.removeprefix("cannot write it: ")
            wrong = f"it still names the picture {picture_path.name}, which was not written"
            if exit_code != stated_exit_code:
                wrong += f", and states exit status {stated_exit_code}, not {exit_code}"
            files.outdated["report"] = (
                f"complete, but could not be updated after the picture failed ({why}): {wrong}"
            )
    return exit_code


def outputs_error(
    files: RunFiles, folder: Path, journal: Path | None, exit_code: int
) -> str | None:
    """The closing message of a run whose outputs failed (exit 2), or None.

    It says exactly what is on disk: a report not written at all (and the picture's
    fate), or a picture not written beside a report that was (up to date or not), and
    how to finish them. It says all :func:`report_failures` would.
    """
    rebuild = f"`navseq report {folder}`"
    if "report" in files.failed:
        if "picture" in files.failed:
            picture = f", nor the picture ({files.failed['picture']})"
        elif "picture" in files.paths:
            picture = f" (the picture {files.paths['picture']} was)"
        else:
            picture = ""
        if journal is None:
            return f"the report could not be written ({files.failed['report']}){picture}"
        return (
            f"the report could not be written ({files.failed['report']}){picture}; the "
            f"journal {journal} holds the run: {rebuild} rebuilds what is missing once "
            "there is room"
        )
    if exit_code != 2 or "picture" not in files.failed:
        return None
    report = files.paths["report"]
    if "report" in files.outdated:
        said = f"the report {report} is {files.outdated['report']}"
    else:
        said = f"the report {report} was written, and says so"
    return (
        f"the picture could not be written ({files.failed['picture']}); {said}. "
        f"{rebuild} draws the picture once the cause is fixed"
    )


__all__ = [
    "OUTPUT_NAMES",
    "RunFiles",
    "free_name",
    "output_error",
    "outputs_error",
    "remove_stale_temporaries",
    "write_new_file",
    "write_outputs",
]
