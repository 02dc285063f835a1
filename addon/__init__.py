"""adfkit Blender extension: author, export and import AMBF Description Format (ADF) models.

Blender-level code lives in this package; the ADF model, reader, writer and validator
come from the ``adfkit`` package (bundled as a wheel, see the README, "Blender add-on").
"""

from __future__ import annotations


def register() -> None:
    from . import holes, operators, properties, tool_operators, ui

    properties.register()
    operators.register()
    tool_operators.register()
    holes.register()
    ui.register()


def unregister() -> None:
    from . import holes, operators, properties, tool_operators, ui

    ui.unregister()
    holes.unregister()
    tool_operators.unregister()
    operators.unregister()
    properties.unregister()
