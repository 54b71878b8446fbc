"""Saving over a mission file so that only what the user changed changes.

The page edits a document (the file as the mission writer would write it); writing
that document out whole would drop the file's comments, reorder its keys and reformat
its numbers (``120`` becoming ``120.0``). Instead the edit is applied to the file
itself: the document the file opened as (``before``) is compared with the one the page
saves (``after``), and only the differences are written into the file's round-trip
tree (ruamel.yaml keeps comments, key order, quoting and flow style):

- a key whose value did not change keeps its node, spelling and comment;
- a changed scalar is replaced in place; a changed mapping is merged key by key;
- the waypoint list is aligned (:class:`difflib.SequenceMatcher`) so that inserting,
  deleting or moving one waypoint leaves the others, and their end-of-line comments,
  as they were; a new waypoint takes the style of its neighbours.

The caller checks that the merged text reads as the mission the page meant and falls
back to the mission writer if it does not (:func:`merged_mission_text` returns None
when the file cannot be merged at all).
"""

from __future__ import annotations

import difflib
import io
import itertools
import json
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import YAMLError
from ruamel.yaml.util import load_yaml_guess_indent


def merged_mission_text(original: str, before: dict[str, Any], after: dict[str, Any]) -> str | None:
    """``original`` (a navseq YAML mission's text) with the changes from ``before`` to
    ``after`` applied, or None when it is not a mapping ruamel.yaml can round-trip."""
    try:
        tree, sequence_indent, offset = load_yaml_guess_indent(original)
    except (YAMLError, ValueError, RecursionError):
        return None
    if not isinstance(tree, CommentedMap):
        return None
    yaml = YAML(typ="rt")
    yaml.preserve_quotes = True
    yaml.width = 4096  # a waypoint stays on its line, as mission files write them
    # ruamel guesses the sequences' indent ("  - " is 4 with the dash at 2); a mapping's
    # is read from the file.
    offset = offset or 0
    yaml.indent(
        mapping=_mapping_indent(original),
        sequence=max(sequence_indent or 2, offset + 2),
        offset=offset,
    )
    yaml.representer.add_representer(type(None), _null)  # "null", not an empty value
    _merge_mapping(tree, before, after)
    out = io.StringIO()
    yaml.dump(tree, out)
    return out.getvalue()


def _mapping_indent(text: str) -> int:
    """The indent of the first block mapping nested in another (2 when there is none)."""
    lines = [
        line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")
    ]
    for line, following in itertools.pairwise(lines):
        if line.split(" #", 1)[0].rstrip().endswith(":") and not following.lstrip().startswith("-"):
            step = (len(following) - len(following.lstrip())) - (len(line) - len(line.lstrip()))
            if step > 0:
                return step
    return 2


def _null(representer: Any, _: None) -> Any:
    return representer.represent_scalar("tag:yaml.org,2002:null", "null")


def _merge_mapping(node: CommentedMap, before: dict[str, Any], after: dict[str, Any]) -> None:
    for key in [key for key in before if key not in after]:
        if key in node:
            del node[key]
    for key, value in after.items():
        # Unchanged: kept as the file has it, or left out if the file leaves it out (a
        # default the document spells out).
        if key in before and _same(before[key], value):
            continue
        old = node.get(key)
        was = before.get(key)
        if isinstance(old, CommentedMap) and isinstance(was, dict) and isinstance(value, dict):
            _merge_mapping(old, was, value)
        elif isinstance(old, CommentedSeq) and isinstance(was, list) and isinstance(value, list):
            _merge_sequence(old, was, value)
        else:
            node[key] = _fresh(value, like=old)


def _merge_sequence(node: CommentedSeq, before: list[Any], after: list[Any]) -> None:
    if len(node) != len(before):  # the file's items are not the document's: start over
        node[:] = [_fresh(value, like=None) for value in after]
        return
    matcher = difflib.SequenceMatcher(
        None, [_key(item) for item in before], [_key(item) for item in after], autojunk=False
    )
    items: list[Any] = []
    comments: dict[int, Any] = {}
    neighbour = next((item for item in node if isinstance(item, CommentedMap)), None)
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag == "equal":
            for old_index in range(i1, i2):
                _keep(node, old_index, len(items), comments)
                items.append(node[old_index])
            continue
        if tag == "replace" and i2 - i1 == j2 - j1:
            # Edited in place (a waypoint dragged, a field typed): merged, comment kept.
            for old_index, new_index in zip(range(i1, i2), range(j1, j2), strict=True):
                old = node[old_index]
                if isinstance(old, CommentedMap) and isinstance(before[old_index], dict):
                    _merge_mapping(old, before[old_index], after[new_index])
                    _keep(node, old_index, len(items), comments)
                    items.append(old)
                else:
                    items.append(_fresh(after[new_index], like=neighbour))
            continue
        items += [_fresh(value, like=neighbour) for value in after[j1:j2]]
    node.ca.items.clear()
    node[:] = items
    node.ca.items.update(comments)


def _keep(node: CommentedSeq, old_index: int, new_index: int, comments: dict[int, Any]) -> None:
    """Carry the end-of-line comment of item ``old_index`` to its new place."""
    comment = node.ca.items.get(old_index)
    if comment is not None:
        comments[new_index] = comment


def _fresh(value: Any, like: Any) -> Any:
    """``value`` as a new node, in the style of ``like`` (a flow mapping stays flow)."""
    if isinstance(value, dict):
        fresh = CommentedMap((key, _fresh(item, like=None)) for key, item in value.items())
        if isinstance(like, CommentedMap | CommentedSeq) and like.fa.flow_style():
            fresh.fa.set_flow_style()
        elif like is None and len(value) <= 4 and _scalars(value.values()):
            fresh.fa.set_flow_style()  # a pose and the like: one line, as the writer has it
        return fresh
    if isinstance(value, list):
        seq = CommentedSeq(_fresh(item, like=None) for item in value)
        if all(not isinstance(item, list) and _pair_or_scalar(item) for item in value):
            # One line, as files write them: tasks: [wait: 5], recovery: [spin: 90, ...]
            seq.fa.set_flow_style()
        return seq
    return value


def _scalars(values: Any) -> bool:
    return all(not isinstance(item, dict | list) for item in values)


def _pair_or_scalar(item: Any) -> bool:
    """A scalar, or a mapping of one key to a scalar (a recovery such as ``spin: 90``)."""
    return not isinstance(item, dict) or (len(item) == 1 and _scalars(item.values()))


def _same(a: Any, b: Any) -> bool:
    """Equal as the document means it (``120`` and ``120.0`` are the same number)."""
    return _key(a) == _key(b)


def _key(value: Any) -> str:
    return json.dumps(_normal(value), sort_keys=True, default=str)


def _normal(value: Any) -> Any:
    if isinstance(value, bool):
        return value
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, dict):
        return {key: _normal(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_normal(item) for item in value]
    return value
