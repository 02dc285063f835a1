"""Volumes (§11.4): every slice file read as the runner will read it (adfkit.geometry.volume:
the input policy, Pillow, one size, a sane count), so a broken volume is a located error in CI
rather than a volume AMBF silently skips; what AMBF loads but a modeller should hear about (a gap
in the numbering, opaque colour slices, a count above the slices found) as a warning or a note."""

from __future__ import annotations

from ..diagnostics import AdfError, Diagnostic, Severity
from ..model import ModelFile

# the input policy's rules for a slice file, as the volume rule that names them
_SLICE_RULES = {
    "file-not-found": "volume-slice-missing",
    "outside-tree": "volume-slice-missing",
    "not-a-regular-file": "volume-slice-missing",
    "bad-path": "volume-slice-missing",
    "file-unreadable": "volume-slice-unreadable",
    "file-too-large": "volume-too-large",
}


def check(m: ModelFile) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    for vol in m.volumes:
        if not vol.defined:
            continue
        try:
            from ..geometry.volume import load_volume  # numpy and Pillow: only when a file has volumes
        except ImportError:
            return out
        try:
            out.extend(load_volume(m, vol).findings)
        except AdfError as exc:
            for d in exc.diagnostics:
                rule = _SLICE_RULES.get(d.rule, d.rule)
                message = d.message if d.message.startswith("volume") else f"volume '{vol.identifier}': {d.message}"
                out.append(Diagnostic(Severity.ERROR, rule, message, d.location, d.hint))
    return out
