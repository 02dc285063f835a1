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

    png = page.screenshot(clip={"x": 0, "y": 160, "width": 900, "height": 600})
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
        else:  # the page opened where the left eye is
            eye0, _, _ = w.cameras[0].view(w)
            assert v.server.initial_camera.position == pytest.approx(eye0, abs=1e-3)
        v.draw_camera()
        img = np.asarray(v.camera_image.image)
        assert img.shape == (w.cameras[0].height, w.cameras[0].width, 3) and img.std() > 5
        assert v.camera_image.label.startswith(names[0] + " · RGB")
        small = dataclasses.replace(w.cameras[0], width=32, height=24).render(w)
        assert small["rgb"].shape == (24, 32, 3) and small["segmentation"].shape == (24, 32)
    finally:
        v.close()
