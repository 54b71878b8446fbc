"""One entry point for every mission file format.

The format is chosen by the file's extension and, where that is not conclusive, by
its content:

- ``.yaml`` / ``.yml``: navseq's mission format, or a rosparam file with the
  tutorial's ``p_seq`` / ``yea_seq`` (at the top or under a node's name);
- ``.launch`` / ``.xml``: a roslaunch file setting those parameters;
- ``.csv``: poses recorded as ``x,y,z,qx,qy,qz,qw``;
- anything else: sniffed (XML, YAML mapping, or comma-separated numbers).
"""

from __future__ import annotations

import contextlib
import gc
import os
import re
from collections.abc import Callable, Collection, Iterator, Mapping
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.mission.csv_format import mission_from_csv
from navseq.mission.launch_xml import mission_from_launch
from navseq.mission.located import Located, from_plain
from navseq.mission.model import Mission
from navseq.mission.nav2_waypoints_format import echoed_message, nav2_reader_for
from navseq.mission.navseq_format import mission_from_document
from navseq.mission.params import mission_from_namespace
from navseq.mission.problems import Problems
from navseq.mission.reading import read_mission_text
from navseq.mission.rosparam_format import find_mission_namespaces, mission_from_tree
from navseq.mission.yaml_doc import parse_yaml

Reader = Callable[[str, str, Path, Problems], "Mission | None"]

# Linear in the line: each repeat is followed by a character it cannot match (numbers
# by spaces or ",", spaces by what is not a space), so backtracking gives back one
# character at a time and fails at once (no possessive quantifiers: Python 3.10).
_CSV_LINE = re.compile(r"\s*[-+0-9.eE]+(?:\s*,\s*[-+0-9.eE]+)+\s*")
_NAVSEQ_KEYS = ("waypoints", "navseq")
SUPPORTED = (
    "navseq YAML or rosparam YAML (.yaml, .yml), roslaunch XML (.launch, .xml), "
    "CSV x,y,z,qx,qy,qz,qw (.csv), Nav2's RViz panel waypoint file and a PoseArray or "
    "nav_msgs/Path as ros2 topic echo prints it (YAML)"
)


def load_mission(path: str | os.PathLike[str]) -> Mission:
    """Read a mission file of any supported format.

    Raises NavseqError for one problem and MissionErrors (a NavseqError listing
    them all) for several.
    """
    mission, problems = _load(Path(path))
    problems.raise_if_any()
    assert mission is not None, "a loader returned no mission without saying why"
    return mission


def mission_from_params(
    params: Mapping[str, Any], source: str = "param ~", *, ignore: Collection[str] = ()
) -> Mission:
    """The mission a ROS node's private parameters describe.

    ``params`` is the node's private namespace as a dict (``rospy.get_param("~")``);
    ``source`` prefixes parameter names in messages (``param ~p_seq``). Keys in
    ``ignore`` belong to the node itself (``action_name``...) and are not checked;
    any other unknown key is an error naming the closest known one. Raises
    NavseqError, or MissionErrors when there are several problems.
    """
    values = {
        str(key): from_plain(value, f"{source}{key}")
        for key, value in params.items()
        if str(key) not in ignore
    }
    namespace = Located(
        values, source.rstrip() or "params", {key: node.where for key, node in values.items()}
    )
    problems = Problems()
    mission = mission_from_namespace(
        namespace, problems, base_dir=None, strict=True, open_mission=load_mission
    )
    problems.raise_if_any()
    assert mission is not None
    return mission


def validate_mission_file(path: str | os.PathLike[str]) -> list[NavseqError]:
    """Every problem of a mission file, at once; an empty list means it loads."""
    return _load(Path(path))[1].errors


def inspect_mission_file(path: str | os.PathLike[str]) -> tuple[Mission | None, Problems]:
    """The mission (None when it has problems) and every problem of a mission file.

    When there are problems, ``Problems.salvage`` holds the waypoints that still
    read well (navseq YAML only), so that they can be checked against the map too.
    """
    return _load(Path(path))


def _load(path: Path) -> tuple[Mission | None, Problems]:
    problems = Problems()
    source = str(path)
    mission = None
    try:
        text = read_mission_text(path)
        reader = _reader_for(path, text)
        with _collector_paused():
            mission = reader(text, source, path.resolve().parent, problems)
    except NavseqError as error:
        problems.record(error)
    except RecursionError:
        problems.add("is nested too deeply to be a mission", source=source)
    if mission is None and not problems.errors:
        problems.add("holds no mission", source=source)
    problems.errors.sort(key=_line_number)  # read like the file, top to bottom
    return (mission if not problems.errors else None), problems


@contextlib.contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while a mission is read.

    Reading a mission builds a few small objects per value, none of them in a
    reference cycle, so the collector finds nothing; but it walked every live one
    again each time a few hundred more had been made: 45 % of the time 100 000
    waypoints took to load. Reference counting still frees them.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _line_number(error: NavseqError) -> int:
    """The line an error points at (``file:12``), 0 when it names the whole file."""
    _, _, line = (error.source or "").rpartition(":")
    return int(line) if line.isdigit() else 0


def _reader_for(path: Path, text: str) -> Reader:
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml"):
        return _read_yaml
    if suffix in (".launch", ".xml"):
        return _read_launch
    if suffix == ".csv":
        return _read_csv
    return _sniff(path, text)


def _sniff(path: Path, text: str) -> Reader:
    """Guess the format of a file whose extension says nothing."""
    stripped = text.lstrip()
    if stripped.startswith("<"):
        return _read_launch
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    if lines and all(_CSV_LINE.fullmatch(line) for line in lines[1:] or lines):
        return _read_csv
    try:
        doc = echoed_message(text, str(path), Problems()) or parse_yaml(text, str(path), Problems())
    except NavseqError:
        doc = None
    if doc is not None and doc.is_mapping:
        return _read_yaml
    raise NavseqError(
        f"is not a mission file navseq can read; it reads {SUPPORTED}", source=str(path)
    )


def _read_yaml(text: str, source: str, base_dir: Path, problems: Problems) -> Mission | None:
    # ``ros2 topic echo`` separates messages by ``---``: its last message is read.
    doc = echoed_message(text, source, problems) or parse_yaml(text, source, problems)
    nav2_reader = nav2_reader_for(doc)
    if nav2_reader is not None:
        assert doc is not None
        return nav2_reader(doc, source, problems)
    if _is_rosparam_tree(doc):
        assert doc is not None
        return mission_from_tree(doc, source, base_dir, problems, open_mission=load_mission)
    return mission_from_document(doc, source, base_dir, problems)


def mission_from_yaml_text(text: str, source: str, base_dir: Path) -> Mission | None:
    """The mission a YAML text (navseq or rosparam) holds, None when it has problems;
    relative paths in it are relative to ``base_dir``, as for a file there."""
    return _read_yaml(text, source, base_dir, Problems())


def is_navseq_document(doc: Located) -> bool:
    """Whether a parsed YAML document is a mission in navseq's own format (not a ROS
    parameter tree, not another kind of YAML)."""
    if not doc.is_mapping or _is_rosparam_tree(doc):
        return False
    return any(key in doc.value for key in _NAVSEQ_KEYS)


def _is_rosparam_tree(doc: Located | None) -> bool:
    """A mapping without navseq's own top-level keys, giving p_seq/yea_seq somewhere.

    A ROS 2 params file for the node named ``navseq`` (``navseq: {ros__parameters:
    {p_seq: ...}}``) is a parameter tree too: its ``navseq`` key is a node's name, not
    the format version of a navseq mission.
    """
    if doc is None or not doc.is_mapping:
        return False
    own_keys = [key for key in doc.value if key in _NAVSEQ_KEYS]
    if own_keys != [] and not (
        own_keys == ["navseq"] and _is_ros2_node_section(doc.value["navseq"])
    ):
        return False
    return bool(find_mission_namespaces(doc))


def _is_ros2_node_section(node: Located) -> bool:
    return node.is_mapping and "ros__parameters" in node.value


def _read_launch(text: str, source: str, base_dir: Path, problems: Problems) -> Mission | None:
    return mission_from_launch(text, source, base_dir, problems, open_mission=load_mission)


def _read_csv(text: str, source: str, base_dir: Path, problems: Problems) -> Mission | None:
    return mission_from_csv(text, source, problems)
