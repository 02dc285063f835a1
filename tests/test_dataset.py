"""The dataset writer and loader (adfkit/dataset): a short recording written and read back,
and the segmentation colouriser."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT

from adfkit.dataset import colourise, load

pytest.importorskip("pybullet")

BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"


def test_colourise_gives_distinct_colours_and_black_background():
    labels = np.array([[-1, 0, 1], [2, 3, 40]])
    img = colourise(labels)
    assert img.dtype == np.uint8 and img.shape == (2, 3, 3)
    assert (img[0, 0] == 0).all()
    colours = {tuple(c) for c in img.reshape(-1, 3)[1:]}
    assert len(colours) == 5 and all(max(c) >= 150 for c in colours)


def test_write_and_load_round_trip(tmp_path):
    if not BUNDLED.is_file():
        pytest.skip("sample_scenes/suturing is not in this checkout")
    from adfkit.adf import load_scene
    from adfkit.dataset.writer import DatasetWriter
    from adfkit.runner import Options, open_world

    world = open_world(load_scene(BUNDLED), Options())
    try:
        writer = DatasetWriter(world, tmp_path / "ds", cameras=[world.cameras[0].name])
        needle = world.body("Needle")
        written = []
        for step in (5, 10):
            world.step(5)
            written += writer.write(step, {"needle": needle.world_matrix(), "psms": {}}, "test")
        writer.close()
        frames = load(tmp_path / "ds")
        assert [f.step for f in frames] == [5, 10] and frames[0].camera == world.cameras[0].name
        cam = world.cameras[0]
        f = frames[-1]
        rgb, depth, labels = f.rgb(), f.depth(), f.labels()
        assert rgb.shape == (cam.height, cam.width, 3) and depth.dtype == np.float32
        assert labels.shape == depth.shape and labels.min() >= -1 and labels.max() < len(world.bodies)
        hit = labels >= 0
        assert hit.any() and np.isfinite(depth[hit]).all() and (depth[hit] > 0).all()
        assert np.allclose(f.K, cam.intrinsics())
        r = f.T_world_camera[:3, :3]
        assert np.allclose(r.T @ r, np.eye(3), atol=1e-9)
        assert np.allclose(f.needle, np.array(written[-1]["needle"]))
        # the labelled needle pixels are where the needle projects through K and the extrinsics
        key = json.loads((tmp_path / "ds" / "labels.json").read_text())
        idx = next(int(k) for k, v in key.items() if v.endswith("Needle"))
        if (labels == idx).any():
            c = np.linalg.inv(f.T_world_camera) @ np.r_[f.needle[:3, 3], 1.0]
            u, v = (f.K @ (c[:3] / c[2]))[:2]
            ys, xs = np.nonzero(labels == idx)
            assert abs(xs.mean() - u) < 25 and abs(ys.mean() - v) < 25
        assert (f.seg_color()[~hit] == 0).all()
    finally:
        world.close()


def test_depth_counts_are_0_1_mm_and_nothing_is_zero():
    from adfkit.dataset.writer import DEPTH_UNIT_M, depth_to_png16

    depth = np.array([[np.inf, np.nan, 0.0, 1e-6], [0.12344, 0.12356, 6.5535, 2.0]], dtype=np.float32)
    counts = depth_to_png16(depth)
    assert counts.dtype == np.uint16
    assert counts.tolist() == [[0, 0, 1, 1], [1234, 1236, 65535, 20000]]  # a hit is never "nothing"
    assert depth_to_png16(np.array([[0.5, 6.6]], dtype=np.float32)) is None  # beyond 16 bits: kept as float32
    assert depth_to_png16(np.full((2, 2), np.inf, dtype=np.float32)).tolist() == [[0, 0], [0, 0]]
    assert DEPTH_UNIT_M == 1e-4


def test_a_recorded_frame_reads_back_as_rendered(tmp_path):
    """The bundled scene's camera frame, rendered, written and loaded: RGB and labels exactly,
    depth to half a 0.1 mm count, nothing stays nothing; and the bytes a camera frame takes."""
    if not BUNDLED.is_file():
        pytest.skip("sample_scenes/suturing is not in this checkout")
    from adfkit.adf import load_scene
    from adfkit.dataset.writer import DEPTH_UNIT_M, DatasetWriter
    from adfkit.runner import Options, open_world

    world = open_world(load_scene(BUNDLED), Options())
    try:
        world.step(5)
        cam = world.cameras[0]
        want = cam.render(world)  # the world does not move between this and the writer's render
        writer = DatasetWriter(world, tmp_path / "ds", cameras=[cam.name])
        writer.write(5, {"needle": world.body("Needle").world_matrix(), "psms": {}}, "test")
        writer.close()
    finally:
        world.close()
    (f,) = load(tmp_path / "ds")
    assert f.paths["depth"].endswith("_depth.png")
    assert (f.rgb() == want["rgb"]).all()
    assert (f.labels() == want["segmentation"]).all()
    depth, seen = f.depth(), np.isfinite(want["depth"])
    assert seen.any() and (np.isfinite(depth) == seen).all()
    assert np.abs(depth[seen].astype(np.float64) - want["depth"][seen]).max() <= DEPTH_UNIT_M / 2 + 1e-7
    frame_bytes = sum((tmp_path / "ds" / f.paths[k]).stat().st_size for k in ("rgb", "depth", "seg", "seg_color"))
    assert frame_bytes < 500_000, frame_bytes  # was 1.24 MB with float32 .npy depth
