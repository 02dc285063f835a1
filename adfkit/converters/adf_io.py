"""ADF as one more converter format: a model file read and written through adfkit.adf."""

from __future__ import annotations

from pathlib import Path

from ..adf.reader import read_file
from ..adf.writer import write_file
from ..diagnostics import AdfError, SourceLocation, error
from ..model.files import ModelFile
from .losses import Loss


def read(path: Path) -> tuple[ModelFile, list[Loss]]:
    doc, diags = read_file(path)
    # what AMBF loads anyway (duplicate keys: it keeps the first) does not stop a conversion
    from ..validator.engine import SEVERITY_OVERRIDES

    errors = [d for d in diags if SEVERITY_OVERRIDES.get(d.rule, d.severity) >= 2]
    if errors:
        raise AdfError(errors)
    if not isinstance(doc, ModelFile):
        raise AdfError(
            error(
                "convert-kind",
                f"{path.name} is a {type(doc).__name__} file, not a model file",
                SourceLocation(str(path), 1, 1),
                "convert one model (multibody) file at a time",
            )
        )
    return doc, []


def write(model: ModelFile, path: Path) -> list[Loss]:
    write_file(model, path)
    return []
