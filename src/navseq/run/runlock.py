"""One live run per output folder: an exclusive lock with the owner's pid.

Two ``navseq run --resume`` of one journal at the same time would both drive the robot
and journal the same visits twice. A run therefore holds an exclusive ``flock`` on
``<folder>/.navseq.lock`` for as long as it lives; the kernel drops the lock when the
process dies, even by ``kill -9``, so a lock can never outlive its run. The file keeps
the holder's pid, for the refusal message, and is removed on a clean release: a pid
found in a file nobody locks belongs to a run that died, and is reported as taken over.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
from pathlib import Path
from types import TracebackType

from navseq.errors import NavseqError

LOCK_NAME = ".navseq.lock"
_ATTEMPTS = 5  # a released lock file is removed: lock the new one instead, a few times at most


class RunLock:
    """Exclusive ownership of a run folder (its journal, report and picture).

    ``acquire()`` raises :class:`NavseqError` when another live process holds the
    folder; :attr:`took_over` then names the pid of a dead run whose lock was left.
    """

    def __init__(self, folder: Path) -> None:
        self.path = folder / LOCK_NAME
        self.took_over: int | None = None
        self._fd: int | None = None

    def acquire(self) -> RunLock:
        for _ in range(_ATTEMPTS):
            fd = self._open()
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                holder = _read_pid(fd)
                os.close(fd)
                who = f"process {holder}" if holder else "another process"
                raise NavseqError(
                    f"another navseq run ({who}) is using this folder and its journal; "
                    "two runs would both drive the robot. Wait for it to end, or stop it "
                    "first",
                    source=str(self.path.parent),
                ) from None
            if _still_named(fd, self.path):
                break
            os.close(fd)  # a run released (removed) it meanwhile: lock the new file
        else:
            raise NavseqError("cannot take the run lock", source=str(self.path))
        previous = _read_pid(fd)
        if previous and previous != os.getpid():
            self.took_over = previous
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return self

    def _open(self) -> int:
        try:
            # O_NOFOLLOW: a symlink planted at the lock's name is not followed.
            return os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
        except OSError as error:
            raise NavseqError(
                f"cannot create the run lock: {error.strerror}", source=str(self.path)
            ) from None

    def release(self) -> None:
        """Remove the lock file, then drop the lock: a clean end leaves nothing behind."""
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            self.path.unlink()
        os.close(self._fd)  # closing drops the flock
        self._fd = None

    def __enter__(self) -> RunLock:
        return self.acquire()

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.release()


def _still_named(fd: int, path: Path) -> bool:
    """The locked file is still the one at ``path`` (not removed by a run that ended)."""
    try:
        return os.path.samestat(os.fstat(fd), os.lstat(path))
    except OSError:
        return False


def _read_pid(fd: int) -> int | None:
    try:
        text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


__all__ = ["LOCK_NAME", "RunLock"]
