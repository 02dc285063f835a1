"""The MJCF text MuJoCo compiles, and where its errors point.

MuJoCo's compiler follows ``<include file=...>`` wherever it points, with its own XML parser
(no DOCTYPE/ENTITY check). We resolve includes ourselves instead: each file is named relative
to the main model's folder, must lie inside that folder's tree (symlinks followed), is a
regular file under the XML size cap (``adfkit.inputs``) and is parsed by ``safexml``; its root
element's children replace the ``<include>``. MuJoCo then compiles the merged text, with the
compiler's mesh and texture folders made absolute, so it opens no XML file itself.

MuJoCo's messages name a line and sometimes an element (``Element 'geom', line 3`` or
``Element name 'a', id 1, line 3``), never a column, and a line of the text it was given.
:class:`Source` maps such a message back to a file, line and column of the user's files.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error
from .safexml import XmlDocument, parse_xml, to_text

#: Includes followed, in all, per model (a guard against include bombs).
MAX_INCLUDES = 256


class Source:
    """The document(s) of one MJCF model. ``text`` is None when the file has no include (MuJoCo
    then reads the file itself, and its line numbers are the file's)."""

    def __init__(
        self,
        doc: XmlDocument,
        text: str | None = None,
        merged: XmlDocument | None = None,
        origin: dict[int, SourceLocation] | None = None,
    ):
        self.doc = doc
        self.text = text
        self._merged = merged
        self._origin = origin or {}
        self._order = list(doc.root.iter()) if merged is not None else []

    def locate(self, message: str) -> SourceLocation:
        """A file:line:column for one of MuJoCo's error messages (never column 0)."""
        m = re.search(r"[Ll]ine(?:\s+number)?\s*[=:]?\s*(\d+)", message)
        line = int(m.group(1)) if m else None
        tag = re.search(r"Element '([^']*)'", message)
        name = re.search(r"Element name '([^']*)'", message)
        view = self._merged if self._merged is not None else self.doc
        candidates = view.elements()
        if line is not None:
            on_line = [el for el in candidates if view.line(el) == line]
            candidates = on_line or ([view.at_line(line)] if view.at_line(line) is not None else candidates)
        if tag:
            candidates = [el for el in candidates if el.tag == tag.group(1)] or candidates
        if name and name.group(1):
            named = [el for el in candidates if el.get("name") == name.group(1)]
            if not named and line is None:
                named = [el for el in view.elements() if el.get("name") == name.group(1)]
            candidates = named or candidates
        if line is None and not (name and name.group(1)) and not tag:
            return self.doc.where(self.doc.root)
        el = candidates[0] if candidates else view.root
        if self._merged is None:
            return self.doc.where(el)
        index = {id(e): i for i, e in enumerate(self._merged.elements())}.get(id(el))
        if index is None or index >= len(self._order):
            return self.doc.where(self.doc.root)
        return self._origin.get(id(self._order[index]), self.doc.where(self.doc.root))


def load(path: Path) -> Source:
    """Parse ``path`` safely and resolve its includes (see the module docstring)."""
    doc = parse_xml(path)
    if not any(el.tag == "include" for el in doc.root.iter()):
        return Source(doc)
    folder = Path(os.path.realpath(path)).parent
    tree = inputs.tree_of(path) if os.environ.get(inputs.ROOT_ENV) else inputs.Tree(folder)
    origin: dict[int, SourceLocation] = {id(el): doc.where(el) for el in doc.elements()}
    pending: list[tuple[ET.Element, XmlDocument, tuple[str, ...]]] = [(doc.root, doc, (os.path.realpath(path),))]
    followed = 0
    while pending:
        parent, owner, chain = pending.pop()
        kids = list(parent)
        for pos in range(len(kids) - 1, -1, -1):
            inc = kids[pos]
            if inc.tag != "include":
                pending.append((inc, owner, chain))
                continue
            where = owner.where(inc)
            name = inc.get("file")
            if not name:
                raise AdfError(error("mjcf-include", "<include> without a file", where, 'add file="part.xml"'))
            inputs.check_path_text(name, where)
            if os.path.isabs(name):
                raise AdfError(
                    error(
                        "mjcf-include",
                        f'<include file="{inputs.shown(name)}">: an absolute path is not followed',
                        where,
                        "include files by a path relative to the model's folder",
                    )
                )
            target = folder / name
            real = os.path.realpath(target)
            if real in chain:
                raise AdfError(
                    error(
                        "mjcf-include",
                        f'<include file="{inputs.shown(name)}"> includes itself (directly or through other files)',
                        where,
                        "remove the include cycle",
                    )
                )
            followed += 1
            if followed > MAX_INCLUDES:
                raise AdfError(
                    error("mjcf-include", f"more than {MAX_INCLUDES} includes", where, "merge the included files")
                )
            data = inputs.read_bytes(target, "xml", tree=tree, referrer=where, what="included MJCF file")
            sub = parse_xml(target, text=data)
            for el in sub.elements():
                origin[id(el)] = sub.where(el)
            parent.remove(inc)
            for k, el in enumerate(list(sub.root)):
                parent.insert(pos + k, el)
                pending.append((el, sub, chain + (real,)))
    for comp in doc.root.iter("compiler"):
        _absolute_dirs(comp, folder)
    if doc.root.find("compiler") is None:
        comp = ET.Element("compiler")
        doc.root.insert(0, comp)
        origin[id(comp)] = doc.where(doc.root)
        _absolute_dirs(comp, folder)
    text = to_text(doc.root) + "\n"
    return Source(doc, text, parse_xml(path, text=text), origin)


def _absolute_dirs(comp: ET.Element, folder: Path) -> None:
    """meshdir and texturedir as absolute folders (MuJoCo compiles the merged text from a string,
    where a relative folder would mean the current one)."""
    base = folder / (comp.get("assetdir") or "")
    for attr in ("meshdir", "texturedir"):
        comp.set(attr, str(base / (comp.get(attr) or "")))
    comp.attrib.pop("assetdir", None)
