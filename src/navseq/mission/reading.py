"""Reading a mission file defensively: the file may be missing, a folder, a device,
huge, or binary. Each case is one clear NavseqError, decided before reading much.
"""

from __future__ import annotations

import re
from pathlib import Path

from navseq.errors import NavseqError
from navseq.files import read_input_bytes

MAX_MISSION_BYTES = 10 * 1024 * 1024  # far above any real mission; refuses accidents
# Text files never hold these; tab, newline and carriage return are fine.
_CONTROL_CHARACTER = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")


def read_mission_text(
    path: Path, *, max_bytes: int = MAX_MISSION_BYTES, what: str = "mission file"
) -> str:
    """The file's text (UTF-8, an optional BOM dropped) or a NavseqError saying why not."""
    data = read_input_bytes(
        path,
        what=what,
        max_bytes=max_bytes,
        too_big=lambda size, limit: _too_big(size, limit, what),
    )
    return decode_text(data, str(path), what.removesuffix(" file"))


def decode_text(data: bytes, source: str, what: str = "mission") -> str:
    """UTF-8 text, refusing binary data with a message that says so."""
    if b"\x00" in data:
        raise NavseqError(f"is a binary file (it contains NUL bytes), not a {what}", source=source)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise NavseqError(
            f"is not UTF-8 text (invalid byte 0x{data[error.start]:02x}); is it a binary file?",
            source=f"{source}:{line}",
        ) from None
    bad = _CONTROL_CHARACTER.search(text)
    if bad is not None:
        line = text[: bad.start()].count("\n") + 1
        raise NavseqError(
            f"contains the control character U+{ord(bad.group()):04X}; is it a binary file?",
            source=f"{source}:{line}",
        )
    return text


def _too_big(size: int, limit: int, what: str) -> str:
    return (
        f"is {size / 2**20:.1f} MiB; navseq refuses {what}s over "
        f"{limit / 2**20:g} MiB (is this really a {what.removesuffix(' file')}?)"
    )
