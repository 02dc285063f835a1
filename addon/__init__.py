"""adfkit Blender extension: author, export and import AMBF Description Format (ADF) models.

Blender-level code lives in this package; the ADF model, reader, writer and validator
come from the ``adfkit`` package (bundled as a wheel, see the README, "Blender add-on").
"""

from __future__ import annotations


def register() -> None:
    from . import operators, properties, ui

    properties.register()
    operators.register()
    ui.register()


def unregister() -> None:
    from . import operators, properties, ui

    ui.unregister()
    operators.unregister()
    properties.unregister()
