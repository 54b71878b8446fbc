"""The run's output folder and file names: nothing the user already has is overwritten."""

from __future__ import annotations

import datetime
import os
from pathlib import Path

from navseq.errors import NavseqError

DEFAULT_ROOT = Path("navseq-out")


def default_run_folder(mission_stem: str, now: datetime.datetime | None = None) -> Path:
    """``navseq-out/<mission-stem>-<YYYYmmdd-HHMMSS>`` (not created here)."""
    now = now or datetime.datetime.now()
    return DEFAULT_ROOT / f"{mission_stem}-{now:%Y%m%d-%H%M%S}"


def create_run_folder(folder: Path, *, fresh: bool) -> Path:
    """Create the output folder and return it.

    ``fresh`` (the default folder): if the folder exists already (two runs in the
    same second), use ``folder-2``, ``folder-3``, ... instead. Otherwise (``--out``)
    an existing folder is used as is; :func:`reserve_file` keeps its files safe.
    """
    try:
        if not fresh:
            if folder.exists() and not folder.is_dir():
                raise NavseqError("exists and is not a folder", source=f"output folder {folder}")
            folder.mkdir(parents=True, exist_ok=True)
            return folder
        folder.parent.mkdir(parents=True, exist_ok=True)
        candidate, number = folder, 1
        while True:
            try:
                candidate.mkdir()
                return candidate
            except FileExistsError:
                number += 1
                candidate = folder.with_name(f"{folder.name}-{number}")
    except OSError as error:
        raise NavseqError(
            f"cannot create it: {error.strerror}", source=f"output folder {folder}"
        ) from None


def reserve_file(folder: Path, name: str) -> Path:
    """A new file ``folder/name`` (or ``stem-2.ext``, ``stem-3.ext``, ... if taken).

    The file is created empty with O_EXCL, so two runs writing into the same folder
    at once cannot pick the same name; the caller then replaces it with the content.
    """
    stem, suffix = os.path.splitext(name)
    candidate, number = folder / name, 1
    while True:
        try:
            fd = os.open(candidate, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            os.close(fd)
            return candidate
        except FileExistsError:
            number += 1
            candidate = folder / f"{stem}-{number}{suffix}"
        except OSError as error:
            raise NavseqError(
                f"cannot create it: {error.strerror}", source=str(candidate)
            ) from None
