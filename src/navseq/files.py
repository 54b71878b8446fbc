"""Writing files so that a crash never leaves half of one, and nothing is replaced by accident."""

from __future__ import annotations

import os
import secrets
from pathlib import Path


def write_atomically(path: Path, data: str | bytes, *, replace: bool = True) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder.

    Readers see either the old file or the complete new one. With ``replace=False``
    an existing ``path`` is never replaced — even one that appears while writing —
    and :class:`FileExistsError` is raised instead. The new file gets ordinary
    permissions under the umask. Other failures raise :class:`OSError`.
    """
    payload = data.encode("utf-8") if isinstance(data, str) else data
    temporary = path.parent / f".{path.name}.{secrets.token_hex(4)}.tmp"
    try:
        # O_EXCL: never follow or reuse someone else's file; 0o666 honours the umask.
        descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(payload)
            stream.flush()
            os.fsync(stream.fileno())
        if replace:
            os.replace(temporary, path)
        else:
            _publish_without_replacing(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


def _publish_without_replacing(temporary: Path, target: Path) -> None:
    """Give the finished file its name unless that name appeared meanwhile."""
    try:
        os.link(temporary, target)  # fails if target exists: no check-then-write race
    except FileExistsError:
        raise
    except OSError:  # file systems without hard links
        if target.exists():
            raise FileExistsError(str(target)) from None
        os.replace(temporary, target)
