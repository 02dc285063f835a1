"""Textured OBJ visuals drawn with their textures by MuJoCo's renderer.

An OBJ visual mesh whose MTL material has a diffuse map (``map_Kd``) gets a MuJoCo 2-D texture
(the image, read through the input policy and decoded here) and a material carrying it; the
visual geom uses that material and MuJoCo maps the image with the OBJ's own texture
coordinates (``vt``). As in PyBullet and the viewer, a body with an ADF colour is drawn in that
colour, untextured. MuJoCo gives a mesh one material: an OBJ whose faces use several textured
materials is drawn untextured, with a warning.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from ... import inputs
from ...diagnostics import AdfError
from ..plan import rgba

VISUAL_GROUP = 1  # the MJCF writer's group for visual geoms


@dataclass
class ObjTexture:
    image: Path  # the diffuse map
    colour: list  # the material's Kd and d (MuJoCo multiplies the texture by it)


def _words(line: str) -> list[str]:
    return line.split("#", 1)[0].split()


def obj_texture(path: Path, tree=None) -> ObjTexture | str | None:
    """The diffuse texture of an OBJ's material(s): an ObjTexture, None when it has none, or
    why it cannot be drawn (several textured materials)."""
    text = inputs.read_text(path, "mesh", tree=tree, what="mesh file")
    libs, used = [], []
    for line in text.splitlines():
        if line.startswith("mtllib"):
            libs += _words(line)[1:]
        elif line.startswith("usemtl"):
            w = _words(line)
            if len(w) > 1 and w[1] not in used:
                used.append(w[1])
    materials: dict[str, dict] = {}
    for lib in libs:
        try:
            mtl = inputs.read_text(path.parent / lib, "mesh", tree=tree, what="material file")
        except AdfError:
            continue  # no MTL: drawn in the geom's colour, as before
        current = None
        for line in mtl.splitlines():
            w = _words(line.strip())
            if not w:
                continue
            if w[0] == "newmtl" and len(w) > 1:
                current = materials.setdefault(w[1], {})
            elif current is not None and w[0] in ("map_Kd", "Kd", "d") and len(w) > 1:
                current[w[0]] = w[1:]
    textured = [n for n in (used or list(materials)) if "map_Kd" in materials.get(n, {})]
    images = {materials[n]["map_Kd"][-1] for n in textured}  # options (-s, -o ...) come before the file
    if not images:
        return None
    if len(images) > 1:
        return f"{path.name}: its faces use {len(images)} textured materials; MuJoCo gives a mesh one, so it is drawn untextured"
    mat = materials[textured[0]]
    try:
        kd = [float(x) for x in mat.get("Kd", ["1", "1", "1"])[:3]]
        alpha = float(mat.get("d", ["1"])[0])
    except ValueError:
        kd, alpha = [1.0, 1.0, 1.0], 1.0
    return ObjTexture(path.parent / images.pop(), [*kd, alpha])


def _add_texture(spec, name: str, image: Path, tree) -> None:
    from io import BytesIO

    from PIL import Image

    data = inputs.read_bytes(image, "image", tree=tree, what="texture image")
    with Image.open(BytesIO(data)) as im:
        rgb = np.asarray(im.convert("RGB"), dtype=np.uint8)
    tex = spec.add_texture(name=name, type=mujoco.mjtTexture.mjTEXTURE_2D)
    tex.width, tex.height, tex.nchannel = rgb.shape[1], rgb.shape[0], 3
    tex.data = rgb.tobytes()  # rows top-down, as in the file: MuJoCo flips the OBJ v coordinate itself


def apply_textures(world, spec, bodies) -> None:
    """Give the visual mesh geoms of ``bodies`` (build.BodyPlan, without an ADF colour) the
    texture their OBJ's material names. A texture that cannot be read is a warning; the mesh
    is then drawn in its colour."""
    made: dict[str, str | None] = {}  # image path -> material name (None: could not be read)
    for bp in bodies:
        if bp.mjname == "world" or rgba(bp.body) is not None:
            continue
        tree = getattr(bp.model, "tree", None)
        for g in spec.body(bp.mjname).geoms:
            if g.type != mujoco.mjtGeom.mjGEOM_MESH or g.group != VISUAL_GROUP or g.material:
                continue
            path = Path(spec.mesh(g.meshname).file)
            if path.suffix.lower() != ".obj":
                continue
            try:
                found = obj_texture(path, tree)
                if isinstance(found, str):
                    world._warn("runner-texture", found, bp.body)
                    continue
                if found is None:
                    continue
                key = str(found.image.resolve())
                if key not in made:
                    made[key] = None
                    name = f"adfkit:texture{len(made)}"
                    _add_texture(spec, name, found.image, tree)
                    spec.add_material(name=name, rgba=found.colour).textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = name
                    made[key] = name
            except (AdfError, OSError, ValueError) as exc:
                why = exc.diagnostics[0].message if isinstance(exc, AdfError) else f"{type(exc).__name__}: {exc}"
                world._warn("runner-texture", f"{path.name}: texture not drawn ({why})", bp.body)
                continue
            if made[key] is not None:
                g.material = made[key]
