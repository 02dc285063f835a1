"""Safe XML for URDF and MJCF: expat with DOCTYPE and ENTITY declarations refused (no external
entities, no expansion bombs), building an ``xml.etree`` tree and keeping each element's line."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from xml.parsers import expat

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error


class XmlDocument:
    """The parsed root plus ``line(element)`` for diagnostics."""

    def __init__(self, root: ET.Element, lines: dict[int, int], path: Path | None):
        self.root = root
        self._lines = lines
        self.path = path

    def line(self, element: ET.Element) -> int | None:
        return self._lines.get(id(element))

    def where(self, element: ET.Element) -> SourceLocation:
        return SourceLocation(str(self.path) if self.path else "<xml>", self.line(element))


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
    keep: list[ET.Element] = []  # ids stay valid while the elements live

    def start(tag, attrs):
        el = builder.start(tag, attrs)
        keep.append(el)
        lines[id(el)] = parser.CurrentLineNumber

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
        raise AdfError(error("xml-unsafe", "DOCTYPE or ENTITY declarations are not accepted",
                             SourceLocation(where, parser.CurrentLineNumber),
                             "URDF and MJCF need no DTD; remove the <!DOCTYPE ...> block")) from None
    except expat.ExpatError as exc:
        raise AdfError(error("xml-syntax", f"not well-formed XML: {expat.ErrorString(exc.code)}",
                             SourceLocation(where, exc.lineno, exc.offset + 1),
                             "fix the XML syntax at that position")) from None
    root = builder.close()
    return XmlDocument(root, lines, Path(path) if path is not None else None)
