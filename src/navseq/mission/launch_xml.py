"""Missions in a roslaunch file, the way the tutorial writes them::

    <launch>
      <node pkg="simple_navigation_goals" type="move_base_seq.py" name="move_base_seq">
        <rosparam param="p_seq">[-1,-4,0,1,-4,0,1,-1,0]</rosparam>
        <rosparam param="yea_seq">[90,0,180]</rosparam>
      </node>
    </launch>

The file is read by :mod:`xml_tree` (line numbers for every element; DTDs and entity
declarations refused, so no entity expansion attacks). The parameters that
``<param>`` and ``<rosparam>`` set (in ``<group>``s, ``<node>``s and ``<include>``d
files, with namespaces resolved like roslaunch does) form a parameter tree; the
mission is then read from it like from a rosparam file.

Like roslaunch, the reader declares ``<arg>``s per file in document order, honours
``if=``/``unless=``, and resolves substitution args (see :mod:`launch_subst`) in
attributes and, with ``subst_value="true"``, in ``<rosparam>`` bodies and files.
``<include>`` is followed (a relative path is relative to the including file, which
roslaunch does not allow), with its ``ns=`` and the args it passes; cycles and
runaway nesting are refused. What stays unresolved (``$(eval)``, ``$(anon)``, a
package not on ``ROS_PACKAGE_PATH``) is reported where it matters, and the files it
kept navseq from reading are named when no mission is found.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from navseq.errors import NavseqError
from navseq.mission.launch_subst import (
    ExpansionBudget,
    ExpansionLimitError,
    LaunchArgs,
    PackageFinder,
    Substitution,
    SubstitutionError,
)
from navseq.mission.located import MAX_DEPTH, Located
from navseq.mission.model import Mission
from navseq.mission.params import OpenMission
from navseq.mission.problems import Problems
from navseq.mission.reading import MAX_MISSION_BYTES, read_mission_text
from navseq.mission.rosparam_format import mission_from_tree
from navseq.mission.xml_tree import XmlElement, parse_xml
from navseq.mission.yaml_doc import (
    NumberTooLongError,
    TooManyValuesError,
    ValueBudget,
    parse_yaml,
    parse_yaml_value,
)
from navseq.text import printable

# Real launch trees are a few includes deep; these bound a file that includes others
# many times over (each of which includes more), not just cycles.
MAX_INCLUDE_DEPTH = 16
MAX_INCLUDED_FILES = 200
# ... and the text of all of them together (each file alone may hold MAX_MISSION_BYTES).
MAX_LAUNCH_TREE_BYTES = 2 * MAX_MISSION_BYTES


def mission_from_launch(
    text: str,
    source: str,
    base_dir: Path | None,
    problems: Problems,
    *,
    open_mission: OpenMission,
) -> Mission | None:
    """The mission a launch file sets; ``open_mission`` reads a file a ``mission``
    parameter names."""
    root = parse_xml(text, source)
    if root.tag != "launch":
        problems.add(
            f"is XML but not a roslaunch file: its root element is <{root.tag}>, expected <launch>",
            source=f"{source}:{root.line}",
        )
        return None
    reader = _LaunchReader(source, base_dir, problems)
    reader.bytes_read = len(text)
    before = len(problems)
    reader.walk(root, "/", None, reader.top)
    if len(problems) > before:  # e.g. a broken <rosparam> body: what it set is unknown
        return None
    return mission_from_tree(
        reader.tree.located(),
        source,
        base_dir,
        problems,
        open_mission=open_mission,
        not_followed=reader.not_followed,
    )


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
        values = {
            key: entry.located() if isinstance(entry, _ParamTree) else entry
            for key, entry in self.entries.items()
        }
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


@dataclass
class _File:
    """One launch file being read: how messages name it, and its substitution args."""

    source: str
    subst: Substitution

    def where(self, line: int) -> str:
        return f"{self.source}:{line}"


class _LaunchReader:
    """Walks <launch>, and the files it includes, collecting what <param> and <rosparam> set."""

    def __init__(self, source: str, base_dir: Path | None, problems: Problems):
        self.problems = problems
        self.packages = PackageFinder()
        self.tree = _ParamTree(f"{source}:1")
        self.not_followed: list[str] = []
        self.budget = ExpansionBudget()
        self.values = ValueBudget()  # the YAML values of every param and file together
        self.top = _File(source, Substitution(LaunchArgs(), base_dir, self.packages, self.budget))
        self.reading = [_file_key(Path(source))]  # the chain of includes, to refuse cycles
        self.files_read = 1
        self.bytes_read = 0

    def walk(
        self, element: XmlElement, namespace: str, private: str | None, file: _File, depth: int = 0
    ) -> None:
        if depth > MAX_DEPTH:
            self.problems.add(
                f"nests groups, nodes and includes more than {MAX_DEPTH} deep",
                source=file.where(element.line),
            )
            return
        for child in element.children:
            try:
                self.visit(child, namespace, private, file, depth)
            except SubstitutionError as error:
                self.problems.add(error.message, source=file.where(child.line))
            except ExpansionLimitError as error:
                # Fatal: going on would only hit the limit again, element after element.
                raise NavseqError(error.message, source=file.where(child.line)) from None

    def visit(
        self, element: XmlElement, namespace: str, private: str | None, file: _File, depth: int
    ) -> None:
        if not self.condition_holds(element, file):
            return
        if element.tag == "arg":
            self.arg(element, file)
        elif element.tag == "group":
            inner = _resolve(self.attr(element, "ns", file) or "", namespace, None)
            self.walk(element, inner, None, file, depth + 1)
        elif element.tag == "node":
            node_namespace = _resolve(self.attr(element, "ns", file) or "", namespace, None)
            node_name = _resolve(self.attr(element, "name", file) or "", node_namespace, None)
            self.walk(element, node_namespace, node_name, file, depth + 1)
        elif element.tag == "param":
            self.param(element, namespace, private, file)
        elif element.tag == "rosparam":
            self.rosparam(element, namespace, private, file)
        elif element.tag == "include":
            self.include(element, namespace, file, depth)

    @staticmethod
    def attr(element: XmlElement, name: str, file: _File) -> str | None:
        value = element.attrs.get(name)
        return None if value is None else file.subst.resolve(value)

    def condition_holds(self, element: XmlElement, file: _File) -> bool:
        """roslaunch's if=/unless=; a substitution navseq cannot evaluate counts as true."""
        for key, keep_when in (("if", True), ("unless", False)):
            value = self.attr(element, key, file)
            if value is None or "$(" in value:
                continue
            truth = _boolean(value)
            if truth is None:
                raise SubstitutionError(
                    f'{key}="{value}" is neither true nor false '
                    "(roslaunch accepts true, false, 1 and 0)"
                )
            if truth != keep_when:
                return False
        return True

    def arg(self, element: XmlElement, file: _File) -> None:
        name = self.attr(element, "name", file)
        if not name:
            self.problems.add("<arg> needs a name=", source=file.where(element.line))
            return
        file.subst.args.declare(
            name,
            value=self.attr(element, "value", file),
            default=self.attr(element, "default", file),
        )

    def param(self, element: XmlElement, namespace: str, private: str | None, file: _File) -> None:
        name = self.attr(element, "name", file)
        value = self.attr(element, "value", file)
        if not name or value is None:  # textfile=, binfile=, command= need ROS
            return
        where = file.where(element.line)
        located = Located(value, where)
        if element.attrs.get("type", "auto") not in ("str", "string"):
            try:
                parsed = parse_yaml_value(
                    value, file.source, first_line=element.line, budget=self.values
                )
            except TooManyValuesError:
                raise
            except NumberTooLongError as error:  # meant as a number: not kept as text
                raise NumberTooLongError(
                    error.message, source=error.source, subject=f"param {printable(name)}"
                ) from None
            except NavseqError:
                parsed = None  # plain text, as roslaunch would keep it
            if parsed is not None:
                located = parsed
        self.tree.set(_parts(_resolve(name, namespace, private)), located)

    def rosparam(
        self, element: XmlElement, namespace: str, private: str | None, file: _File
    ) -> None:
        if (self.attr(element, "command", file) or "load") != "load":
            return
        target = _resolve(self.attr(element, "ns", file) or "", namespace, private)
        param = self.attr(element, "param", file)
        if param:
            target = _resolve(param, target, None)
        value = self.rosparam_value(element, file)
        if value is not None:
            self.tree.set(_parts(target), value)

    def rosparam_value(self, element: XmlElement, file: _File) -> Located | None:
        # As in roslaunch, a body or loaded file is substituted only when asked to.
        substitute = _boolean(self.attr(element, "subst_value", file) or "false") is True
        file_name = self.attr(element, "file", file)
        if file_name is not None:
            return self.rosparam_file(file_name, file, substitute, element.line)
        body = element.body
        first_line = element.text_line or element.line
        if substitute:
            try:
                body = file.subst.resolve(body)
            except SubstitutionError as error:
                line = first_line + body[: error.offset].count("\n")
                self.problems.add(error.message, source=file.where(line))
                return None
        try:
            return parse_yaml(
                body, file.source, self.problems, first_line=first_line, budget=self.values
            )
        except TooManyValuesError:
            raise
        except NavseqError as error:
            self.problems.record(error)
            return None

    def rosparam_file(
        self, file_name: str, file: _File, substitute: bool, element_line: int
    ) -> Located | None:
        if "$(" in file_name:
            self.not_followed.append(file.subst.explain(file_name))
            return None
        path = self.path(file_name, file)
        try:
            text = read_mission_text(path)
        except NavseqError:
            self.not_followed.append(file_name)
            return None
        self.count_bytes(text, file.where(element_line))
        if substitute:
            try:
                text = file.subst.resolve(text)
            except SubstitutionError as error:
                line = 1 + text[: error.offset].count("\n")
                self.problems.add(error.message, source=f"{path}:{line}")
                return None
        try:
            return parse_yaml(text, str(path), self.problems, budget=self.values)
        except TooManyValuesError:
            raise
        except NavseqError:
            self.not_followed.append(file_name)
            return None

    def include(self, element: XmlElement, namespace: str, file: _File, depth: int) -> None:
        here = file.where(element.line)
        file_name = self.attr(element, "file", file)
        if not file_name:
            self.problems.add("<include> needs a file=", source=here)
            return
        inner = _resolve(self.attr(element, "ns", file) or "", namespace, None)
        passed = self.passed_args(element, file)
        if passed is None:
            return
        if "$(" in file_name:
            self.not_followed.append(file.subst.explain(file_name))
            return
        path = self.path(file_name, file)
        key = _file_key(path)
        if key in self.reading:
            chain = " -> ".join(str(p) for p in [*self.reading[self.reading.index(key) :], key])
            self.problems.add(
                f"includes {file_name}, which is already being read: an include cycle ({chain})",
                source=here,
            )
            return
        if len(self.reading) > MAX_INCLUDE_DEPTH or self.files_read >= MAX_INCLUDED_FILES:
            self.problems.add(
                f"includes {file_name} beyond navseq's limits ({MAX_INCLUDE_DEPTH}"
                f" includes deep, {MAX_INCLUDED_FILES} files in all)",
                source=here,
            )
            return
        try:
            text = read_mission_text(path)
            self.count_bytes(text, here)
            root = parse_xml(text, str(path))
        except NavseqError as error:
            if error.source == here:  # over the launch tree's size limit: stop reading
                raise
            if error.source == str(path):  # the file itself is missing or unreadable
                self.problems.add(
                    f"includes {file_name}, which navseq cannot read: {error.message} ({path})",
                    source=here,
                )
            else:
                self.problems.record(error)
            return
        if root.tag != "launch":
            self.problems.add(
                f"is included by {here} but is not a roslaunch file: its root "
                f"element is <{root.tag}>",
                source=f"{path}:{root.line}",
            )
            return
        self.files_read += 1
        included = _File(
            str(path), Substitution(LaunchArgs(passed), path.parent, self.packages, self.budget)
        )
        self.reading.append(key)
        try:
            self.walk(root, inner, None, included, depth + 1)
        finally:
            self.reading.pop()

    def count_bytes(self, text: str, where: str) -> None:
        """Refuse a launch tree whose files hold more text, all together, than navseq reads."""
        self.bytes_read += len(text)
        if self.bytes_read > MAX_LAUNCH_TREE_BYTES:
            raise NavseqError(
                f"the launch file and the files it includes hold more than "
                f"{MAX_LAUNCH_TREE_BYTES / 2**20:g} MiB of text together; "
                "navseq refuses to read on (a file included over and over?)",
                source=where,
            )

    def passed_args(self, element: XmlElement, file: _File) -> dict[str, str] | None:
        """The args an <include> gives the included file; None when one is wrong."""
        all_args = _boolean(self.attr(element, "pass_all_args", file) or "false")
        passed = file.subst.args.given() if all_args else {}
        for child in element.children:
            if child.tag != "arg":
                continue
            try:
                if not self.condition_holds(child, file):
                    continue
                name = self.attr(child, "name", file)
                value = self.attr(child, "value", file)
                if value is None:
                    value = self.attr(child, "default", file)
            except SubstitutionError as error:
                self.problems.add(error.message, source=file.where(child.line))
                return None
            if not name or value is None:
                self.problems.add(
                    "<arg> in an <include> needs name= and value=", source=file.where(child.line)
                )
                return None
            passed[name] = value
        return passed

    @staticmethod
    def path(file_name: str, file: _File) -> Path:
        """A path from a launch file; relative ones are relative to that file's folder."""
        path = Path(file_name)
        if not path.is_absolute() and file.subst.folder is not None:
            path = file.subst.folder / path
        return path


def _file_key(path: Path) -> Path:
    """The same file under any of its names, to recognise an include cycle."""
    try:
        return path.resolve()
    except (OSError, RuntimeError, ValueError):
        return path.absolute()


def _boolean(value: str) -> bool | None:
    text = value.strip().lower()
    return True if text in ("true", "1") else False if text in ("false", "0") else None
