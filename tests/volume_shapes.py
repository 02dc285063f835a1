"""Volumes in the shape the public AMBF drilling and skull-base projects ship them, built by the
tests: RGBA slices named ``plane00<i>.png`` (index unpadded after a prefix ending in zeros),
``count: 512`` over a folder holding fewer, a model file per volume with the project's keys
(namespace, shaders, a volume under a parent body), two files naming the same volume, and a
drill whose tip is a mesh."""

from __future__ import annotations

from pathlib import Path

import numpy as np

BONE = (255, 249, 219)  # the colour the drilling projects' segmented volumes give bone
SINUS = (110, 184, 209)


def skull_rgba(slices: int, side: int, seed: int = 3) -> np.ndarray:
    """(slices, side, side, 4) uint8 in picture order: a rounded block of bone (alpha 255) with
    air cells (alpha 0) and a tube of another tissue colour; alpha 0 outside."""
    z, y, x = np.meshgrid(*(np.linspace(-1, 1, n) for n in (slices, side, side)), indexing="ij")
    bone = (np.abs(x) / 0.8) ** 3 + (np.abs(y) / 0.7) ** 3 + (np.abs(z) / 0.75) ** 3 <= 1.0
    rng = np.random.default_rng(seed)
    for cx, cy, cz in rng.uniform(-0.4, 0.4, size=(4, 3)):
        bone &= (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2 > 0.15**2
    tube = bone & ((x + 0.2) ** 2 + (z - 0.1) ** 2 < 0.12**2)
    out = np.zeros((*bone.shape, 4), np.uint8)
    out[bone] = (*BONE, 255)
    out[tube] = (*SINUS, 255)
    return out


def write_slices(folder: Path, rgba: np.ndarray, prefix: str = "plane00", indices=None) -> list[Path]:
    """Slices ``prefix<i>.png`` for i in ``indices`` (default 0..n-1), RGBA."""
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for k, i in enumerate(range(len(rgba)) if indices is None else indices):
        p = folder / f"{prefix}{i}.png"
        Image.fromarray(rgba[k], "RGBA").save(p)
        out.append(p)
    return out


def volume_yaml(
    name: str,
    slices: str,
    count: int = 512,
    dims=(0.0492027, 0.0492027, 0.048485),
    parent: str | None = None,
    position=(-0.3, 0.0, 0.0),
    rpy=(1.57079, 1.4, 0.0),
    bodies: str = "",
    body_list: str = "[]",
) -> str:
    """A model file holding one volume, as the drilling projects write theirs."""
    x, y, z = position
    r, p, yw = rpy
    parent_line = f"  parent: {parent}\n" if parent else ""
    return f"""# AMBF Version: (0.1)
bodies: {body_list}
joints: []
volumes: [VOLUME {name}]
high resolution path: ./meshes/high_res/
low resolution path: ./meshes/low_res/
ignore inter-collision: true
namespace: /ambf/env/
{bodies}
VOLUME {name}:
  name: {name}
{parent_line}  location:
    position: {{x: {x}, y: {y}, z: {z}}}
    orientation: {{r: {r}, p: {p}, y: {yw}}}
  scale: 1.0
  dimensions: {{x: {dims[0]}, y: {dims[1]}, z: {dims[2]}}}
  images:
    path: {slices}
    prefix: plane00
    format: png
    count: {count}
  shaders:
    path: ./shaders/volume/
    vertex: shader.vs
    fragment: shader.fs
"""


ORIGIN = (0.1, 0.2, 0.3)  # the skull-base volume's parent body, turned 90° about z


def skull_base(folder: Path, mass: float = 0.0) -> Path:
    """A model file as the skull-base project has its volume: RGBA slices under count 512,
    hanging from a body at the anatomy's origin (10 mm along its x); returns the file."""
    write_slices(folder / "slices", skull_rgba(12, 16))
    body = (
        "BODY volume_Anatomical_Origin:\n  name: volume_Anatomical_Origin\n"
        f"  mass: {mass}\n  shape: Sphere\n  geometry: {{radius: 0.001}}\n"
        f"  location:\n    position: {{x: {ORIGIN[0]}, y: {ORIGIN[1]}, z: {ORIGIN[2]}}}\n"
        "    orientation: {r: 0.0, p: 0.0, y: 1.5707963267948966}\n"
    )
    text = volume_yaml(
        "skull",
        "slices/",
        dims=(0.04, 0.04, 0.03),
        parent="BODY volume_Anatomical_Origin",
        position=(0.01, 0.0, 0.0),
        rpy=(0.0, 0.0, 0.0),
        bodies=body,
        body_list="[BODY volume_Anatomical_Origin]",
    ).replace("  shaders:\n    path: ./shaders/volume/\n    vertex: shader.vs\n    fragment: shader.fs\n", "")
    (folder / "skull.yaml").write_text(text)
    return folder / "skull.yaml"


def write_launch(root: Path, adf: str, world: str, models: list[str]) -> Path:
    """``root/launch.yaml`` naming ``adf/world`` and the model files, with the colour and
    input-device files AMBF requires (written empty into ``root/adf``)."""
    d = root / adf if adf else root
    pre = f"{adf}/" if adf else ""
    (d / "colors.yaml").write_text("colors: {}\n")
    (d / "input_devices.yaml").write_text("input devices: []\n")
    listed = "".join(f"  - {pre}{m}\n" for m in models)
    (root / "launch.yaml").write_text(
        f"world config: {pre}{world}\ncolor config: {pre}colors.yaml\ninput devices config: {pre}input_devices.yaml\n"
        f"multibody configs:\n{listed}"
    )
    return root / "launch.yaml"


def write_shaders(adf_dir: Path) -> None:
    """The volume shader files the model files name (the runner does not use them)."""
    d = adf_dir / "shaders" / "volume"
    d.mkdir(parents=True, exist_ok=True)
    (d / "shader.vs").write_text("void main(void) { gl_Position = ftransform(); }\n")
    (d / "shader.fs").write_text("void main(void) { gl_FragColor = vec4(1.0); }\n")


def project(
    root: Path,
    slices: int = 20,
    side: int = 24,
    count: int = 512,
    files=("volume_a.yaml",),
    name: str = "mastoidectomy_volume",
    **kw,
) -> Path:
    """The drilling projects' layout: ``ADF/<file>`` naming ``../resources/volumes/skull/``
    (``slices`` RGBA slices of ``side``² pixels, ``count`` as given), with shaders; returns ADF/."""
    adf = root / "ADF"
    adf.mkdir(parents=True, exist_ok=True)
    write_shaders(adf)
    write_slices(root / "resources" / "volumes" / "skull", skull_rgba(slices, side))
    for f in files:
        (adf / f).write_text(volume_yaml(name, "../resources/volumes/skull/", count, **kw))
    return adf


__all__ = [
    "BONE",
    "ORIGIN",
    "SINUS",
    "project",
    "skull_base",
    "skull_rgba",
    "volume_yaml",
    "write_launch",
    "write_shaders",
    "write_slices",
]
