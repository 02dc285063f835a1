"""ADF as one more converter format: a model file read and written through adfkit.adf."""
from __future__ import annotations

from pathlib import Path

from ..adf.reader import load
from ..adf.writer import write_file
from ..diagnostics import AdfError, SourceLocation, error
from ..model.files import ModelFile
from .losses import Loss


def read(path: Path) -> tuple[ModelFile, list[Loss]]:
    doc = load(path)
    if not isinstance(doc, ModelFile):
        raise AdfError(error("convert-kind", f"{path.name} is a {type(doc).__name__} file, not a model file",
                             SourceLocation(str(path), 1, 1), "convert one model (multibody) file at a time"))
    return doc, []


def write(model: ModelFile, path: Path) -> list[Loss]:
    write_file(model, path)
    return []
