"""Files, carefully: writing so that a crash never leaves half of one and nothing is
replaced by accident; reading what a user names so that a pipe, a device or a huge
file is refused before it can hang navseq or fill the memory.
"""

from __future__ import annotations

import fcntl
import os
import re
import secrets
import stat
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

from navseq.errors import NavseqError
from navseq.text import printable

#: The temporary :func:`write_atomically` writes ``name`` through: ``.name.<8 hex>.tmp``.
TEMPORARY_NAME = re.compile(r"\.(?P<name>.+)\.[0-9a-f]{8}\.tmp")


def write_atomically(path: Path, data: str | bytes, *, replace: bool = True) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder.

    Readers see either the old file or the complete new one. With ``replace=False``
    an existing ``path`` is never replaced — even one that appears while writing —
    and :class:`FileExistsError` is raised instead. The new file gets ordinary
    permissions under the umask. Other failures raise :class:`OSError`.

    The temporary (:data:`TEMPORARY_NAME`) is locked (``flock``) from its creation
    until it is gone, so :func:`remove_stale_temporaries` can tell one a live process
    is writing from one a killed process left (the kernel drops the lock of a dead
    process, even after ``kill -9``).
    """
    # A file name with bytes that are not UTF-8 reaches Python as lone surrogates;
    # written as "\udcff" it stays readable (and JSON reads the escape back).
    payload = data.encode("utf-8", "backslashreplace") if isinstance(data, str) else data
    temporary, descriptor = _locked_temporary(path)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(payload)
            stream.flush()
            os.fsync(stream.fileno())
            # Published while still open and locked: never seen unlocked and unnamed.
            if replace:
                os.replace(temporary, path)
            else:
                _publish_without_replacing(temporary, path)
            temporary.unlink(missing_ok=True)
    finally:
        temporary.unlink(missing_ok=True)


def _locked_temporary(path: Path) -> tuple[Path, int]:
    """A new temporary beside ``path``, opened and locked; retried if a cleaner removed
    it between its creation and the lock."""
    while True:
        temporary = path.parent / f".{path.name}.{secrets.token_hex(4)}.tmp"
        # O_EXCL: never follow or reuse someone else's file; 0o666 honours the umask.
        descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX)
            if _still_named(descriptor, temporary):
                return temporary, descriptor
        except BaseException:
            os.close(descriptor)
            raise
        os.close(descriptor)


def remove_stale_temporaries(folder: Path, names: re.Pattern[str]) -> list[Path]:
    """Remove the temporaries of :func:`write_atomically` that killed processes left in
    ``folder``, for the files whose names match ``names``; returns those removed.

    Only regular files named as this module names its temporaries, and only those no
    live process holds locked: one being written now is left alone. Whatever else the
    folder holds is not touched. Failures are ignored (tidying up only).
    """
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        match = TEMPORARY_NAME.fullmatch(entry.name)
        if match is None or not names.fullmatch(match["name"]):
            continue
        path = Path(entry.path)
        try:
            descriptor = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
        except OSError:
            continue  # gone meanwhile, a symlink, unreadable
        try:
            if not stat.S_ISREG(os.fstat(descriptor).st_mode):
                continue
            try:
                fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                continue  # a live process is writing it
            if _still_named(descriptor, path):
                path.unlink()
                removed.append(path)
        except OSError:
            continue
        finally:
            os.close(descriptor)
    return removed


def _still_named(descriptor: int, path: Path) -> bool:
    """The open file is still the one at ``path`` (not removed or replaced meanwhile)."""
    try:
        return os.path.samestat(os.fstat(descriptor), os.lstat(path))
    except OSError:
        return False


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


# --- reading what a user names ---------------------------------------------------------


def open_input_file(
    path: Path, *, what: str, max_bytes: int, too_big: Callable[[int, int], str] | None = None
) -> BinaryIO:
    """Open a file the user named for reading, or raise NavseqError saying why not.

    Only regular files: a FIFO would block forever and a device (``/dev/zero``) never
    ends. Files over ``max_bytes`` are refused before anything is read. The type is
    checked on the open descriptor (opened non-blocking, so a FIFO cannot hang the
    open itself), so a file swapped for a pipe after the check is refused too.
    ``what`` names the role in messages (``mission file``, ``map image``).
    """
    source = str(path)
    describe_size = too_big or (lambda size, limit: _too_big(size, limit, what))
    try:
        _refuse_unless_regular(path.stat(), what, max_bytes, describe_size, source)
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        raise NavseqError("no such file", source=source) from None
    except OSError as error:
        raise NavseqError(f"cannot be read: {error.strerror or error}", source=source) from None
    except (ValueError, UnicodeEncodeError):  # a NUL byte or a lone surrogate in the name
        raise NavseqError("is not a valid file name", source=printable(repr(source))) from None
    try:
        _refuse_unless_regular(os.fstat(descriptor), what, max_bytes, describe_size, source)
        os.set_blocking(descriptor, True)
        return os.fdopen(descriptor, "rb")
    except BaseException:
        os.close(descriptor)
        raise


def read_input_bytes(
    path: Path, *, what: str, max_bytes: int, too_big: Callable[[int, int], str] | None = None
) -> bytes:
    """The bytes of a file the user named, with the checks of :func:`open_input_file`."""
    describe_size = too_big or (lambda size, limit: _too_big(size, limit, what))
    with open_input_file(path, what=what, max_bytes=max_bytes, too_big=describe_size) as stream:
        try:
            # The size can change between the check and the read; never read past the cap.
            data = stream.read(max_bytes + 1)
        except OSError as error:
            raise NavseqError(
                f"cannot be read: {error.strerror or error}", source=str(path)
            ) from None
    if len(data) > max_bytes:
        raise NavseqError(describe_size(len(data), max_bytes), source=str(path))
    return data


def require_file(path: Path, what: str) -> None:
    """A clear NavseqError unless ``path``, given by the user as ``what``, is a regular file.

    A FIFO or a device would hang or never end when read, so they are refused here,
    before anything opens them.
    """
    shown = printable(str(path))
    try:
        info = path.stat()
    except FileNotFoundError:
        raise NavseqError(f"no such file: {shown}", source=what) from None
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the name
        reason = error.strerror if isinstance(error, OSError) else "not a valid file name"
        raise NavseqError(f"cannot read {shown}: {reason or error}", source=what) from None
    if stat.S_ISDIR(info.st_mode):
        raise NavseqError(f"{shown} is a directory, not a file", source=what)
    if not stat.S_ISREG(info.st_mode):
        raise NavseqError(f"{shown} is not a regular file (a device, pipe or socket?)", source=what)


def limit_from_environment(variable: str, default: int) -> int:
    """A positive whole-number limit that the environment variable ``variable`` may raise."""
    written = os.environ.get(variable, "").strip()
    if not written:
        return default
    try:
        value = int(written.replace("_", ""))
    except ValueError:
        value = 0
    if value < 1:
        raise NavseqError(
            f"must be a whole number >= 1, got {printable(repr(written))}",
            source=f"environment variable {variable}",
        )
    return value


def _refuse_unless_regular(
    info: os.stat_result, what: str, max_bytes: int, too_big: Callable[[int, int], str], source: str
) -> None:
    if stat.S_ISDIR(info.st_mode):
        raise NavseqError(f"is a folder, not a {what}", source=source)
    if not stat.S_ISREG(info.st_mode):
        raise NavseqError(
            f"is not a regular file (a device, pipe or socket?); a {what} must be a regular file",
            source=source,
        )
    if info.st_size > max_bytes:
        raise NavseqError(too_big(info.st_size, max_bytes), source=source)


def _too_big(size: int, limit: int, what: str) -> str:
    return f"is {size / 2**20:.1f} MiB; navseq refuses a {what} over {limit / 2**20:g} MiB"
