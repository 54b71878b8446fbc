"""The fast YAML path (libyaml events straight to Located values) reads every document
exactly as the slow path (PyYAML's composer, then the located walker) does: the same
values, the same lines, the same problems and messages."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from navseq.errors import NavseqError
from navseq.mission import yaml_doc, yaml_flow_lines
from navseq.mission.located import Located
from navseq.mission.problems import Problems
from navseq.mission.yaml_doc import ValueBudget, parse_yaml

pytestmark = pytest.mark.skipif(
    yaml_doc._FAST_LOADER is yaml_doc.yaml.SafeLoader, reason="libyaml is not installed"
)


def _read(text: str, *, slow: bool, first_line: int = 1, budget: int | None = None) -> Any:
    """(value tree with places, recorded problems) or the error raised, as comparable data."""
    problems = Problems()
    spent = ValueBudget(budget)
    try:
        if slow:
            root = yaml_doc._parse_slowly(text, "m.yaml", problems, first_line - 1, spent)
        else:
            root = parse_yaml(text, "m.yaml", problems, first_line=first_line, budget=spent)
    except NavseqError as error:
        return ("error", str(error))
    return (_plain(root), [str(e) for e in problems.errors], spent.left)


def _plain(node: Located | None) -> Any:
    """The tree with every place and value's type, so 1 and 1.0 and True differ."""
    if node is None:
        return None
    value = node.value
    if isinstance(value, dict):
        return (
            node.where,
            {k: (node.key_where[k], _plain(v)) for k, v in value.items()},
        )
    if isinstance(value, list):
        return (node.where, [_plain(v) for v in value])
    return (node.where, type(value).__name__, repr(value))


def _same(text: str, **options: Any) -> Any:
    fast = _read(text, slow=False, **options)
    assert fast == _read(text, slow=True, **options), text
    return fast


SCALARS = [
    "1",
    "-1",
    "+1",
    "0",
    "-0",
    "00",
    "012",
    "0x1F",
    "0o17",
    "0b101",
    "1_000",
    "1:30",
    "1.5",
    "-1.5",
    "+1.5",
    "-0.0",
    "1.",
    ".5",
    "1.5e3",
    "1.5E+3",
    "5e-2",
    "1e3",
    "-1e3",
    "1_0.5",
    ".inf",
    "-.inf",
    ".nan",
    "1:30.5",
    "2001-12-14",
    "2001-12-14t21:59:43.10-05:00",
    "yes",
    "no",
    "Yes",
    "NO",
    "on",
    "Off",
    "y",
    "n",
    "true",
    "False",
    "TRUE",
    "null",
    "Null",
    "~",
    "",
    "north",
    "wp1",
    "_x",
    "x_1",
    "<<",
    "=",
    "a b",
    "-",
    "1e",
    "e5",
    "'quoted 1'",
    '"1.5"',
    "'yes'",
    '"\\u00e9t\\u00e9"',
    '"\\ud800"',
    "!!str 1",
    "!!int '7'",
    "!!float 1",
    "!!bool yes",
    "!!binary aGk=",
    "!custom 1",
    "! 1",
    "[]",
    "{}",
    "'': 1",
]


@pytest.mark.parametrize("scalar", SCALARS)
def test_every_kind_of_scalar_reads_the_same_in_a_mapping_and_a_list(scalar: str) -> None:
    _same(f"a: {scalar}\nb: [{scalar}, 2]\n")
    _same(f"- {scalar}\n- x\n")


DOCUMENTS = [
    "",
    "# only a comment\n",
    "---\n",
    "a: 1\n---\nb: 2\n",  # two documents
    "a: 1\na: 2\nb: 3\nb: 4\n",  # duplicate keys: problems, not errors
    "a: &x {k: 1}\nb: *x\n",  # aliases
    "base: &b {x: 1, y: 2}\nw: {<<: *b, y: 3}\n",  # merge key
    "a: [1, 2\n",  # syntax error
    "a: b: c\n",
    "a:\n  - {x: 1, y: 2}\n  - [1, 2, 3]\n  - text\n",
    "? [1, 2]\n: x\n",  # a list as a key
    "? {a: 1}\n: x\n",
    "1: one\n1.5: x\ntrue: y\n",  # keys are their text
    '"k\\ud800": 1\n',  # a surrogate in a key
    "a: |\n  two\n  lines\nb: >\n  folded\n  text\n",
    "a: !!map {x: 1}\nb: !!seq [1]\n",
    "a: !!set {x}\n",
    "a: &a [*a]\n",  # an alias inside itself
    "x: " + "[" * 70 + "]" * 70 + "\n",  # deeper than MAX_DEPTH
    "a:\n  b:\n    c: [1, {d: 2.5, e: [x, 'y']}]\n",
    "- &w {x: 1}\n- *w\n- *w\n",
    "x: " + "9" * 5000 + "\n",  # more digits than Python converts
    "a: {b: [1, -0x" + "f" * 2000 + "]}\n",
    "a: [[" * 40 + "]]" * 40 + "\n",  # deeper than MAX_DEPTH, opened two at a time
]


@pytest.mark.parametrize("text", DOCUMENTS)
def test_documents_read_the_same(text: str) -> None:
    _same(text)
    _same(text, first_line=40)  # YAML inside a launch file


def test_the_value_budget_is_spent_and_enforced_the_same() -> None:
    text = "w:\n" + "".join(f"  - {{x: {i}, y: 1.5}}\n" for i in range(50))
    assert _same(text)[2] == ValueBudget(None).limit - (3 + 50 * 5)  # keys count too
    refused = _same(text, budget=100)
    assert refused[0] == "error" and "more than 100 YAML values" in refused[1]


def test_a_long_document_takes_the_fast_path() -> None:
    text = "waypoints:\n" + "".join(
        f"  - {{name: wp{i}, x: {i}.25, y: -{i}, yaw: 90}}\n" for i in range(200)
    )
    root, count = yaml_doc._EventBuilder("m.yaml", Problems(), 0, 10_000).build(text)
    assert count == 3 + 200 * 9 and root is not None  # a mapping, 4 keys, 4 values
    assert _same(text)[0] == _plain(root)


_words = st.sampled_from([*SCALARS, "x", "name", "1.25", "-3", "yes", "5e-2", "wp7"])
_values = st.recursive(
    _words,
    lambda inner: (
        st.lists(inner, max_size=4).map(lambda xs: "[" + ", ".join(xs) + "]")
        | st.lists(st.tuples(_words, inner), max_size=4).map(
            lambda kv: "{" + ", ".join(f"{k}: {v}" for k, v in kv) + "}"
        )
    ),
    max_leaves=12,
)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(_words, _values), min_size=1, max_size=5))
def test_generated_documents_read_the_same(entries: list[tuple[str, str]]) -> None:
    _same("".join(f"{key}: {value}\n" for key, value in entries))


WAYPOINTS = [
    "{x: 1, y: 2}",
    "{name: a, x: 1.5, y: -2, z: -0.0, yaw: 450}",
    "{name: 7, x: 1, y: 2, yaw: -180}",
    "{name: '', x: 1, y: 2}",
    "{name: a, x: 1e9, y: 2}",
    "{x: true, y: 2}",
    "{x: 1}",
    "{x: 1, y: 2, yaw: 4000}",
    "{x: 1, y: 2, yaw: .nan}",
    "{x: 1, y: 2, dwell: 3}",
    "{x: 1, y: 2, colour: red}",
    "{x: 1, y: 2, yaw: 90, yaw_rad: 1}",
    "[1, 2, 90]",
    "{name: dup, x: 1, y: 2}",
]


@pytest.mark.parametrize("waypoint", WAYPOINTS)
def test_plain_waypoints_read_as_the_general_reader_reads_them(
    waypoint: str, tmp_path: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from navseq.mission import inspect_mission_file, navseq_format

    path = tmp_path / "m.yaml"
    path.write_text(f"waypoints:\n  - {waypoint}\n  - {{name: dup, x: 0, y: 0}}\n")

    def read() -> Any:
        mission, problems = inspect_mission_file(path)
        waypoints = mission.waypoints if mission is not None else ()
        return [(w, w.where) for w in waypoints], [str(e) for e in problems.errors]

    fast = read()
    monkeypatch.setattr(navseq_format, "_plain_waypoint", lambda node: None)
    assert fast == read()


# -- the line path: runs of one-line flow-mapping items, read by regex ------------------


def _run(count: int, indent: str = "  ", item: str = "{{name: wp{i}, x: {i}.5, y: -{i}}}") -> str:
    return "".join(f"{indent}- {item.format(i=i)}\n" for i in range(count))


def _line_path(text: str) -> Any:
    """The document read by the line path alone (it raises where it would give up)."""
    shortened, runs = yaml_flow_lines.find_runs(text)
    assert runs, "no run long enough"
    builder = yaml_doc._EventBuilder("m.yaml", Problems(), 0, ValueBudget(None).limit)
    root, _count = builder._build_text(shortened, runs)
    return _plain(root)


LINE_PATH_DOCUMENTS = [
    "waypoints:\n" + _run(12),
    "navseq: 1\nwaypoints:\n" + _run(10) + "defaults: {dwell: 2}\n",  # keys after the run
    "waypoints:\n" + _run(10, "") + "loops: 2\n",  # items at column 0
    "a:\n  b:\n" + _run(10, "    ") + "  c: 1\n",  # nested
    "waypoints:\n" + _run(5) + "  - [1, 2]\n" + _run(9),  # two runs around another item
    "waypoints:\n" + _run(9) + _run(9, "    "),  # an indent change ends a run (an error)
    "w:\n" + _run(10) + "    z: 3\n",  # a deeper line after the run (an error)
    "w:\n" + _run(10) + "  k: v\n",  # a key at the items' indent (an error)
    "w:\n" + _run(10) + "  # a comment\n" + _run(8),
    "w:\n\n" + _run(6) + "\n" + _run(6),  # blank lines within the list
    "w: |\n" + _run(10),  # inside a block scalar: text, not items
    "w: >\n" + _run(10),
    'w: "start\n' + _run(10) + '  end"\n',  # inside a quoted text
    "w: plain\n" + _run(10),  # after a plain scalar: an error
    "w: [\n" + _run(10) + "]\n",  # inside a flow list: an error
    "w:\n" + _run(10, item="{{x: {i}, x: 1}}"),  # a duplicate key: a problem
    "w:\n" + _run(10, item="{{name: n{i}, x: 1e3, y: 0x1F, z: .inf, a: yes, b: null}}"),
    "w:\n" + _run(10, item="{{name: north, x: -, y: +, z: ., t: 2001-12-14}}"),  # odd values
    "w:\n" + _run(10, item="{{a: 1_000, b: 012, c: -0, d: 1., e: -.5, f: +1.5, g: 00.5}}"),
    "w:\n" + _run(10, item="{{  a:   1 ,b: 2   }}") + "   ",  # spacing, trailing blanks
    "w:\n" + _run(10).replace("\n", "\r\n"),  # CRLF
    "w:\n" + _run(10) + f"  - {yaml_flow_lines.SENTINEL}\n",  # the sentinel written
    "---\nw:\n" + _run(10) + "...\n",
    "w:\n" + _run(10) + "---\nw: 2\n",  # a second document
    "w: &a\n" + _run(10) + "v: *a\n",  # an anchored list, aliased
]


@pytest.mark.parametrize("text", LINE_PATH_DOCUMENTS)
def test_documents_with_runs_of_one_line_items_read_the_same(text: str) -> None:
    _same(text)
    _same(text, first_line=40)


def test_a_recorded_patrol_takes_the_line_path_and_reads_the_same() -> None:
    text = "navseq: 1\nwaypoints:\n" + _run(
        300, item="{{name: wp{i}, x: {i}.25, y: -{i}, yaw: 90}}"
    )
    value, problems, left = _same(text)
    assert _line_path(text) == value
    assert problems == [] and left == ValueBudget(None).limit - (5 + 300 * 9)
    where, items = value[1]["waypoints"][1]
    assert where == "m.yaml:3"  # where the list starts, as YAML readers say
    assert items[0] == (
        "m.yaml:3",
        {
            "name": ("m.yaml:3", ("m.yaml:3", "str", "'wp0'")),
            "x": ("m.yaml:3", ("m.yaml:3", "float", "0.25")),
            "y": ("m.yaml:3", ("m.yaml:3", "int", "0")),
            "yaw": ("m.yaml:3", ("m.yaml:3", "int", "90")),
        },
    )
    assert items[-1][0] == "m.yaml:302"


def test_the_value_budget_is_enforced_within_a_run() -> None:
    text = "w:\n" + _run(50, item="{{x: {i}, y: 1.5}}")
    assert _line_path(text)
    refused = _same(text, budget=100)
    assert refused[0] == "error" and "more than 100 YAML values" in refused[1]


_run_values = st.sampled_from(
    [s for s in SCALARS if yaml_flow_lines._PAIR.fullmatch(f"k: {s}")] + ["wp7", "1.25", "-3"]
)
_run_keys = st.sampled_from(["x", "y", "name", "yaw", "on", "n", "_k", "k1"])


@settings(max_examples=200, deadline=None)
@given(
    st.lists(
        st.lists(st.tuples(_run_keys, _run_values), min_size=1, max_size=4),
        min_size=yaml_flow_lines.MIN_RUN,
        max_size=20,
    ),
    st.sampled_from(["", "  ", "    "]),
    st.sampled_from(["", "loops: 2\n", "  x: 1\n", "  - [1, 2]\n"]),
)
def test_generated_runs_read_the_same(
    lines: list[list[tuple[str, str]]], indent: str, after: str
) -> None:
    items = "".join(
        f"{indent}- {{" + ", ".join(f"{k}: {v}" for k, v in pairs) + "}\n" for pairs in lines
    )
    text = "w:\n" + items + after
    read = _same(text)
    if read[0] != "error" and not read[1]:  # the line path gives up on problems
        assert _line_path(text) == read[0]
