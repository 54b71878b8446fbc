"""The shell examples of the README and docs/, read as a test reads them.

An example is a fenced block in ``README.md`` or ``docs/*.md``:

- ```` ```bash ```` / ```` ```sh ````: every line is a command (``\\`` joins lines, a
  ``# comment`` is dropped, a line that is only a comment is skipped);
- ```` ```console ````: lines starting with ``$ `` are commands, and the lines after one
  (up to the next ``$ ``) are its expected output. In expected output a line ``...``
  stands for any number of lines, and a last line ``(exit N)`` gives the exit status
  (default 0). Times and real-time factors are normalised before comparing, as they
  depend on the machine.

:func:`examples_in` returns the commands of one file in document order, each with its
line number so that a failure points at the docs line to fix.
"""

from __future__ import annotations

import functools
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

# A fence: its indent, its language and the rest of its info string (```` ```python ros1 ````).
FENCE = re.compile(r"^(\s*)```(\w*)(?:[ \t]+([^`]*?))?\s*$")
SHELL_LANGUAGES = {"bash", "sh", "shell"}
EXIT_LINE = re.compile(r"^\(exit (\d+)\)$")

# What differs from one machine or run to the next: wall-clock figures, and simulated
# times printed with a unit (they depend on the planner build only through float noise).
_NORMALISE = (
    (re.compile(r"\d+(\.\d+)?x real time"), "Nx real time"),
    (re.compile(r"\d+(\.\d+)? ?(ms|s)\b"), "T s"),
    (re.compile(r"\d{8}-\d{6}(-\d+)?"), "YYYYMMDD-HHMMSS"),
    (re.compile(r" +"), " "),
)


@dataclass
class Example:
    """One command of the docs, with what the docs say it prints and returns."""

    path: Path
    line: int
    command: str
    expected_output: list[str] | None = None
    expected_status: int = 0
    block_lines: list[str] = field(default_factory=list)

    @property
    def where(self) -> str:
        return f"{self.path.name}:{self.line}"


def _strip_comment(line: str) -> str:
    # A `#` starts a comment only at a word start outside quotes (enough for our docs).
    quote = ""
    for index, char in enumerate(line):
        if char in "'\"" and not quote:
            quote = char
        elif char == quote:
            quote = ""
        elif char == "#" and not quote and (index == 0 or line[index - 1].isspace()):
            return line[:index].rstrip()
    return line.rstrip()


def _open_quote(command: str) -> bool:
    try:
        shlex.split(command)
    except ValueError:
        return True
    return False


def _shell_commands(path: Path, start: int, lines: list[str]) -> list[Example]:
    examples: list[Example] = []
    pending = ""
    pending_line = 0
    for offset, raw in enumerate(lines):
        text = _strip_comment(raw) if not pending else raw.rstrip()
        if not pending:
            pending_line = start + offset
        if text.endswith("\\"):
            pending += text[:-1] + " "
            continue
        command = (pending + _strip_comment(text)).strip()
        if _open_quote(command):  # a quoted argument goes on on the next line
            pending = command + " "
            continue
        pending = ""
        if command:
            examples.append(Example(path, pending_line, " ".join(command.split())))
    return examples


def _console_commands(path: Path, start: int, lines: list[str]) -> list[Example]:
    examples: list[Example] = []
    for offset, raw in enumerate(lines):
        if raw.startswith("$ "):
            examples.append(Example(path, start + offset, raw[2:].strip(), expected_output=[]))
        elif examples:
            output = examples[-1].expected_output
            assert output is not None
            output.append(raw.rstrip())
    for example in examples:
        output = example.expected_output or []
        while output and not output[-1]:
            output.pop()
        if output and (match := EXIT_LINE.match(output[-1])):
            example.expected_status = int(match.group(1))
            output.pop()
    return examples


def examples_in(path: Path) -> list[Example]:
    """Every shell command of a markdown file, in document order."""
    examples: list[Example] = []
    language: str | None = None
    indent = ""
    block: list[str] = []
    block_start = 0
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        fence = FENCE.match(line)
        if language is None:
            if fence:
                language, indent, block, block_start = (
                    fence.group(2),
                    fence.group(1),
                    [],
                    number + 1,
                )
            continue
        if fence and fence.group(1) == indent and not fence.group(2):
            if language in SHELL_LANGUAGES:
                examples += _shell_commands(path, block_start, block)
            elif language == "console":
                examples += _console_commands(path, block_start, block)
            language = None
            continue
        block.append(line[len(indent) :] if line.startswith(indent) else line)
    return examples


NOT_RUN = re.compile(r"^\s*<!-- not run here: (?P<reason>.*?) -->\s*$")


@dataclass
class Block:
    """One fenced block of the docs: its language, its text, and why it is not run (if
    the line before it says so: ``<!-- not run here: REASON -->``)."""

    path: Path
    line: int  # the opening fence's line
    language: str
    info: str  # what follows the language on the fence line: ``ros1`` in ```` ```python ros1 ````
    text: str
    not_run_because: str | None

    @property
    def where(self) -> str:
        return f"{self.path.name}:{self.line}"


def blocks_in(path: Path) -> list[Block]:
    """Every fenced block of a markdown file, in document order."""
    blocks: list[Block] = []
    lines = path.read_text(encoding="utf-8").splitlines()
    opened: tuple[int, str, str, str] | None = None  # line, language, info, indent
    body: list[str] = []
    last_text = ""
    reason: str | None = None
    for number, line in enumerate(lines, start=1):
        fence = FENCE.match(line)
        if opened is None:
            if fence:
                marker = NOT_RUN.match(last_text)
                opened = (number, fence.group(2), (fence.group(3) or "").strip(), fence.group(1))
                body = []
                reason = marker.group("reason").strip() if marker else None
            elif line.strip():
                last_text = line
            continue
        start, language, info, indent = opened
        if fence and fence.group(1) == indent and not fence.group(2):
            blocks.append(Block(path, start, language, info, "\n".join(body) + "\n", reason))
            opened = None
            last_text = line
            continue
        body.append(line[len(indent) :] if line.startswith(indent) else line)
    return blocks


def normalise(text: str) -> str:
    for pattern, replacement in _NORMALISE:
        text = pattern.sub(replacement, text)
    return text.strip()


def output_matches(expected: list[str], actual: list[str]) -> bool:
    """Whether the actual lines match the expected ones, ``...`` matching any lines."""
    want = [normalise(line) for line in expected]
    got = [normalise(line) for line in actual]

    @functools.cache
    def match(i: int, j: int) -> bool:
        while i < len(want):
            if want[i] == "...":
                return any(match(i + 1, k) for k in range(j, len(got) + 1))
            if j >= len(got) or want[i] != got[j]:
                return False
            i, j = i + 1, j + 1
        return j == len(got)

    return match(0, 0)
