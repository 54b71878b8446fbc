"""Safe YAML parsing into :class:`Located` trees with line numbers.

PyYAML *composes* the document (syntax only, no object construction; libyaml's C
parser where installed); navseq then walks the node graph itself so that every value
keeps its line number.
Only plain YAML types are accepted (null, bool, int, float, str, lists, mappings):
any other tag is an error. Aliases are allowed, but before anything is built the
document's size *with aliases expanded* is computed on the node graph (linear in
the written size): an "alias bomb" (a few lines that expand to billions of values)
or an alias that contains itself is refused at once.
"""

from __future__ import annotations

import re
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from navseq.errors import NavseqError
from navseq.files import limit_from_environment
from navseq.mission.located import MAX_DEPTH, Located
from navseq.mission.problems import Problems
from navseq.text import text_problem

# Aliases may repeat what was written, but not blow it up: the expanded document may
# hold at most this many values more than were written.
MAX_ALIAS_EXPANSION = 100_000

# About 160 000 waypoints written long-hand: a 100 000-waypoint mission (recorded
# patrols) still loads, while a 10 MiB file of tiny values is refused before composing.
MAX_VALUES = 1_000_000
MAX_VALUES_VARIABLE = "NAVSEQ_MAX_YAML_VALUES"
_VALUE_EVENTS = (yaml.ScalarEvent, yaml.SequenceStartEvent, yaml.MappingStartEvent, yaml.AliasEvent)
_FAST_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

_TAG = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_TAG + name for name in ("null", "bool", "int", "float", "str")}
# PyYAML follows YAML 1.1, where "1e3" (no dot) is text; YAML 1.2 and every user
# reads it as a number. Possessive quantifiers never give back what they matched, so
# the match is linear in the scalar's length (a backtracking "\d+\.?\d*" was quadratic:
# 38 s on 100 000 digits).
EXPONENT_FLOAT = re.compile(r"[-+]?+(?:\d++(?:\.\d*+)?+|\.\d++)[eE][-+]?+\d++")


def parse_yaml(
    text: str,
    source: str,
    problems: Problems,
    *,
    first_line: int = 1,
    budget: ValueBudget | None = None,
) -> Located | None:
    """Parse one YAML document. Syntax errors raise; duplicate keys are recorded.

    ``first_line`` is the file line of the text's first line (YAML inside a launch
    file). ``budget`` bounds the values read, across documents if shared. Returns
    None for an empty document.
    """
    offset = first_line - 1
    try:
        _spend_values(text, source, offset, budget or ValueBudget())
        root = _compose(text)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"{source}:{mark.line + 1 + offset}" if mark is not None else source
        what = error.problem or error.context or "syntax error"
        raise NavseqError(f"is not valid YAML: {what}", source=where) from None
    except yaml.YAMLError as error:
        raise NavseqError(f"is not valid YAML: {error}", source=source) from None
    except RecursionError:
        raise NavseqError("is nested too deeply to be a mission", source=source) from None
    if root is None:
        return None
    walker = _Walker(source, problems, offset)
    walker.check_expansion(root)
    return walker.walk(root, 0)


def _compose(text: str) -> Node | None:
    """The document's node graph, composed by libyaml (fast) where installed.

    On a syntax error the pure-Python composer reads the text again: its error names
    the line where the construct went wrong, libyaml's the line where it noticed.
    """
    try:
        return yaml.compose(text, Loader=_FAST_LOADER)
    except yaml.MarkedYAMLError:
        if _FAST_LOADER is yaml.SafeLoader:
            raise
        yaml.compose(text, Loader=yaml.SafeLoader)
        raise


class TooManyValuesError(NavseqError):
    """A document (or a launch tree's documents together) holds too many values."""


class ValueBudget:
    """How many more YAML values may be read; one budget can span several documents
    (the parameters of a launch file and the files it includes)."""

    def __init__(self, limit: int | None = None):
        self.limit = limit or limit_from_environment(MAX_VALUES_VARIABLE, MAX_VALUES)
        self.left = self.limit


def _spend_values(text: str, source: str, offset: int, budget: ValueBudget) -> None:
    """Count the document's values against ``budget`` before composing it; refuse excess.

    Composing and checking cost some 20 µs a value; the 10 MiB a file may hold can
    write millions (minutes and gigabytes). Counting the parser's events (with libyaml's C
    parser where installed) is linear and quick, and stops at the limit. Syntax
    errors are left to the composer, which reports them with their lines.
    """
    count = 0
    try:
        for event in yaml.parse(text, Loader=_FAST_LOADER):
            if isinstance(event, _VALUE_EVENTS):
                count += 1
                if count > budget.left:
                    mark = event.start_mark
                    line = (mark.line if mark is not None else 0) + 1 + offset
                    raise TooManyValuesError(
                        f"holds more than {budget.limit:,} YAML values (with the documents "
                        "read before it); navseq refuses missions this large (write long "
                        "recorded paths as CSV, or set the environment variable "
                        f"{MAX_VALUES_VARIABLE} to raise the limit)",
                        source=f"{source}:{line}",
                    )
    except yaml.YAMLError:
        pass
    budget.left -= count


def parse_yaml_value(
    text: str, source: str, *, first_line: int = 1, budget: ValueBudget | None = None
) -> Located | None:
    """A YAML value written inside another file (a launch file's attribute or body)."""
    problems = Problems()
    result = parse_yaml(text, source, problems, first_line=first_line, budget=budget)
    problems.raise_if_any()
    return result


class _Walker:
    """Turns composed nodes into Located values; an aliased node is built once and shared."""

    def __init__(self, source: str, problems: Problems, line_offset: int):
        self.source = source
        self.line_offset = line_offset
        self.problems = problems
        self.built: dict[int, Located] = {}
        self.constructor = yaml.SafeLoader("")

    def check_expansion(self, root: Node) -> None:
        """Refuse documents whose aliases contain themselves or expand far beyond the text."""
        sizes: dict[int, int] = {}
        in_progress: set[int] = set()

        def expanded_size(node: Node, depth: int) -> int:
            key = id(node)
            if key in sizes:
                return sizes[key]
            if key in in_progress:
                raise NavseqError(
                    "an alias refers to a value that contains it (a loop)", source=self.where(node)
                )
            if depth > MAX_DEPTH:
                raise NavseqError(
                    f"is nested more than {MAX_DEPTH} levels deep", source=self.where(node)
                )
            in_progress.add(key)
            if isinstance(node, SequenceNode):
                children: list[Node] = node.value
            elif isinstance(node, MappingNode):
                children = [part for pair in node.value for part in pair]
            else:
                children = []
            size = 1 + sum(expanded_size(child, depth + 1) for child in children)
            in_progress.discard(key)
            sizes[key] = size
            return size

        total = expanded_size(root, 0)
        if total > len(sizes) + MAX_ALIAS_EXPANSION:
            raise NavseqError(
                f"has aliases that expand {len(sizes)} written values to {total}; "
                "refusing it (an alias bomb?)",
                source=self.where(root),
            )

    def where(self, node: Node) -> str:
        return f"{self.source}:{node.start_mark.line + 1 + self.line_offset}"

    def walk(self, node: Node, depth: int) -> Located:
        built = self.built.get(id(node))
        if built is None:
            built = self.built[id(node)] = self.build(node, depth)
        return built

    def build(self, node: Node, depth: int) -> Located:
        if isinstance(node, ScalarNode):
            return Located(self.scalar(node), self.where(node))
        if isinstance(node, SequenceNode):
            self.require_tag(node, _TAG + "seq")
            return Located([self.walk(item, depth + 1) for item in node.value], self.where(node))
        if isinstance(node, MappingNode):
            self.require_tag(node, _TAG + "map")
            return self.mapping(node, depth)
        raise NavseqError("holds an unknown kind of YAML node", source=self.where(node))

    def require_tag(self, node: Node, tag: str) -> None:
        if node.tag != tag:
            kind = str(node.tag).removeprefix(_TAG)
            raise NavseqError(
                f"uses the YAML type '{kind}', which navseq does not accept",
                source=self.where(node),
            )

    def scalar(self, node: ScalarNode) -> Any:
        if node.tag not in _SCALAR_TAGS:
            kind = node.tag.removeprefix(_TAG)
            raise NavseqError(
                f"the value {node.value[:40]!r} has the YAML type '{kind}', which "
                "navseq does not accept (quote it if it is text)",
                source=self.where(node),
            )
        problem = text_problem(node.value, single_line=False)
        if problem is not None:  # also in keys: messages print them
            raise NavseqError(f"the text {node.value[:40]!r} {problem}", source=self.where(node))
        # A plain scalar's style is None from PyYAML's composer, "" from libyaml's.
        if node.tag == _TAG + "str" and not node.style and EXPONENT_FLOAT.fullmatch(node.value):
            return float(node.value)
        try:
            return self.constructor.construct_object(node)
        # PyYAML's constructors fail on some empty or odd values (``!!float ""``:
        # IndexError, ``!!bool maybe``: KeyError) with more than YAMLError.
        except (yaml.YAMLError, ValueError, OverflowError, LookupError, TypeError) as error:
            raise NavseqError(
                f"cannot read the value {node.value[:40]!r}: {error}", source=self.where(node)
            ) from None

    def mapping(self, node: MappingNode, depth: int) -> Located:
        values: dict[str, Located] = {}
        key_where: dict[str, str] = {}
        for key_node, value_node in self.entries(node, depth):
            if not isinstance(key_node, ScalarNode):
                raise NavseqError(
                    "has a key that is a list or mapping; keys must be names",
                    source=self.where(key_node),
                )
            key = key_node.value
            problem = text_problem(key, single_line=False)
            if problem is not None:
                raise NavseqError(f"the key {key[:40]!r} {problem}", source=self.where(key_node))
            if key in values:
                first_line = key_where[key].rsplit(":", 1)[1]
                shown = key if len(key) <= 60 else key[:57] + "..."
                self.problems.add(
                    f"the key '{shown}' appears twice (first at line {first_line}); "
                    "the second one would silently win",
                    source=self.where(key_node),
                )
                continue
            values[key] = self.walk(value_node, depth + 1)
            key_where[key] = self.where(key_node)
        return Located(values, self.where(node), key_where)

    def entries(self, node: MappingNode, depth: int) -> list[tuple[Node, Node]]:
        """Key/value pairs with YAML merge keys (``<<: *defaults``) expanded; explicit win."""
        explicit: list[tuple[Node, Node]] = []
        merged: list[tuple[Node, Node]] = []
        for key_node, value_node in node.value:
            if key_node.tag != _TAG + "merge":
                explicit.append((key_node, value_node))
                continue
            sources = value_node.value if isinstance(value_node, SequenceNode) else [value_node]
            for source in sources:
                if not isinstance(source, MappingNode):
                    raise NavseqError(
                        "a merge key (<<) must refer to a mapping", source=self.where(source)
                    )
                merged.extend(self.entries(source, depth + 1))
        names = {k.value for k, _ in explicit if isinstance(k, ScalarNode)}
        kept: list[tuple[Node, Node]] = []
        for key_node, value_node in merged:
            name = key_node.value if isinstance(key_node, ScalarNode) else None
            if name not in names:
                names.add(name)
                kept.append((key_node, value_node))
        return kept + explicit
