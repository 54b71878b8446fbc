"""Safe YAML parsing into :class:`Located` trees with line numbers.

PyYAML *composes* the document (syntax only, no object construction; libyaml's C
parser where installed); navseq then walks the node graph itself so that every value
keeps its line number.
Only plain YAML types are accepted (null, bool, int, float, str, lists, mappings):
any other tag is an error. Aliases are allowed, but before anything is built the
document's size *with aliases expanded* is computed on the node graph (linear in
the written size): an "alias bomb" (a few lines that expand to billions of values)
or an alias that contains itself is refused at once.

Composing costs: PyYAML's composer resolves every scalar with Python regexes, and
the node graph is walked twice more (alias check, Located values): 100 000 waypoints
took 18 s and 620 MB. Most documents use nothing but plain mappings, lists and
scalars, so :func:`parse_yaml` first tries a fast path, :class:`_EventBuilder`: one
pass over libyaml's parse events, building the Located values directly and reading
the common scalars (plain decimal ints and floats, plain words no YAML 1.1 rule
applies to) with exact shortcuts, every other scalar as the slow path does. Anything
the slow path would treat specially (anchors, aliases, merge keys, explicit tags,
duplicate keys, surrogates, several documents, too many values, a syntax error)
abandons the fast path and the document is read the slow way, so values, problems
and messages are the same either way (``tests/test_yaml_fast_path.py`` compares).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Iterator
from typing import Any, NoReturn

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from navseq.errors import NavseqError
from navseq.files import limit_from_environment
from navseq.mission.located import MAX_DEPTH, Located
from navseq.mission.problems import Problems
from navseq.mission.yaml_flow_lines import SENTINEL, NotPlain, Run, find_runs
from navseq.text import printable, text_problem

# Aliases may repeat what was written, but not blow it up: the expanded document may
# hold at most this many values more than were written.
MAX_ALIAS_EXPANSION = 100_000

# About 160 000 waypoints written long-hand: a 100 000-waypoint mission (recorded
# patrols) still loads, while a 10 MiB file of tiny values is refused before composing.
MAX_VALUES = 1_000_000
MAX_VALUES_VARIABLE = "NAVSEQ_MAX_YAML_VALUES"
_VALUE_EVENTS = (yaml.ScalarEvent, yaml.SequenceStartEvent, yaml.MappingStartEvent, yaml.AliasEvent)
_COLLECTION_STARTS = (yaml.SequenceStartEvent, yaml.MappingStartEvent)
_COLLECTION_ENDS = (yaml.SequenceEndEvent, yaml.MappingEndEvent)
_FAST_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

_TAG = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_TAG + name for name in ("null", "bool", "int", "float", "str")}
# PyYAML follows YAML 1.1, where "1e3" (no dot) is text; YAML 1.2 and every user
# reads it as a number. The match is linear in the scalar's length: the fraction's
# digits come only after a ".", so no digit can be read by two repeats (a backtracking
# "\d+\.?\d*" was quadratic: 38 s on 100 000 digits), and no possessive quantifier is
# needed (Python 3.10 has none).
EXPONENT_FLOAT = re.compile(r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)[eE][-+]?\d+")

# No value navseq reads needs a long whole number, and Python refuses to convert one of
# more than 4300 decimal digits (``sys.set_int_max_str_digits``; the environment may
# lower it to 640) either way, from text or to text: a ValueError deep in the reader,
# or in a message that prints the value. Hexadecimal, octal and binary are not limited
# when read, only when printed, so the bound is on the digits as written, with room
# for hexadecimal's 1.2 decimal digits per digit.
MAX_INTEGER_DIGITS = min(1000, int(0.8 * sys.get_int_max_str_digits()) or 1000)
_INT_TAG = "tag:yaml.org,2002:int"


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
    budget = budget or ValueBudget()
    if _FAST_LOADER is not yaml.SafeLoader:
        try:
            root, count = _EventBuilder(source, problems, first_line - 1, budget.left).build(text)
        except _SlowPath:
            pass
        else:
            budget.left -= count
            return root
    return _parse_slowly(text, source, problems, first_line - 1, budget)


def _parse_slowly(
    text: str, source: str, problems: Problems, offset: int, budget: ValueBudget
) -> Located | None:
    """Compose the node graph, check its aliases, then walk it into Located values."""
    try:
        _spend_values(text, source, offset, budget)
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
    """Count the document's values against ``budget`` and check how deep it nests,
    before composing it; refuse excess.

    Composing and checking cost some 20 µs a value; the 10 MiB a file may hold can
    write millions (minutes and gigabytes). Counting the parser's events (with libyaml's C
    parser where installed) is linear and quick, and stops at the limit. Syntax
    errors are left to the composer, which reports them with their lines. For the
    depth, see :func:`refuse_deep_nesting`.
    """
    count = 0
    for event in _shallow_events(text, source, offset):
        if isinstance(event, _VALUE_EVENTS):
            count += 1
            if count > budget.left:
                raise TooManyValuesError(
                    f"holds more than {budget.limit:,} YAML values (with the documents "
                    "read before it); navseq refuses missions this large (write long "
                    "recorded paths as CSV, or set the environment variable "
                    f"{MAX_VALUES_VARIABLE} to raise the limit)",
                    source=f"{source}:{_line_of(event, offset)}",
                )
    budget.left -= count


def refuse_deep_nesting(text: str, source: str, *, first_line: int = 1) -> None:
    """Raise :class:`NavseqError` (with the line) if ``text`` nests more than
    :data:`MAX_DEPTH` lists and mappings; for readers that then hand it to PyYAML.

    PyYAML's composer recurses once per level (libyaml's in C, where nothing stops
    it: ``[[[[...`` 50 000 levels deep crashed the process with SIGSEGV), and the
    parser's own work per event grows with the depth of the open flow collections
    (the same text took 30 s to parse before the crash). The parser's events come one
    level at a time, so the depth is known before the parser goes any deeper: a
    document opening more than :data:`MAX_DEPTH` collections is refused there, after
    a few hundred events at most. Syntax errors are left to the reader.
    """
    for _ in _shallow_events(text, source, first_line - 1):
        pass


def _shallow_events(text: str, source: str, offset: int) -> Iterator[yaml.Event]:
    """The document's parse events, until a syntax error ends them; NavseqError where a
    collection opens deeper than :data:`MAX_DEPTH` (see :func:`refuse_deep_nesting`)."""
    depth = 0
    try:
        for event in yaml.parse(text, Loader=_FAST_LOADER):
            if isinstance(event, _COLLECTION_STARTS):
                depth += 1
                if depth > MAX_DEPTH:
                    raise NavseqError(
                        f"is nested more than {MAX_DEPTH} levels deep",
                        source=f"{source}:{_line_of(event, offset)}",
                    )
            elif isinstance(event, _COLLECTION_ENDS):
                depth -= 1
            yield event
    except yaml.MarkedYAMLError as error:
        # libyaml 0.2.6 (in PyYAML's wheels since 6.0.2; Debian 12 has 0.2.5) refuses a
        # collection 1000 levels deep in its scanner, which reads a flow collection's
        # openings ahead before the parser hands out their events: the refusal comes
        # before the depth above is passed, and is the same refusal.
        mark = error.problem_mark
        if mark is not None and "maximum nesting depth" in (error.problem or ""):
            raise NavseqError(
                f"is nested more than {MAX_DEPTH} levels deep",
                source=f"{source}:{mark.line + 1 + offset}",
            ) from None
        return
    except yaml.YAMLError:
        return


def _line_of(event: yaml.Event, offset: int) -> int:
    mark = event.start_mark
    return (mark.line if mark is not None else 0) + 1 + offset


def parse_yaml_value(
    text: str, source: str, *, first_line: int = 1, budget: ValueBudget | None = None
) -> Located | None:
    """A YAML value written inside another file (a launch file's attribute or body)."""
    problems = Problems()
    result = parse_yaml(text, source, problems, first_line=first_line, budget=budget)
    problems.raise_if_any()
    return result


class NumberTooLongError(NavseqError):
    """A whole number with more digits than any value can need (:data:`MAX_INTEGER_DIGITS`).

    Raised where the number is read, without a subject; the mapping that holds it
    names its key (:meth:`under_key`), so the message says which field it is.
    """

    def under_key(self, key: str) -> NumberTooLongError:
        """This error naming ``key`` (the nearest key around the number wins)."""
        if self.subject is not None:
            return self
        shown = printable(key if len(key) <= 60 else key[:57] + "...")
        return NumberTooLongError(self.message, source=self.source, subject=f"key {shown}")


def _refuse_long_integer(literal: str, where: str) -> None:
    """Raise :class:`NumberTooLongError` for an integer literal too long to be a value.

    Counts the digits as written (sign, ``_``, ``:`` and a ``0x``/``0o``/``0b`` prefix
    left out), before Python is asked to convert them: linear, whatever the length.
    """
    body = literal.lstrip("+-")
    if body[:2].lower() in ("0x", "0o", "0b"):
        body = body[2:]
    digits = len(body) - body.count("_") - body.count(":")
    if digits > MAX_INTEGER_DIGITS:
        raise NumberTooLongError(
            f"the whole number {literal[:20]}... has {digits:,} digits; navseq reads whole "
            f"numbers of at most {MAX_INTEGER_DIGITS:,} digits (no coordinate, angle, time "
            "or count needs more: a typo or a damaged file?)",
            source=where,
        )


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
        if node.tag == _INT_TAG:  # digits only: checked before a slower look at the text
            _refuse_long_integer(node.value, self.where(node))
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
            try:
                values[key] = self.walk(value_node, depth + 1)
            except NumberTooLongError as error:
                raise error.under_key(key) from None
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


class _PlainScalar:
    """What :meth:`_EventBuilder.scalar` reads of a plain scalar's event."""

    __slots__ = ("end_mark", "start_mark", "value")
    style = None
    implicit = (True, False)

    def __init__(self, value: str, mark: Any):
        self.value = value
        self.start_mark = self.end_mark = mark


class _SlowPath(Exception):
    """The document needs the composer's full treatment (see the module docstring)."""


def _slow_path() -> NoReturn:
    raise _SlowPath


def _standard_resolvers(first: str, tags: tuple[str, ...]) -> bool:
    resolvers = yaml.resolver.Resolver.yaml_implicit_resolvers.get(first, [])
    return tuple(tag for tag, _ in resolvers) == tuple(_TAG + tag for tag in tags)


# Shortcuts valid only while PyYAML resolves numbers as it always has (nothing added).
_SHORTCUTS = _standard_resolvers("-", ("float", "int")) and all(
    _standard_resolvers(digit, ("float", "int", "timestamp")) for digit in "0123456789"
)
# Plain scalars whose YAML 1.1 reading is certain and cheap: a decimal int without
# leading zeros or "_" (PyYAML: int(value)); digits '.' digits (PyYAML: float(value));
# a word starting with a character no implicit resolver is registered for (text).
_PLAIN_INT = re.compile(r"-?(?:0|[1-9][0-9]*)")
_PLAIN_FLOAT = re.compile(r"-?[0-9]+\.[0-9]+")
_PLAIN_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
# Either of the two above at once (one match per value where most are numbers): the
# group holds the fraction of a _PLAIN_FLOAT.
_PLAIN_NUMBER = re.compile(r"-?[0-9]+(\.[0-9]+)?")
_RESOLVED_FIRST = frozenset(yaml.resolver.Resolver.yaml_implicit_resolvers)
_SURROGATE = re.compile("[\ud800-\udfff]")


class _EventBuilder:
    """The fast path: Located values straight from libyaml's events, or :class:`_SlowPath`."""

    def __init__(self, source: str, problems: Problems, offset: int, budget_left: int):
        self.source = source
        self.offset = offset
        self.budget_left = budget_left
        self.walker = _Walker(source, problems, offset)  # for the scalars it must read
        self.places: dict[int, str] = {}

    def where(self, mark: Any) -> str:
        return self._place_of_line(mark.line)

    def build(self, text: str) -> tuple[Located | None, int]:
        """The document's root (None when empty) and how many values it holds."""
        if _SURROGATE.search(text):
            _slow_path()  # the slow path names the value that holds one
        shortened, runs = find_runs(text)
        if runs:
            try:
                return self._build_text(shortened, dict(runs))
            except (_SlowPath, NotPlain):
                pass  # the events of the whole text decide
        return self._build_text(text, {})

    def _build_text(self, text: str, runs: dict[int, Run]) -> tuple[Located | None, int]:
        parser = _FAST_LOADER(text)
        try:
            return self._build(parser.get_event, runs)
        except (yaml.YAMLError, NavseqError):
            # The slow path reports it, after any problem it finds first (a syntax
            # error further on, an alias bomb), with the same message and line.
            _slow_path()
        finally:
            parser.dispose()

    def _place_of_line(self, line: int) -> str:
        place = self.places.get(line)
        if place is None:
            place = self.places[line] = f"{self.source}:{line + 1 + self.offset}"
        return place

    def _run_value(self, value: str, line: int) -> Any:
        """One plain value of a run's line, read as its scalar event would be."""
        if _SHORTCUTS:
            number = _PLAIN_NUMBER.fullmatch(value)
            if number is not None:
                if number[1]:
                    return float(value)
                if len(value) <= MAX_INTEGER_DIGITS and _PLAIN_INT.fullmatch(value):
                    return int(value)
        if value[:1] not in _RESOLVED_FIRST and _PLAIN_WORD.fullmatch(value):
            return value
        mark = yaml.Mark(self.source, 0, line, 0, None, 0)
        return self.scalar(_PlainScalar(value, mark))

    def _splice_run(
        self, event: Any, stack: list[list[Any]], runs: dict[int, Run]
    ) -> tuple[list[Located], int]:
        """The items (and value count) of the run ``event`` stands for, if it stands
        where the run was written: an item of a block list, on its line and column."""
        mark = event.start_mark
        run = runs.get(mark.line)
        top = stack[-1] if stack else None
        if (
            run is None
            or event.value != SENTINEL  # a longer text holding it: the run's lines were text
            or event.style
            or mark.column != run.column
            or top is None
            or type(top[0]) is not list
            or top[3]  # a flow list (see _build): the run's lines were no items of it
        ):
            raise NotPlain
        del runs[mark.line]  # each run is spliced once (_build checks all were)
        return run.items(self._place_of_line, self._run_value)

    def _build(self, next_event: Any, runs: dict[int, Run]) -> tuple[Located | None, int]:
        # Each open container: [value (dict or list), where, key_where, pending key].
        stack: list[list[Any]] = []
        root: Located | None = None
        documents = 0
        count = 0
        budget_left = self.budget_left
        located, where, scalar = Located, self.where, self.scalar
        places = self.places
        scalar_event, mapping_start, sequence_start = (
            yaml.ScalarEvent,
            yaml.MappingStartEvent,
            yaml.SequenceStartEvent,
        )
        end_events = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
        stream_end = yaml.StreamEndEvent
        while True:
            event = next_event()
            kind = type(event)
            if kind is scalar_event:
                count += 1
                if event.anchor is not None or event.tag is not None:
                    _slow_path()
                if runs and SENTINEL in event.value:
                    items, values = self._splice_run(event, stack, runs)
                    stack[-1][0].extend(items)
                    count += values - 1  # the sentinel was counted
                    if count > budget_left:
                        _slow_path()  # the slow path refuses it with the line
                    continue
                place = places.get(event.start_mark.line) or where(event.start_mark)
                top = stack[-1] if stack else None
                if top is not None and top[3] is None and type(top[0]) is dict:
                    # A key: its text as written, once, not a merge key.
                    key = event.value
                    if key in top[0] or (key == "<<" and not event.style):
                        _slow_path()
                    if event.style == '"' and text_problem(key, single_line=False):
                        _slow_path()
                    top[3] = key
                    top[2][key] = place
                    continue
                node = located(scalar(event), place)
            elif kind is mapping_start or kind is sequence_start:
                count += 1
                if event.anchor is not None or event.tag is not None:
                    _slow_path()
                if len(stack) >= MAX_DEPTH or count > budget_left:
                    _slow_path()
                top = stack[-1] if stack else None
                if top is not None and top[3] is None and type(top[0]) is dict:
                    _slow_path()  # a list or mapping as a key
                if kind is mapping_start:
                    stack.append([{}, where(event.start_mark), {}, None])
                else:  # a list's last slot: whether it is written in flow style
                    stack.append([[], where(event.start_mark), None, bool(event.flow_style)])
                continue
            elif kind in end_events:
                value, place, key_where, _ = stack.pop()
                if key_where is None:
                    node = located(value, place)
                else:
                    node = located(value, place, key_where)
            elif kind is stream_end:
                if runs:
                    raise NotPlain  # a run that was no list's items
                return root, count
            elif kind is yaml.DocumentStartEvent:
                documents += 1
                if documents > 1:
                    _slow_path()  # the composer's error names the line
                continue
            elif kind is yaml.AliasEvent:
                _slow_path()
            else:
                continue  # stream start, document end
            if count > budget_left:
                _slow_path()  # the slow path refuses it with the line
            if not stack:
                root = node
                continue
            top = stack[-1]
            if type(top[0]) is dict:
                top[0][top[3]] = node
                top[3] = None
            else:
                top[0].append(node)

    def scalar(self, event: Any) -> Any:
        value: str = event.value
        if not event.style:
            if _SHORTCUTS:
                if _PLAIN_FLOAT.fullmatch(value):
                    return float(value)
                if len(value) <= MAX_INTEGER_DIGITS and _PLAIN_INT.fullmatch(value):
                    return int(value)
            if value[:1] not in _RESOLVED_FIRST and _PLAIN_WORD.fullmatch(value):
                return value
            tag = self.walker.constructor.resolve(ScalarNode, value, event.implicit)
        else:
            tag = _TAG + "str"  # quoted or a block scalar (implicit tags only: no '!')
        node = ScalarNode(tag, value, event.start_mark, event.end_mark, event.style)
        return self.walker.scalar(node)  # as the slow path reads it, errors included
