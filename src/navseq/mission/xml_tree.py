"""XML documents as a small element tree that remembers each element's line.

Read with expat, which gives line numbers for every element; DTDs and entity
declarations are refused, so no entity-expansion attack can get through. Used for
roslaunch files and for the ``package.xml`` files that ``$(find)`` looks at.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from xml.parsers import expat

from navseq.errors import NavseqError
from navseq.mission.located import MAX_DEPTH


@dataclass
class XmlElement:
    """One element: tag, attributes, its line, children and body text."""

    tag: str
    attrs: dict[str, str]
    line: int
    children: list[XmlElement] = field(default_factory=list)
    text: list[str] = field(default_factory=list)
    text_line: int | None = None  # file line of the first character of the body

    def child(self, tag: str) -> XmlElement | None:
        """The first child element with this tag, if any."""
        return next((child for child in self.children if child.tag == tag), None)

    @property
    def body(self) -> str:
        return "".join(self.text)


def parse_xml(text: str, source: str) -> XmlElement:
    """The element tree of an XML document, each element with its line number."""
    parser = expat.ParserCreate()
    stack: list[XmlElement] = []
    roots: list[XmlElement] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        element = XmlElement(tag, attrs, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)
        if len(stack) > MAX_DEPTH:
            raise NavseqError(
                f"nests elements more than {MAX_DEPTH} deep",
                source=f"{source}:{parser.CurrentLineNumber}",
            )

    def end(tag: str) -> None:
        stack.pop()

    def characters(data: str) -> None:
        if stack:
            if stack[-1].text_line is None:
                stack[-1].text_line = parser.CurrentLineNumber
            stack[-1].text.append(data)

    def refuse_dtd(*args: object) -> None:
        raise NavseqError(
            "declares a DTD or entities; navseq's XML files have no use for them and "
            "navseq does not expand them",
            source=f"{source}:{parser.CurrentLineNumber}",
        )

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = characters
    parser.StartDoctypeDeclHandler = refuse_dtd
    parser.EntityDeclHandler = refuse_dtd
    try:
        parser.Parse(text, True)
    except expat.ExpatError as error:
        message = expat.errors.messages[error.code]
        raise NavseqError(
            f"is not well-formed XML: {message}", source=f"{source}:{error.lineno}"
        ) from None
    if not roots:
        raise NavseqError("has no XML element", source=source)
    return roots[0]
