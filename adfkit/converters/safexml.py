"""Safe XML for URDF and MJCF: expat with DOCTYPE and ENTITY declarations refused (no external
entities, no expansion bombs), building an ``xml.etree`` tree and keeping each element's line."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from xml.parsers import expat

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error


class XmlDocument:
    """The parsed root plus ``line(element)`` and ``where(element)`` (line and column of the
    element's start tag, both 1-based) for diagnostics."""

    def __init__(
        self,
        root: ET.Element,
        lines: dict[int, tuple[int, int]],
        path: Path | None,
        keep: list[ET.Element] | None = None,
    ):
        self.root = root
        self._lines = lines
        self.path = path
        self._keep = keep if keep is not None else []  # ids stay valid while the elements live

    def line(self, element: ET.Element) -> int:
        return self._lines.get(id(element), (1, 1))[0]

    def column(self, element: ET.Element) -> int:
        return self._lines.get(id(element), (1, 1))[1]

    def where(self, element: ET.Element | None = None) -> SourceLocation:
        """The element's start tag; an element not from this document (or None): the root's."""
        if element is None or id(element) not in self._lines:
            element = self.root
        line, col = self._lines.get(id(element), (1, 1))
        return SourceLocation(str(self.path) if self.path else "<xml>", line, col)

    def elements(self) -> list[ET.Element]:
        """Every element in document order."""
        return list(self._keep)

    def at_line(self, line: int) -> ET.Element | None:
        """The first element whose start tag is on ``line`` (or the last one before it)."""
        best = None
        for el in self._keep:
            ln = self._lines[id(el)][0]
            if ln > line:
                break
            best = el
        return best


class _Refused(Exception):
    pass


def parse_xml(path: str | Path | None = None, text: str | bytes | None = None) -> XmlDocument:
    """Parse a file (or ``text``); raise ``AdfError`` (rule ``xml-unsafe``/``xml-syntax``/
    ``file-unreadable``) with the line, never an expat or OS exception."""
    where = str(path) if path is not None else "<xml>"
    if text is None:
        text = inputs.read_bytes(path, "xml", what="XML file")  # regular file, size cap (adfkit.inputs)
    builder = ET.TreeBuilder()
    lines: dict[int, int] = {}
    parser = expat.ParserCreate()
    keep: list[ET.Element] = []  # document order; ids stay valid while the elements live

    def start(tag, attrs):
        el = builder.start(tag, attrs)
        keep.append(el)
        lines[id(el)] = (parser.CurrentLineNumber, parser.CurrentColumnNumber + 1)

    def refuse(*_args):
        raise _Refused()

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    parser.StartDoctypeDeclHandler = refuse
    parser.EntityDeclHandler = refuse
    parser.ExternalEntityRefHandler = refuse
    try:
        parser.Parse(text, True)
    except _Refused:
        raise AdfError(
            error(
                "xml-unsafe",
                "DOCTYPE or ENTITY declarations are not accepted",
                SourceLocation(where, parser.CurrentLineNumber, parser.CurrentColumnNumber + 1),
                "URDF and MJCF need no DTD; remove the <!DOCTYPE ...> block",
            )
        ) from None
    except expat.ExpatError as exc:
        raise AdfError(
            error(
                "xml-syntax",
                f"not well-formed XML: {expat.ErrorString(exc.code)}",
                SourceLocation(where, exc.lineno, exc.offset + 1),
                "fix the XML syntax at that position",
            )
        ) from None
    root = builder.close()
    return XmlDocument(root, lines, Path(path) if path is not None else None, keep)


def _escape(text: str, attribute: bool) -> str:
    text = text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    if attribute:
        text = text.replace('"', "&quot;").replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#09;")
    return text


def to_text(root: ET.Element, indent: str = "  ") -> str:
    """``root`` as indented XML text, one element per line, with an explicit stack: a chain of
    thousands of nested bodies needs no recursion (``ET.indent``/``ET.tostring`` recurse once
    per level). Element text is kept; tails (whitespace between elements) are not."""
    out: list[str] = []
    stack: list[tuple[ET.Element, int, bool]] = [(root, 0, False)]
    while stack:
        el, depth, closing = stack.pop()
        pad = indent * depth
        if closing:
            out.append(f"{pad}</{el.tag}>")
            continue
        attrs = "".join(f' {k}="{_escape(str(v), True)}"' for k, v in el.attrib.items())
        text = el.text if el.text and el.text.strip() else ""
        kids = list(el)
        if not kids and not text:
            out.append(f"{pad}<{el.tag}{attrs} />")
        elif not kids:
            out.append(f"{pad}<{el.tag}{attrs}>{_escape(text, False)}</{el.tag}>")
        else:
            out.append(f"{pad}<{el.tag}{attrs}>{_escape(text, False)}")
            stack.append((el, depth, True))
            stack.extend((kid, depth + 1, False) for kid in reversed(kids))
    return "\n".join(out)
