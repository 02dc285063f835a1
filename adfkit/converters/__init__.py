"""ADF ⇄ URDF and ADF ⇄ MJCF through the scene model (format-mapping.md).

Each format module offers ``read(path) -> (ModelFile, [Loss])`` and
``write(model, path) -> [Loss]``; nothing converts one file format directly into another.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error
from .losses import Loss

FORMATS = ("adf", "urdf", "mjcf")
_EXTENSIONS = {".yaml": "adf", ".yml": "adf", ".adf": "adf", ".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf"}


def format_of(path: str | Path, given: str | None = None) -> str:
    """The format named by ``given`` or by the file's extension (`.urdf`, `.xml`/`.mjcf`,
    `.yaml`); an `.xml` whose root is <robot> is URDF."""
    if given:
        return given
    p = Path(path)
    fmt = _EXTENSIONS.get(p.suffix.lower())
    if fmt is None:
        raise AdfError(
            error(
                "convert-format",
                f"cannot tell the format of {p.name!r} from its extension",
                SourceLocation(str(p)),
                "use .yaml (ADF), .urdf or .xml (MJCF), or pass --from/--to",
            )
        )
    if fmt == "mjcf" and inputs.is_regular(p):
        with open(inputs.check_file(p, "xml", what="XML file"), "rb") as fh:  # regular file only
            head = fh.read(4096).decode("utf-8", "replace")
        if "<robot" in head and "<mujoco" not in head:
            return "urdf"
    return fmt


def _module(fmt: str):
    return importlib.import_module(f"{__name__}.{'adf_io' if fmt == 'adf' else fmt}")


def read(path: str | Path, fmt: str | None = None):
    """(ModelFile, [Loss]) for a file in any supported format."""
    return _module(format_of(path, fmt)).read(Path(path))


def write(model, path: str | Path, fmt: str | None = None) -> list[Loss]:
    """Write ``model`` in the format of ``path``; the losses of that format."""
    return _module(format_of(path, fmt)).write(model, Path(path))


__all__ = ["FORMATS", "Loss", "format_of", "read", "write"]
