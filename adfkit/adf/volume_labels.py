"""A volume's labels file (``labels.yaml`` in its slice folder; ``adfkit drill`` reads it): the
tissue each range of slice values stands for, in the slices' own units, or each colour of a
colour-segmented volume (RGBA slices, as the drilling projects ship theirs), and which tissues
a burr must not touch::

    bone: [150, 255]
    canal: [60, 120]
    protected: [canal]

    bone: "#fff9db"
    facial nerve: "#f4d631"
    protected: [facial nerve]

Not an ADF file (AMBF never reads it); its syntax is checked here, in the core, so that
``adfkit validate`` of a scene folder checks it too and ``adfkit drill`` reads it the same way.
Any mistake is a located ``drill-labels`` error with a hint."""

from __future__ import annotations

import math

from ..diagnostics import AdfError, SourceLocation, error

FILE_NAME = "labels.yaml"
MAX_TISSUES = 254  # label ids 1..254 in a uint8 label volume (0: no tissue)


def is_labels_file(path) -> bool:
    return str(path).replace("\\", "/").rsplit("/", 1)[-1].lower() == FILE_NAME


def _colour(v) -> tuple[int, int, int] | None:
    """(r, g, b) of a ``"#rrggbb"`` scalar, else None."""
    text = str(getattr(v, "value", ""))
    if len(text) == 7 and text.startswith("#"):
        try:
            return int(text[1:3], 16), int(text[3:5], 16), int(text[5:7], 16)
        except ValueError:
            return None
    return None


def parse_labels(text: str, shown: str) -> tuple[list[str], list[tuple], list[str]]:
    """(tissue names, each one's (low, high) range in the slices' units or (r, g, b) colour,
    protected names) of a labels file's text; ``shown``: the file name the errors carry."""
    import yaml

    from .yamlnodes import compose

    root = compose(text, shown)

    def at(node) -> SourceLocation:
        return SourceLocation(shown, node.start_mark.line + 1, node.start_mark.column + 1)

    def bad(node, message: str, hint: str) -> AdfError:
        return AdfError(error("drill-labels", message, at(node), hint))

    if not isinstance(root, yaml.MappingNode):
        raise AdfError(
            error(
                "drill-labels",
                "a labels file is a mapping of tissue names to value ranges",
                SourceLocation(shown, 1, 1),
                "e.g. bone: [150, 255]",
            )
        )
    names: list[str] = []
    ranges: list[tuple] = []
    protected_nodes: list = []
    for k, v in root.value:
        if k.value == "protected":
            if not isinstance(v, yaml.SequenceNode) or not all(isinstance(x, yaml.ScalarNode) for x in v.value):
                raise bad(v, "`protected` is a list of tissue names", "e.g. protected: [canal]")
            protected_nodes = v.value
            continue
        colour = _colour(v) if isinstance(v, yaml.ScalarNode) else None
        if colour is not None:
            if len(names) >= MAX_TISSUES:
                raise bad(k, f"more than {MAX_TISSUES} tissues", "merge tissues")
            names.append(str(k.value))
            ranges.append(colour)
            continue
        ok = isinstance(v, yaml.SequenceNode) and len(v.value) == 2
        try:
            lo, hi = (float(x.value) for x in v.value) if ok else (0.0, -1.0)
        except (ValueError, TypeError, AttributeError):
            ok = False
        if not ok or not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi or hi < 0:
            raise bad(
                v,
                f"tissue '{str(k.value)[:40]}' needs a range [low, high] of slice values, low <= high, "
                'or a colour "#rrggbb"',
                'e.g. bone: [150, 255] (the slices\' own units), or bone: "#fff9db" for colour slices',
            )
        if len(names) >= MAX_TISSUES:
            raise bad(k, f"more than {MAX_TISSUES} tissues", "merge tissues")
        names.append(str(k.value))
        ranges.append((lo, hi))
    if not names:
        raise bad(root, "the labels file names no tissue", "e.g. bone: [150, 255]")
    protected: list[str] = []
    for node in protected_nodes:
        if node.value not in names:
            raise bad(
                node, f"protected tissue '{str(node.value)[:40]}' is not one of {names}", "name a tissue of this file"
            )
        protected.append(node.value)
    return names, ranges, protected
