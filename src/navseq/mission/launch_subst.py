"""roslaunch substitution args, resolved without ROS.

Resolved like roslaunch does: ``$(arg NAME)`` (the args of the file being read),
``$(dirname)`` (that file's folder), ``$(env NAME)``, ``$(optenv NAME [default words])``
and ``$(find PKG)`` (the package on ``ROS_PACKAGE_PATH`` whose ``package.xml`` names
it). What cannot be known without running roslaunch (``$(eval ...)``, ``$(anon ...)``,
a ``$(find)`` of a package that is not on the path) stays in the text as written, so
that whoever uses the value can say that it was not resolved. A substitution that
roslaunch itself refuses (an undeclared or unset arg, an unset ``$(env)``, an unknown
command) is a :class:`SubstitutionError`.
"""

from __future__ import annotations

import os
from pathlib import Path

from navseq.errors import NavseqError
from navseq.mission.reading import read_mission_text
from navseq.mission.xml_tree import parse_xml

COMMANDS = ("arg", "dirname", "env", "optenv", "find", "anon", "eval")
# rospack crawls whole trees; navseq bounds the walk, since ROS_PACKAGE_PATH may name "/".
MAX_SEARCH_DEPTH = 6
MAX_SEARCHED_FOLDERS = 20_000
# Args that expand other args can grow ten-fold per level (an 874-byte file reached
# gigabytes in five). One attribute or body may grow by at most MAX_EXPANSION_CHARS,
# and all substitutions of a launch tree together by at most MAX_TOTAL_EXPANSION_CHARS,
# which also bounds the work spent parsing what they produce.
MAX_EXPANSION_CHARS = 1024 * 1024
MAX_TOTAL_EXPANSION_CHARS = 4 * 1024 * 1024


class SubstitutionError(NavseqError):
    """What roslaunch would refuse; ``offset`` is where in the text, for a line number."""

    def __init__(self, message: str, offset: int = 0):
        super().__init__(message)
        self.offset = offset


class ExpansionLimitError(NavseqError):
    """Substitution would grow the text beyond navseq's limits; reading stops here."""


class ExpansionBudget:
    """How much text substitutions may still add, shared by every file of a launch tree."""

    def __init__(self, total: int = MAX_TOTAL_EXPANSION_CHARS, per_text: int = MAX_EXPANSION_CHARS):
        self.left = total
        self.total = total
        self.per_text = per_text

    def check(self, written: int, resolved: int, command: str) -> None:
        """Refuse a text that has grown from ``written`` to ``resolved`` characters so far."""
        growth = resolved - written
        if growth > self.per_text:
            raise ExpansionLimitError(
                f"$({command}) makes this value grow by more than {_mib(self.per_text)} "
                "(navseq's limit for one attribute or body); do args expand each other "
                "over and over (an expansion bomb)?"
            )
        if growth > self.left:
            raise ExpansionLimitError(
                f"$({command}) makes the launch files' substitutions grow by more than "
                f"{_mib(self.total)} in all (navseq's limit); do args expand each other "
                "over and over (an expansion bomb)?"
            )

    def spend(self, written: int, resolved: int) -> None:
        self.left -= max(0, resolved - written)


def _mib(chars: int) -> str:
    return f"{chars / 2**20:g} MiB"


class LaunchArgs:
    """The ``<arg>``s of one launch file: roslaunch scopes them per file, not per group.

    ``passed`` are the values the including file gives (``<include><arg .../>``).
    """

    def __init__(self, passed: dict[str, str] | None = None):
        self.passed = dict(passed or {})
        self.values: dict[str, str | None] = {}  # None: declared, but no value anywhere

    def declare(self, name: str, *, value: str | None, default: str | None) -> None:
        if name in self.values:
            raise SubstitutionError(f"declares arg '{name}' a second time")
        if value is not None:
            if name in self.passed:
                raise SubstitutionError(
                    f"arg '{name}' has a fixed value= here, so the including file cannot "
                    "set it (roslaunch refuses this too); write default= to allow it"
                )
            self.values[name] = value
        else:
            self.values[name] = self.passed.get(name, default)

    def value(self, name: str, offset: int) -> str:
        if name not in self.values:
            raise SubstitutionError(
                f"$(arg {name}): no arg '{name}' is declared in this file before this line; "
                f'declare it with <arg name="{name}" default="..."/>',
                offset,
            )
        value = self.values[name]
        if value is None:
            raise SubstitutionError(
                f"$(arg {name}): arg '{name}' has neither a default nor a value and no "
                f"including file passes it (roslaunch would need {name}:=... on its command "
                "line); give it a default=",
                offset,
            )
        return value

    def given(self) -> dict[str, str]:
        """The args that have a value, for ``<include pass_all_args="true">``."""
        return {name: value for name, value in self.values.items() if value is not None}


class PackageFinder:
    """``$(find PKG)`` without rospack: the folders of ``ROS_PACKAGE_PATH``, crawled once."""

    def __init__(self, package_path: str | None = None):
        if package_path is None:
            package_path = os.environ.get("ROS_PACKAGE_PATH", "")
        self.roots = [Path(part) for part in package_path.split(os.pathsep) if part]
        self._index: dict[str, Path] | None = None

    def find(self, name: str) -> Path | None:
        if self._index is None:
            self._index = self._crawl()
        return self._index.get(name)

    def why_missing(self, name: str) -> str:
        if not self.roots:
            return f"package '{name}' not found: ROS_PACKAGE_PATH is not set"
        return f"package '{name}' is not on ROS_PACKAGE_PATH"

    def _crawl(self) -> dict[str, Path]:
        index: dict[str, Path] = {}
        budget = MAX_SEARCHED_FOLDERS
        for root in self.roots:  # earlier entries win, as in rospack
            stack = [(root, 0)]
            while stack and budget > 0:
                folder, depth = stack.pop()
                budget -= 1
                try:
                    entries = sorted(os.scandir(folder), key=lambda e: e.name, reverse=True)
                except (OSError, ValueError):
                    continue
                names = {entry.name for entry in entries}
                if "CATKIN_IGNORE" in names:
                    continue
                if "package.xml" in names:
                    # A package's own subfolders hold no other packages worth finding.
                    name = _package_name(folder / "package.xml")
                    if name:
                        index.setdefault(name, folder)
                    continue
                if depth < MAX_SEARCH_DEPTH:
                    stack.extend(
                        (Path(entry.path), depth + 1)
                        for entry in entries
                        if not entry.name.startswith(".") and _is_folder(entry)
                    )
        return index


def _is_folder(entry: os.DirEntry[str]) -> bool:
    try:
        return entry.is_dir()  # follows symbolic links, as workspaces often use them
    except OSError:
        return False


def _package_name(path: Path) -> str | None:
    """The ``<name>`` of a package.xml, or None when it cannot be read."""
    try:
        root = parse_xml(read_mission_text(path, max_bytes=1024 * 1024), str(path))
    except NavseqError:
        return None
    name = root.child("name") if root.tag == "package" else None
    return (name.body.strip() or None) if name is not None else None


class Substitution:
    """Resolves the substitution args in the text of one launch file."""

    def __init__(
        self,
        args: LaunchArgs,
        folder: Path | None,
        packages: PackageFinder,
        budget: ExpansionBudget | None = None,
    ):
        self.args = args
        self.folder = folder
        self.packages = packages
        self.budget = budget or ExpansionBudget()

    def resolve(self, text: str) -> str:
        if "$(" not in text:
            return text
        if text.startswith("$(eval ") and text.endswith(")"):
            return text  # Python code; navseq never runs what a file says
        parts = []
        position = 0
        length = 0  # of the parts so far: checked before the text is built, not after
        while (start := text.find("$(", position)) != -1:
            end = text.find(")", start)
            if end == -1:
                break  # roslaunch keeps an unclosed "$(" as text too
            body = text[start + 2 : end]
            resolved = self._one(body, start)
            piece = text[start : end + 1] if resolved is None else resolved
            length += (start - position) + len(piece)
            self.budget.check(end + 1, length, " ".join(body.split()[:2]))
            parts.append(text[position:start])
            parts.append(piece)
            position = end + 1
        parts.append(text[position:])
        result = "".join(parts)
        self.budget.spend(len(text), len(result))
        return result

    def explain(self, text: str) -> str:
        """``text``, plus why a ``$(find)`` in it stayed unresolved (for "not followed")."""
        missing = [word.split(")")[0] for word in text.split("$(find ")[1:]]
        reasons = [self.packages.why_missing(name.strip()) for name in missing if name.strip()]
        return f"{text} ({'; '.join(reasons)})" if reasons else text

    def _one(self, body: str, offset: int) -> str | None:
        """The value of ``$(body)``; None when it stays as written."""
        words = body.split()
        if not words or words[0] not in COMMANDS:
            known = ", ".join(f"$({command})" for command in COMMANDS)
            raise SubstitutionError(
                f"$({body}) is not a roslaunch substitution (roslaunch knows {known})", offset
            )
        command, rest = words[0], words[1:]
        if command in ("anon", "eval"):
            return None
        if command == "dirname":
            self._count(body, rest, 0, offset)
            return None if self.folder is None else str(self.folder)
        if command == "optenv":
            if not rest:
                raise SubstitutionError(f"$({body}) names no environment variable", offset)
            return os.environ.get(rest[0], " ".join(rest[1:]))
        self._count(body, rest, 1, offset)
        if command == "arg":
            return self.args.value(rest[0], offset)
        if command == "env":
            value = os.environ.get(rest[0])
            if value is None:
                raise SubstitutionError(
                    f"$(env {rest[0]}): the environment variable {rest[0]} is not set "
                    f"(write $(optenv {rest[0]} DEFAULT) for a default)",
                    offset,
                )
            return value
        package = self.packages.find(rest[0])
        return None if package is None else str(package)

    @staticmethod
    def _count(body: str, rest: list[str], wanted: int, offset: int) -> None:
        if len(rest) != wanted:
            what = "no name" if wanted == 0 else "exactly one name"
            raise SubstitutionError(f"$({body}) takes {what}, got {len(rest)}", offset)
