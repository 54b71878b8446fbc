"""Missions in a roslaunch file, the way the tutorial writes them::

    <launch>
      <node pkg="simple_navigation_goals" type="move_base_seq.py" name="move_base_seq">
        <rosparam param="p_seq">[-1,-4,0,1,-4,0,1,-1,0]</rosparam>
        <rosparam param="yea_seq">[90,0,180]</rosparam>
      </node>
    </launch>

The file is read with expat (line numbers for every element; DTDs and entity
declarations refused, so no entity expansion attacks). The parameters that
``<param>`` and ``<rosparam>`` set (in ``<group>``s and ``<node>``s, with namespaces
resolved like roslaunch does) form a parameter tree; the mission is then read from
it like from a rosparam file. Substitution args (``$(arg x)``, ``$(find pkg)``)
cannot be resolved without ROS and are reported where they matter.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from navseq.errors import NavseqError
from navseq.mission.located import MAX_DEPTH, Located
from navseq.mission.model import Mission
from navseq.mission.problems import Problems
from navseq.mission.reading import read_mission_text
from navseq.mission.rosparam_format import mission_from_tree
from navseq.mission.yaml_doc import parse_yaml, parse_yaml_value


@dataclass
class _Element:
    tag: str
    attrs: dict[str, str]
    line: int
    children: list[_Element] = field(default_factory=list)
    text: list[str] = field(default_factory=list)
    text_line: int | None = None  # file line of the first character of the body


def mission_from_launch(text: str, source: str, base_dir: Path | None,
                        problems: Problems) -> Mission | None:
    root = parse_xml(text, source)
    if root.tag != "launch":
        problems.add(f"is XML but not a roslaunch file: its root element is <{root.tag}>, "
                     "expected <launch>", source=f"{source}:{root.line}")
        return None
    reader = _LaunchReader(source, base_dir, problems)
    before = len(problems)
    reader.walk(root, "/", None)
    if len(problems) > before:  # a broken <rosparam> body; what it set is unknown
        return None
    return mission_from_tree(reader.tree.located(), source, base_dir, problems,
                             not_followed=reader.not_followed)


def parse_xml(text: str, source: str) -> _Element:
    """The element tree of an XML document, each element with its line number."""
    parser = expat.ParserCreate()
    stack: list[_Element] = []
    roots: list[_Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        element = _Element(tag, attrs, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)
        if len(stack) > MAX_DEPTH:
            raise NavseqError(f"nests elements more than {MAX_DEPTH} deep",
                              source=f"{source}:{parser.CurrentLineNumber}")

    def end(tag: str) -> None:
        stack.pop()

    def characters(data: str) -> None:
        if stack:
            if stack[-1].text_line is None:
                stack[-1].text_line = parser.CurrentLineNumber
            stack[-1].text.append(data)

    def refuse_dtd(*args: object) -> None:
        raise NavseqError("declares a DTD or entities; launch files have no use for them and "
                          "navseq does not expand them",
                          source=f"{source}:{parser.CurrentLineNumber}")

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = characters
    parser.StartDoctypeDeclHandler = refuse_dtd
    parser.EntityDeclHandler = refuse_dtd
    try:
        parser.Parse(text, True)
    except expat.ExpatError as error:
        message = expat.errors.messages[error.code]
        raise NavseqError(f"is not well-formed XML: {message}",
                          source=f"{source}:{error.lineno}") from None
    if not roots:
        raise NavseqError("has no XML element", source=source)
    return roots[0]


class _ParamTree:
    """The parameter server's view: nested namespaces; later settings win, like roslaunch."""

    def __init__(self, where: str):
        self.where = where
        self.entries: dict[str, Located | _ParamTree] = {}

    def set(self, path: list[str], value: Located) -> None:
        if not path:  # a mapping loaded into this namespace itself
            if value.is_mapping:
                for key, child in value.value.items():
                    self.set([key], child)
            return
        head, rest = path[0], path[1:]
        if not rest and not value.is_mapping:
            self.entries[head] = value
            return
        child = self.entries.get(head)
        if not isinstance(child, _ParamTree):
            child = self.entries[head] = _ParamTree(value.where)
        child.set(rest, value)

    def located(self) -> Located:
        values = {key: entry.located() if isinstance(entry, _ParamTree) else entry
                  for key, entry in self.entries.items()}
        return Located(values, self.where, {key: v.where for key, v in values.items()})


def _resolve(name: str, namespace: str, private: str | None) -> str:
    """A parameter's full name, as roslaunch resolves it inside groups and nodes."""
    if name.startswith("/"):
        return name
    if name.startswith("~"):
        return f"{(private or namespace).rstrip('/')}/{name[1:]}"
    return f"{(private or namespace).rstrip('/')}/{name}"


def _parts(name: str) -> list[str]:
    return [part for part in name.split("/") if part]


class _LaunchReader:
    """Walks <launch> collecting what <param> and <rosparam> set."""

    def __init__(self, source: str, base_dir: Path | None, problems: Problems):
        self.source = source
        self.base_dir = base_dir
        self.problems = problems
        self.tree = _ParamTree(f"{source}:1")
        self.not_followed: list[str] = []

    def where(self, element: _Element) -> str:
        return f"{self.source}:{element.line}"

    def walk(self, element: _Element, namespace: str, private: str | None) -> None:
        for child in element.children:
            if not _condition_holds(child):
                continue
            if child.tag == "group":
                inner = _resolve(child.attrs.get("ns", ""), namespace, None)
                self.walk(child, inner, None)
            elif child.tag == "node":
                node_namespace = _resolve(child.attrs.get("ns", ""), namespace, None)
                node_name = _resolve(child.attrs.get("name", ""), node_namespace, None)
                self.walk(child, node_namespace, node_name)
            elif child.tag == "param":
                self.param(child, namespace, private)
            elif child.tag == "rosparam":
                self.rosparam(child, namespace, private)
            elif child.tag == "include":
                self.not_followed.append(child.attrs.get("file", "<include>"))

    def param(self, element: _Element, namespace: str, private: str | None) -> None:
        name = element.attrs.get("name")
        value = element.attrs.get("value")
        if not name or value is None:  # textfile=, binfile=, command= need ROS
            return
        where = self.where(element)
        located = Located(value, where)
        if element.attrs.get("type", "auto") not in ("str", "string"):
            try:
                parsed = parse_yaml_value(value, self.source, first_line=element.line)
            except NavseqError:
                parsed = None  # plain text, as roslaunch would keep it
            if parsed is not None:
                located = parsed
        self.tree.set(_parts(_resolve(name, namespace, private)), located)

    def rosparam(self, element: _Element, namespace: str, private: str | None) -> None:
        if element.attrs.get("command", "load") != "load":
            return
        target = _resolve(element.attrs.get("ns", ""), namespace, private)
        param = element.attrs.get("param")
        if param:
            target = _resolve(param, target, None)
        value = self.rosparam_value(element)
        if value is not None:
            self.tree.set(_parts(target), value)

    def rosparam_value(self, element: _Element) -> Located | None:
        file_name = element.attrs.get("file")
        if file_name is not None:
            return self.rosparam_file(file_name)
        body = "".join(element.text)
        try:
            return parse_yaml(body, self.source, self.problems,
                              first_line=element.text_line or element.line)
        except NavseqError as error:
            self.problems.record(error)
            return None

    def rosparam_file(self, file_name: str) -> Located | None:
        if "$(" in file_name:
            self.not_followed.append(file_name)
            return None
        path = Path(file_name)
        if not path.is_absolute() and self.base_dir is not None:
            path = self.base_dir / path
        try:
            return parse_yaml(read_mission_text(path), str(path), self.problems)
        except NavseqError:
            self.not_followed.append(file_name)
            return None


def _condition_holds(element: _Element) -> bool:
    """roslaunch's if=/unless=; a substitution it cannot evaluate counts as true."""
    truthy, falsy = ("true", "1"), ("false", "0")
    condition = element.attrs.get("if")
    if condition is not None and condition.strip().lower() in falsy:
        return False
    condition = element.attrs.get("unless")
    return not (condition is not None and condition.strip().lower() in truthy)
