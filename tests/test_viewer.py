"""`adfkit view` driven in a real headless browser (the system's Chromium through Playwright):
the bundled suturing scene is drawn (not a blank canvas), a joint slider moves the picture, a
recorded episode replays on its timeline; and bad input is a clear error."""

from __future__ import annotations

import json
import shutil
import socket

import numpy as np
import pytest
from conftest import ROOT

from adfkit.cli import main

pytest.importorskip("pybullet", reason="pybullet (sim extra) is not installed")
pytest.importorskip("viser", reason="viser (view extra) is not installed")

BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"
CHROMIUM = next((p for p in (shutil.which("chromium"), shutil.which("chromium-browser")) if p), None)
# software WebGL in headless Chromium (design.md)
FLAGS = ["--headless=new", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no Chromium here (apt-get install chromium; .ci/run installs it)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        yield b
        b.close()


def _canvas(page) -> np.ndarray:
    """The 3-D view's pixels (the left of the page; the panel is on the right)."""
    from io import BytesIO

    from PIL import Image

    # a loaded box draws the challenge scene slowly in software: a generous time out
    png = page.screenshot(clip={"x": 0, "y": 160, "width": 900, "height": 600}, timeout=120_000)
    return np.asarray(Image.open(BytesIO(png)).convert("RGB")).astype(np.int16)


def _serve(episode=None):
    from adfkit.viewer.server import Viewer

    v = Viewer(BUNDLED, None, "pybullet", "127.0.0.1", _free_port(), episode)
    v.load()
    return v, v.start()


def _open(browser, address):
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.goto(address)
    page.wait_for_selector("canvas", timeout=30_000)
    page.wait_for_timeout(4000)  # the scene's meshes arrive over the websocket
    return page


def _to_end(slider) -> None:
    """Press End on a slider until the page shows it at its maximum (a folder just opened may
    still be animating), then let the new picture arrive."""
    for _ in range(10):
        slider.page.wait_for_timeout(500)
        slider.press("End")
        if slider.get_attribute("aria-valuenow") == slider.get_attribute("aria-valuemax"):
            break
    slider.page.wait_for_timeout(2500)


def _expand(page, *titles) -> None:
    for t in titles:
        page.get_by_text(t, exact=True).first.click()
        page.wait_for_timeout(300)


def test_the_scene_is_drawn_and_a_joint_slider_moves_it(browser):
    v, address = _serve()
    try:
        assert v.world is not None and len(v.body_nodes) == len(v.world.bodies) > 50
        page = _open(browser, address)
        before = _canvas(page)
        # not a blank canvas: many colours and real contrast where the bodies are
        assert len(np.unique(before.reshape(-1, 3), axis=0)) > 200 and before.std() > 10
        _expand(page, "Joints", "psm1/base link simple")
        _to_end(page.locator("[role=slider]").first)  # the first joint (the arm's yaw) to its upper limit
        arm = v.world.articulations[0]
        assert v.world.joint_state(arm, [0])[0][0] == pytest.approx(arm.records[0][0].joint_limits.high, abs=1e-6)
        after = _canvas(page)
        moved = np.abs(after - before).max(axis=2) > 40
        assert moved.mean() > 0.002, moved.mean()  # the arm swung: its pixels changed
        page.close()
    finally:
        v.close()


def _record_episode(folder):
    """A short episode in the format `adfkit suture --record` writes: frames of the live world
    while psm1 turns its yaw, and a metrics.json with one verdict."""
    from adfkit.adf import load_scene
    from adfkit.dataset.writer import DatasetWriter
    from adfkit.runner import Options, open_world
    from adfkit.runner.psm import PSM

    world = open_world(load_scene(BUNDLED), Options())
    try:
        psm = PSM(world, "psm1")
        writer = DatasetWriter(world, folder / "dataset", cameras=[world.cameras[0].name])
        q0 = psm.measured_jp()
        for k in range(4):
            q = q0.copy()
            q[0] += 0.25 * k
            psm.reset_jp(q)
            world.step(2)
            writer.write(
                k,
                {
                    "needle": world.body("Needle").world_matrix(),
                    "psms": {"psm1": {"jp": [float(x) for x in psm.measured_jp()], "jaw": 0.5}},
                },
                f"phase {k}",
            )
        writer.close()
    finally:
        world.close()
    (folder / "metrics.json").write_text(
        json.dumps({"pairs": [{"pair": 1, "passed": False, "reason": "blocked at entry 1"}]})
    )


def test_a_recorded_episode_replays_on_its_timeline(browser, tmp_path):
    _record_episode(tmp_path)
    v, address = _serve(tmp_path)
    try:
        assert v.episode is not None and len(v.episode.frames) == 4
        page = _open(browser, address)
        assert page.get_by_text("blocked at entry 1").count() >= 1  # the verdicts are listed
        first = _canvas(page)
        _to_end(page.locator("[role=slider]").last)  # the timeline (the last panel) to the last frame
        assert page.get_by_text("phase 3", exact=False).count() >= 1
        last = _canvas(page)
        assert (np.abs(last - first).max(axis=2) > 40).mean() > 0.002
        page.close()
    finally:
        v.close()


def test_a_scene_with_errors_opens_with_them_listed(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("bodies: [BODY a]\nBODY a:\n  mass: heavy\n")
    from adfkit.viewer.server import Viewer

    v = Viewer(bad, None, "pybullet", "127.0.0.1", _free_port())
    v.load()
    try:
        assert v.world is None
        assert any(d.rule == "bad-type" and d.location.line == 3 for d in v.findings)
    finally:
        v.close()


def test_bad_input_is_a_clear_error(tmp_path, capsys):
    assert main(["view", str(tmp_path / "absent.yaml")]) == 2
    assert "error[file-not-found]" in capsys.readouterr().err
    with socket.socket() as s:  # a port in use
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert main(["view", str(BUNDLED), "--port", str(port)]) == 2
    err = capsys.readouterr().err
    assert "error[port-in-use]" in err and f"127.0.0.1:{port}" in err and "Traceback" not in err


@pytest.mark.parametrize("scene, soft, volume", [("soft_phantom", 1, False), ("drilling", 0, True)])
def test_soft_bodies_deform_and_volumes_show_in_the_page(scene, soft, volume):
    from adfkit.viewer.server import Viewer

    v = Viewer(ROOT / "sample_scenes" / scene / "launch.yaml", None, "pybullet", "127.0.0.1", _free_port())
    v.load()
    v.start()
    try:
        assert len(v.soft_nodes) == soft
        for _s, h in v.soft_nodes:
            before = np.array(h.vertices)
            with v.lock:
                v.world.run(0.3)  # the probe presses into the skin
            v.update_poses()
            assert np.abs(np.array(h.vertices) - before).max() > 1e-4
        drawn = [sb for sb, _ in v.body_nodes if getattr(sb, "surface", None) is not None]
        assert bool(drawn) == volume
        if volume:
            assert drawn[0].key.endswith("VOLUME Bone") and len(drawn[0].surface[1]) > 1000
    finally:
        v.close()


def test_textured_visual_meshes_keep_their_texture():
    """The bundled phantom's OBJ names a texture: the viewer sends it, not a flat colour."""
    from adfkit.adf import load_scene
    from adfkit.viewer.geometry import visual_parts

    scene = load_scene(BUNDLED)
    phantom = next((m, b) for m in scene.all_models() for b in m.bodies if b.name == "Phantom")
    (part,) = visual_parts(*phantom)
    assert part.textured is not None and part.textured.visual.kind == "texture"
    assert part.textured.visual.material.image.size[0] >= 64
    assert len(part.textured.vertices) >= len(part.vertices)  # UV seams split vertices


def test_clicking_a_body_shows_its_adf_facts():
    from adfkit.viewer import panels

    v, _ = _serve()
    try:
        needle = v.world.body("Needle")
        panels.show_body(v, needle)
        text = v.selected.content
        where = needle.body.where()
        assert "**BODY Needle**" in text and f"{where.file}:{where.line}" in text
        assert f"mass: {needle.mass:g} kg" in text and "inertia: ix " in text
        panels.show_body(v, v.world.body("Phantom"))  # the same panel, updated
        assert "**BODY Phantom**" in v.selected.content and "mass: 0 kg" in v.selected.content
    finally:
        v.close()


def _parented_camera_scene(folder):
    """box_camera_model's camera riding on its box, the box turned."""
    from conftest import box_camera_model

    text = box_camera_model(mass=1.0, z=0.5)
    text = text.replace(
        "z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}", "z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.6}"
    )
    text = text.replace("  name: cam\n", "  name: cam\n  parent: BODY box\n")
    assert "y: 0.6" in text and "parent: BODY box" in text
    path = folder / "model.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("scene", ["drilling", "parented"])
def test_the_mujoco_engine_serves_its_cameras(scene, tmp_path):
    """`adfkit view --engine mujoco` on a scene with cameras: the page opens looking as the first
    camera looks, and the Cameras panel draws an image, through the same calls as for PyBullet
    (``view`` where the MJCF camera is, ``render``, a resized copy as the Gymnasium envs make)."""
    import dataclasses

    from conftest import require_renderer

    from adfkit.viewer.server import Viewer

    require_renderer("mujoco")
    path = (
        ROOT / "sample_scenes" / "drilling" / "launch.yaml" if scene == "drilling" else _parented_camera_scene(tmp_path)
    )
    v = Viewer(path, None, "mujoco", "127.0.0.1", _free_port())
    v.load()
    assert v.world is not None, v.findings
    v.start()
    try:
        w = v.world
        names = [c.name for c in w.cameras]
        assert names == (["cameraL_left", "cameraL_right"] if scene == "drilling" else ["cam"])
        with v.lock:
            w.run(0.1)
        for cam in w.cameras:
            eye, target, up = (np.array(x) for x in cam.view(w))
            fwd = (target - eye) / np.linalg.norm(target - eye)
            # where MuJoCo draws it from: the MJCF camera looks along its -z
            assert eye == pytest.approx(w.data.cam_xpos[cam.cam_id], abs=1e-9)
            assert fwd == pytest.approx(-w.data.cam_xmat[cam.cam_id].reshape(3, 3)[:, 2], abs=1e-9)
        if scene == "parented":
            (cam,) = w.cameras  # 1 m ahead of the box and 0.5 m up, the box turned 0.6 rad (resting on the ground)
            box = w.body("box").world_matrix()[:3, 3]
            expected = box + [np.cos(0.6), np.sin(0.6), 0.5]
            assert cam.view(w)[0] == pytest.approx(expected, abs=2e-3)
        else:  # the page opened on the scene from the side the left eye looks from
            eye0, target0, _ = (np.array(x) for x in w.cameras[0].view(w))
            init = v.server.initial_camera
            back = np.array(init.position) - np.array(init.look_at)
            assert back / np.linalg.norm(back) == pytest.approx(
                (eye0 - target0) / np.linalg.norm(eye0 - target0), abs=1e-3
            )
        v.draw_camera()
        img = np.asarray(v.camera_image.image)
        assert img.shape == (w.cameras[0].height, w.cameras[0].width, 3) and img.std() > 5
        assert v.camera_image.label.startswith(names[0] + " · RGB")
        small = dataclasses.replace(w.cameras[0], width=32, height=24).render(w)
        assert small["rgb"].shape == (24, 32, 3) and small["segmentation"].shape == (24, 32)
    finally:
        v.close()


# --- the first view -------------------------------------------------------------------------------


def _in_view(cam, points) -> np.ndarray:
    """Which ``points`` the page's first camera shows (its vertical field of view, as wide)."""
    eye, target, up = (np.array(x, float) for x in (cam.position, cam.look_at, cam.up))
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    rel = np.asarray(points, float) - eye
    depth = rel @ fwd
    t = np.tan(cam.fov / 2)
    return (depth > 0) & (np.abs(rel @ right) <= t * depth) & (np.abs(rel @ up) <= t * depth)


def _spread_scene(folder):
    """Five boxes 3 m apart, a 40 m static floor under them, and a camera a few cm from one box
    (as the challenge's endoscope looks at its phantom)."""
    text = "bodies: [BODY floor, BODY b0, BODY b1, BODY b2, BODY b3, BODY b4]\ncameras: [CAMERA close]\n"
    text += (
        "BODY floor:\n  name: floor\n  mass: 0.0\n"
        "  location: {position: {x: 0, y: 0, z: -0.05}, orientation: {r: 0, p: 0, y: 0}}\n"
        "  collision shape: BOX\n  collision geometry: {x: 40, y: 40, z: 0.1}\n"
        "  shape: BOX\n  geometry: {x: 40, y: 40, z: 0.1}\n"
    )
    for i, (x, y) in enumerate([(0, 0), (3, 0), (-3, 0), (0, 3), (0, -3)]):
        text += (
            f"BODY b{i}:\n  name: b{i}\n  mass: 1.0\n  inertia: {{ix: 0.01, iy: 0.01, iz: 0.01}}\n"
            f"  location: {{position: {{x: {x}, y: {y}, z: 0.1}}, orientation: {{r: 0, p: 0, y: 0}}}}\n"
            "  collision shape: BOX\n  collision geometry: {x: 0.2, y: 0.2, z: 0.2}\n"
            "  shape: BOX\n  geometry: {x: 0.2, y: 0.2, z: 0.2}\n"
        )
    text += (
        "CAMERA close:\n  name: close\n  location: {x: 0.0, y: -0.3, z: 0.35}\n"
        "  look at: {x: 0.0, y: 0.0, z: 0.1}\n  up: {x: 0.0, y: 0.0, z: 1.0}\n"
    )
    path = folder / "spread.yaml"
    path.write_text(text)
    return path


def test_the_first_view_frames_every_body_whatever_the_cameras(tmp_path):
    """The page opens on all five boxes, from the side the scene's close-up camera looks from;
    the 40 m floor is drawn but not framed (it would shrink the boxes to dots). The camera's own
    view, what the page opened on before, shows one box."""
    from adfkit.viewer.server import Viewer

    v = Viewer(_spread_scene(tmp_path), None, "pybullet", "127.0.0.1", _free_port())
    v.load()
    v.start()
    try:
        w = v.world
        corners = np.array(
            [
                sb.world_matrix()[:3, 3] + np.array([sx, sy, sz]) * 0.1
                for sb in w.bodies
                if sb.name != "floor"
                for sx in (-1, 1)
                for sy in (-1, 1)
                for sz in (-1, 1)
            ]
        )
        init = v.server.initial_camera
        assert _in_view(init, corners).all()
        back = np.array(init.position) - np.array(init.look_at)
        eye, target, _ = (np.array(x) for x in w.cameras[0].view(w))
        assert back / np.linalg.norm(back) == pytest.approx((eye - target) / np.linalg.norm(eye - target), abs=1e-6)
        assert np.linalg.norm(back) < 20  # framed on the boxes (~6 m across), not on the 40 m floor

        class Close:  # the scene camera's own view: the negative control
            position, look_at, up, fov = eye, target, (0, 0, 1), init.fov

        assert _in_view(Close, corners).sum() < len(corners) / 2
    finally:
        v.close()


def test_textures_are_drawn_tinted_by_the_adf_colour_and_a_missing_one_is_said_once(tmp_path):
    """A textured OBJ is drawn with its texture even where the body has an ADF colour (AMBF's
    material modulates the texture): the colour tints it. A texture its MTL names by an absolute
    path from another machine is one finding for the two bodies that use the mesh."""
    from PIL import Image

    from adfkit.adf import load
    from adfkit.viewer.geometry import visual_parts
    from adfkit.viewer.server import Viewer

    Image.new("RGB", (8, 8), (200, 100, 50)).save(tmp_path / "tex.png")
    obj = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
    # v/vt/vn: `f v/vt` faces crash AMBF, an error (obj-faces-crash-ambf) the viewer stops at
    obj += "f 1/1/1 3/3/1 2/2/1\nf 1/1/1 2/2/1 4/3/1\nf 1/1/1 4/3/1 3/2/1\nf 2/1/1 3/2/1 4/3/1\n"
    (tmp_path / "t.obj").write_text("mtllib t.mtl\nusemtl m\n" + obj)
    (tmp_path / "t.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd tex.png\n")
    (tmp_path / "far.obj").write_text("mtllib far.mtl\nusemtl m\n" + obj)
    (tmp_path / "far.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd /home/someone/drape.png\n")
    body = (
        "BODY {n}:\n  name: {n}\n  mass: 0.0\n  mesh: {mesh}\n{colour}"
        "  location: {{position: {{x: {x}, y: 0, z: 0}}, orientation: {{r: 0, p: 0, y: 0}}}}\n"
    )
    text = "bodies: [BODY plain, BODY tinted, BODY far1, BODY far2]\n"
    text += body.format(n="plain", mesh="t.obj", colour="", x=0)
    text += body.format(n="tinted", mesh="t.obj", colour="  color rgba: {r: 0.5, g: 1.0, b: 1.0, a: 1.0}\n", x=0.3)
    text += body.format(n="far1", mesh="far.obj", colour="", x=0.6)
    text += body.format(n="far2", mesh="far.obj", colour="", x=0.9)
    (tmp_path / "m.yaml").write_text(text)
    m = load(tmp_path / "m.yaml")
    (plain,) = visual_parts(m, m.body("BODY plain"))
    (tinted,) = visual_parts(m, m.body("BODY tinted"))
    assert plain.textured is not None and tinted.textured is not None
    assert list(tinted.textured.visual.material.diffuse[:3]) == [127, 255, 255]
    assert tinted.textured.visual.material.image.getpixel((0, 0)) == (200, 100, 50)
    (far,) = visual_parts(m, m.body("BODY far1"))
    assert far.textured is None  # its texture is not here: the flat colour
    v = Viewer(tmp_path / "m.yaml", None, "pybullet", "127.0.0.1", _free_port())
    v.load()
    v.start()
    try:
        said = [d for d in v.findings if d.rule == "view-missing-texture"]
        assert len(said) == 1, said
        assert (
            "/home/someone/drape.png (in far.mtl; an absolute path, from the machine the file was made on)"
            in said[0].message
        )
        assert said[0].location.file.endswith("m.yaml")
    finally:
        v.close()


def test_the_challenge_scene_opens_on_its_arms_and_textured_drape(browser, tmp_path):
    """The challenge's scene (corpus src/launch.yaml -l 6-11) opened as a grey close-up of the
    phantom (its endoscope's view, the drape drawn in its flat ADF grey: 1,200 colours, standard
    deviation 9); now on both arms and the phantom over the textured drape (measured 8,600
    colours, standard deviation 62)."""
    from conftest import CORPUS, require_corpus

    from adfkit.viewer.server import Viewer

    require_corpus()
    v = Viewer(CORPUS / "src" / "launch.yaml", [6, 7, 8, 9, 10, 11], "pybullet", "127.0.0.1", _free_port())
    v.load()
    address = v.start()
    try:
        w = v.world
        arms = np.array([sb.world_matrix()[:3, 3] for sb in w.bodies if not sb.static])
        assert _in_view(v.server.initial_camera, arms).all()
        page = _open(browser, address)
        page.wait_for_timeout(6000)
        pic = _canvas(page)
        assert len(np.unique(pic.reshape(-1, 3), axis=0)) > 4000 and pic.std() > 30, (
            len(np.unique(pic.reshape(-1, 3), axis=0)),
            pic.std(),
        )
        page.close()
    finally:
        v.close()
