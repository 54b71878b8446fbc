"""Reading a mission file defensively: the file may be missing, a folder, a device,
huge, or binary. Each case is one clear NavseqError, decided before reading much.
"""

from __future__ import annotations

import re
import stat
from pathlib import Path

from navseq.errors import NavseqError

MAX_MISSION_BYTES = 10 * 1024 * 1024  # far above any real mission; refuses accidents
# Text files never hold these; tab, newline and carriage return are fine.
_CONTROL_CHARACTER = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")


def read_mission_text(path: Path, *, max_bytes: int = MAX_MISSION_BYTES) -> str:
    """The file's text (UTF-8, an optional BOM dropped) or a NavseqError saying why not."""
    source = str(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        raise NavseqError("no such file", source=source) from None
    except OSError as error:
        raise NavseqError(f"cannot be read: {error.strerror or error}", source=source) from None
    except ValueError:  # a NUL byte in the name
        raise NavseqError("is not a valid file name", source=repr(source)) from None
    if stat.S_ISDIR(info.st_mode):
        raise NavseqError("is a folder, not a mission file", source=source)
    if not stat.S_ISREG(info.st_mode):
        # Reading a FIFO or a device could block forever or never end.
        raise NavseqError("is not a regular file (a device, pipe or socket?)", source=source)
    if info.st_size > max_bytes:
        raise NavseqError(_too_big(info.st_size, max_bytes), source=source)
    try:
        with open(path, "rb") as stream:
            # The size can change between stat and read; never read more than the cap.
            data = stream.read(max_bytes + 1)
    except OSError as error:
        raise NavseqError(f"cannot be read: {error.strerror or error}", source=source) from None
    if len(data) > max_bytes:
        raise NavseqError(_too_big(len(data), max_bytes), source=source)
    return decode_text(data, source)


def decode_text(data: bytes, source: str) -> str:
    """UTF-8 text, refusing binary data with a message that says so."""
    if b"\x00" in data:
        raise NavseqError("is a binary file (it contains NUL bytes), not a mission",
                          source=source)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise NavseqError(
            f"is not UTF-8 text (invalid byte 0x{data[error.start]:02x}); "
            "is it a binary file?",
            source=f"{source}:{line}",
        ) from None
    bad = _CONTROL_CHARACTER.search(text)
    if bad is not None:
        line = text[: bad.start()].count("\n") + 1
        raise NavseqError(f"contains the control character U+{ord(bad.group()):04X}; "
                          "is it a binary file?", source=f"{source}:{line}")
    return text


def _too_big(size: int, limit: int) -> str:
    return (f"is {size / 2**20:.1f} MiB; navseq refuses mission files over "
            f"{limit / 2**20:g} MiB (is this really a mission?)")

