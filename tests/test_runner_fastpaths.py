"""The runner's batched hot paths give what the one-at-a-time code gave (issue 17): spring
states read in one pass equal each body's own state, and the segmentation lookup table labels
every pixel as the per-body loop did."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from test_run_bad_inputs import SPRING_MODEL  # noqa: E402

from adfkit.adf.scene import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.pybullet.cameras import label_image  # noqa: E402


@pytest.fixture
def springy_world(tmp_path):
    f = tmp_path / "springy.yaml"
    f.write_text(SPRING_MODEL)
    world = open_world(load_scene(f, None, []), Options())
    yield world
    world.close()


def test_spring_states_in_one_pass_equal_each_bodys_state(springy_world):
    from adfkit.runner.rotations import quat_to_matrix

    springy_world.run(0.2)
    s = springy_world.springs
    assert {b.link for b in s.bodies} >= {-1, 0}  # free bodies and a multibody link
    pos, rot, lv, av = s.states()
    one = [b.state() for b in s.bodies]
    assert np.array_equal(pos, np.array([o[0] for o in one]))
    assert np.array_equal(rot, quat_to_matrix(np.array([o[1] for o in one])))
    assert np.array_equal(lv, np.array([o[2] for o in one]))
    assert np.array_equal(av, np.array([o[3] for o in one]))


def _labels_one_by_one(world, seg):
    """The labelling loop the lookup table replaced."""
    labels = np.full(seg.shape, -1, dtype=np.int32)
    valid = seg >= 0
    uid = seg & ((1 << 24) - 1)
    link = (seg >> 24) - 1
    index = {(sb.uid, sb.link): i for i, sb in enumerate(world.bodies)}
    for u, l in set(zip(uid[valid].tolist(), link[valid].tolist())):
        i = index.get((u, l))
        if i is not None:
            labels[(uid == u) & (link == l) & valid] = i
    return labels


def test_segmentation_lookup_table_labels_as_the_loop_did(springy_world):
    import pybullet as pb

    w = springy_world
    vm = pb.computeViewMatrix([1.5, 1.5, 1.0], [0, 0, 0.4], [0, 0, 1], physicsClientId=w.cid)
    pm = pb.computeProjectionMatrixFOV(60, 4 / 3, 0.01, 10, physicsClientId=w.cid)
    seg = pb.getCameraImage(
        80,
        60,
        vm,
        pm,
        renderer=pb.ER_TINY_RENDERER,
        flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
        physicsClientId=w.cid,
    )[4]
    seg = np.reshape(np.asarray(seg, dtype=np.int64), (60, 80))
    seg[0, 0] = (7 << 24) | 999  # a uid and link that are no body
    labels = label_image(w, seg)
    assert np.array_equal(labels, _labels_one_by_one(w, seg))
    assert set(np.unique(labels).tolist()) >= {-1, 0, 1, 2}  # background and the three bodies
