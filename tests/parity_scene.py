"""Hand-made models played against AMBF: a launch file with the parity scenes' world, floor,
colours and input devices (`adfkit build-scene parity`) and the given model files, and
`adfkit parity --json` on it, one comparison per engine."""

from __future__ import annotations

import json
from pathlib import Path

from adfkit.cli import main


def launch_with(folder: Path, models: dict[str, str], name: str = "hand_made_launch.yaml") -> Path:
    """A launch file in ``folder`` loading ``models`` (file name -> ADF text) in their order."""
    main(["build-scene", "parity", str(folder)])
    for file_name, text in models.items():
        (folder / file_name).write_text(text)
    launch = folder / name
    launch.write_text(
        "world config: world.yaml\ncolor config: colors.yaml\ninput devices config: input_devices.yaml\n"
        "multibody configs:\n" + "".join(f"- {m}\n" for m in models)
    )
    return launch


def parity(capsys, launch: Path, seconds: float, engine: str = "both", *more: str) -> list[dict]:
    """`adfkit parity LAUNCH --json`'s comparisons, one per engine."""
    capsys.readouterr()
    main(["parity", str(launch), "--seconds", str(seconds), "--engine", engine, *more, "--json"])
    doc = json.loads(capsys.readouterr().out)
    return doc if isinstance(doc, list) else [doc]


def body(doc: dict, name: str) -> dict:
    """The comparison's row for the body whose AMBF name ends in /``name``."""
    return next(b for b in doc["bodies"] if b["name"].endswith("/" + name))
