"""User text made safe to print and checked to be real text.

Waypoint names, frames, file paths and the reasons a navigation server gives are
written by users (or by whoever wrote the mission file). Printed raw, a control
character can retitle, clear or take over the terminal, and a lone UTF-16
surrogate (which YAML and JSON escapes can produce) makes ``print`` raise.
"""

from __future__ import annotations

# C0 controls (newline and tab included: names are one line), DEL and C1 controls.
_CONTROL = frozenset(range(0x00, 0x20)) | {0x7F} | frozenset(range(0x80, 0xA0))
_SURROGATES = range(0xD800, 0xE000)
# Characters that change how the rest of a line reads (bidirectional overrides,
# isolates, marks) without being control characters.
_BIDI = frozenset({0x200E, 0x200F, *range(0x202A, 0x202F), *range(0x2066, 0x206A)})


def _needs_escape(code: int) -> bool:
    return code in _CONTROL or code in _BIDI or code in _SURROGATES


def printable(value: str, *, keep_newlines: bool = False) -> str:
    """``value`` with control, bidi and surrogate characters escaped (``\\x1b``, ``\\ud800``).

    Everything else, including non-ASCII letters, is kept as written; with
    ``keep_newlines`` so are line breaks (a message listing several problems). A
    string that needs no escaping is returned unchanged.
    """

    def escaped(ch: str) -> bool:
        return _needs_escape(ord(ch)) and not (keep_newlines and ch == "\n")

    if not any(escaped(ch) for ch in value):
        return value
    return "".join(_escape(ch) if escaped(ch) else ch for ch in value)


def _escape(ch: str) -> str:
    code = ord(ch)
    if code <= 0xFF:
        return {"\n": "\\n", "\t": "\\t", "\r": "\\r"}.get(ch, f"\\x{code:02x}")
    return f"\\u{code:04x}"


def text_problem(value: str, *, single_line: bool = True) -> str | None:
    """Why ``value`` is not acceptable user text, or None when it is.

    Lone surrogates are never text. With ``single_line`` (names, frames), control
    characters and bidirectional overrides are refused too.
    """
    for ch in value:
        code = ord(ch)
        if code in _SURROGATES:
            return (
                f"holds U+{code:04X}, half of a UTF-16 surrogate pair, which is not a "
                'character (an escape such as "\\ud800" wrote it?)'
            )
        if single_line and (code in _CONTROL or code in _BIDI):
            return (
                f"holds the control character U+{code:04X}; names and frames are "
                "plain one-line text"
            )
    return None


def has_surrogates(value: str) -> bool:
    """True when ``value`` holds a lone surrogate (it cannot be encoded as UTF-8)."""
    return any(0xD800 <= ord(ch) < 0xE000 for ch in value)
