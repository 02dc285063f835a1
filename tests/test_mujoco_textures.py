"""MuJoCo's renderer draws textured OBJ visuals with their MTL's diffuse map (runner/mujoco/
textures.py), both as the MuJoCo engine and as the PyBullet world's mirror: the bundled
suturing scene's phantom tissue and checkered floor look as TinyRenderer draws them."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from conftest import ROOT, require_renderer

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

pytest.importorskip("pybullet", reason="pybullet (sim extra) is not installed")
pytest.importorskip("mujoco", reason="mujoco is not installed")

SUTURING = ROOT / "sample_scenes" / "suturing" / "launch.yaml"


def _left_frame(renderer: str, engine: str = "pybullet"):
    """Camera L's frame and the body indices of the phantom and the floor."""
    world = open_world(load_scene(SUTURING), Options(renderer=renderer), engine=engine)
    try:
        assert engine == "mujoco" or world.renderer == renderer
        names = [sb.body.name for sb in world.bodies]
        return world.cameras[0].render(world), names.index("Phantom"), names.index("Floor")
    finally:
        world.close()


def _detail(rgb: np.ndarray) -> np.ndarray:
    """The picture's fine detail (grey minus its 9-pixel local mean): the texture, not the shading."""
    from scipy import ndimage

    g = rgb.astype(float).mean(axis=2)
    return g - ndimage.uniform_filter(g, 9)


@pytest.fixture(scope="module")
def tiny():
    return _left_frame("tiny")


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_textured_meshes_are_drawn_with_their_textures(tiny, engine):
    from scipy import ndimage

    require_renderer("mujoco")
    ref, phantom, floor = tiny
    mj, phantom_mj, floor_mj = _left_frame("mujoco", engine)
    for label, label_mj in ((phantom, phantom_mj), (floor, floor_mj)):
        # the body's pixels in both pictures, away from its edges
        seen = (ref["segmentation"] == label) & (mj["segmentation"] == label_mj)
        region = ndimage.binary_erosion(seen, iterations=5)
        assert region.sum() > 20_000
        a, b = ref["rgb"][region].astype(float), mj["rgb"][region].astype(float)
        # the same colour as TinyRenderer's (untextured, MuJoCo drew both grey: 219 and 144)
        assert np.abs(a.mean(axis=0) - b.mean(axis=0)).max() < 25, (a.mean(axis=0), b.mean(axis=0))
        # the same pattern: the detail of both pictures agrees (untextured: 0.20 and 0.01)
        r = np.corrcoef(_detail(ref["rgb"])[region], _detail(mj["rgb"])[region])[0, 1]
        assert r > 0.45, r
        if label == phantom:  # the tissue is red (untextured: R = G)
            assert b[:, 0].mean() - b[:, 1].mean() > 50
        else:  # the checker's squares (untextured: a flat grey, standard deviation 1)
            assert b.std(axis=0).min() > 15


BOX_OBJ = """mtllib box.mtl
usemtl {first}
v 0 0 0
v 0.1 0 0
v 0.1 0.1 0
v 0 0.1 0
v 0 0 0.1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3
f 1/1 3/3 4/4
usemtl {second}
f 1/1 2/2 5/3
f 2/2 3/3 5/4
f 3/3 4/4 5/1
f 4/4 1/1 5/2
"""

BOX_MODEL = """bodies: [BODY box]
high resolution path: ./
BODY box:
  name: box
  mass: 0.0
  mesh: box.obj
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""


@pytest.mark.parametrize(
    "first, second, mtl, expected",
    [
        # two textured materials: MuJoCo gives a mesh one
        ("a", "b", "newmtl a\nmap_Kd checker.png\nnewmtl b\nmap_Kd other.png\n", "2 textured materials"),
        # the image is not there
        ("a", "a", "newmtl a\nKd 1 1 1\nmap_Kd absent.png\n", "texture not drawn (no such texture image"),
    ],
)
def test_a_texture_that_cannot_be_drawn_is_a_warning(tmp_path, first, second, mtl, expected):
    (tmp_path / "box.obj").write_text(BOX_OBJ.format(first=first, second=second))
    (tmp_path / "box.mtl").write_text(mtl)
    shutil.copy(ROOT / "sample_scenes" / "suturing" / "world" / "meshes" / "checker.png", tmp_path / "checker.png")
    shutil.copy(tmp_path / "checker.png", tmp_path / "other.png")
    (tmp_path / "model.yaml").write_text(BOX_MODEL)
    world = open_world(load_scene(tmp_path / "model.yaml"), Options(renderer="tiny"), engine="mujoco")
    try:
        (found,) = [d for d in world.diagnostics if d.rule == "runner-texture"]
        assert found.message.startswith("box.obj: ") and expected in found.message, found.message
        assert world.model.nmat == 0 and world.model.ntex == 0  # drawn in its colour, as before
    finally:
        world.close()


def test_a_textured_obj_gets_its_image_as_a_mujoco_texture(tmp_path):
    (tmp_path / "box.obj").write_text(BOX_OBJ.format(first="a", second="a"))
    (tmp_path / "box.mtl").write_text("newmtl a\nKd 0.5 1 1\nd 1\nmap_Kd -s 1 1 1 checker.png\n")
    shutil.copy(ROOT / "sample_scenes" / "suturing" / "world" / "meshes" / "checker.png", tmp_path / "checker.png")
    (tmp_path / "model.yaml").write_text(BOX_MODEL)
    world = open_world(load_scene(tmp_path / "model.yaml"), Options(renderer="tiny"), engine="mujoco")
    try:
        m = world.model
        assert not [d for d in world.diagnostics if d.rule == "runner-texture"]
        assert (m.ntex, m.nmat) == (1, 1) and (m.tex_width[0], m.tex_height[0]) == (64, 64)
        assert list(m.mat_rgba[0]) == pytest.approx([0.5, 1, 1, 1])  # the MTL's Kd and d
        visual = [g for g in range(m.ngeom) if m.geom_group[g] == 1]
        assert len(visual) == 1 and m.geom_matid[visual[0]] == 0
        mesh = m.geom_dataid[visual[0]]
        assert m.mesh_texcoordnum[mesh] == 4  # the OBJ's own UVs
    finally:
        world.close()
