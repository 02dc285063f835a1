"""A joint's `parent` and `child` found as AMBF finds them (adf-format.md §12.1-12.2): by the
bodies' keys (namespace + identifier), exact, else the one key holding the text, then the same
with the joint's namespace before it; never by a body's `name`, and an ambiguous text finds
nothing. Both engines make the joints AMBF makes (AMBF's side where a build is present)."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.model.tree import find_body  # noqa: E402
from adfkit.parity import ambf, loader  # noqa: E402
from adfkit.parity.traces import made_by  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

BUILD, WHY = ambf.available()

SPHERE = "collision shape: SPHERE\n  collision geometry: {radius: 0.01}"

MODEL = f"""\
namespace: /ambf/env/edge
bodies: [BODY anchor, BODY swing, BODY Entry1, BODY Entry10, BODY l1]
joints: [JOINT by-key, JOINT ambiguous, JOINT by-name]
BODY anchor:
  name: anchor
  mass: 0
  {SPHERE}
  location: {{position: {{x: 0, y: 0, z: 1.0}}}}
BODY swing:
  name: swing
  mass: 0.2
  {SPHERE}
  location: {{position: {{x: 0.1, y: 0, z: 0.9}}}}
BODY Entry1:
  name: Entry1
  mass: 0
  {SPHERE}
  location: {{position: {{x: 0.6, y: 0.3, z: 0.1}}}}
BODY Entry10:
  name: Entry10
  mass: 0.05
  {SPHERE}
  location: {{position: {{x: 0.6, y: 0.3, z: 0.3}}}}
BODY l1:
  name: link one
  mass: 0.05
  {SPHERE}
  location: {{position: {{x: -0.5, y: 0.0, z: 0.5}}}}
JOINT by-key:
  name: by-key
  parent: /ambf/env/edgeBODY anchor
  child: edgeBODY swing
  type: revolute
  parent pivot: {{x: 0.0, y: 0, z: -0.1}}
  child pivot: {{x: -0.1, y: 0, z: 0}}
  parent axis: {{x: 0, y: 1, z: 0}}
  child axis: {{x: 0, y: 1, z: 0}}
JOINT ambiguous:
  name: ambiguous
  parent: Entry1
  child: BODY Entry10
  type: p2p
  parent pivot: {{x: 0, y: 0, z: 0.1}}
  child pivot: {{x: 0, y: 0, z: -0.1}}
  parent axis: {{x: 0, y: 0, z: 1}}
  child axis: {{x: 0, y: 0, z: 1}}
JOINT by-name:
  name: by-name
  parent: BODY anchor
  child: link one
  type: p2p
  parent pivot: {{x: 0, y: 0, z: -0.5}}
  child pivot: {{x: 0, y: 0, z: 0}}
  parent axis: {{x: 0, y: 0, z: 1}}
  child axis: {{x: 0, y: 0, z: 1}}
"""


def _model(tmp_path):
    path = tmp_path / "edge.yaml"
    path.write_text(MODEL)
    return path


def test_find_body_goes_by_keys_as_ambf(tmp_path):
    (model,) = load_scene(_model(tmp_path)).all_models()
    joints = {j.identifier: j for j in model.joints}
    by_key = joints["JOINT by-key"]
    assert find_body(model, by_key.parent, by_key).identifier == "BODY anchor"  # the whole key
    assert find_body(model, by_key.child, by_key).identifier == "BODY swing"  # a unique part of it
    assert find_body(model, "Entry1") is None  # in two keys: AMBF finds nothing
    assert find_body(model, "BODY Entry1") is None  # still in two keys ("BODY Entry10")
    assert find_body(model, "BODY Entry1", joints["JOINT ambiguous"]) is not None  # namespaced: exact
    assert find_body(model, "link one") is None  # a `name` is not a key


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_both_engines_make_the_joints_ambf_makes(tmp_path, engine):
    path = _model(tmp_path)
    opt = Options(visuals=False, ground=False)
    opt.bodies = "ambf"
    world = open_world(load_scene(path), opt, engine=engine)
    try:
        made = sorted(made_by(world)["joint"])
    finally:
        world.close()
    assert made == ["/ambf/env/edgeby-key"]  # the ambiguous joint and the one by name are skipped
    if BUILD is not None:
        r = loader.check_file(path, BUILD)
        assert r.ambf_counts["joint"] == 1 and r.agree, r.as_json()


SELF_JOINT = f"""\
namespace: /ambf/env/
bodies: [BODY a]
joints: [JOINT aa]
BODY a:
  name: a
  mass: 1.0
  {SPHERE}
  location: {{position: {{x: 0, y: 0, z: 0.2}}}}
JOINT aa:
  name: aa
  parent: BODY a
  child: BODY a
  type: revolute
  parent pivot: {{x: 0, y: 0, z: 0}}
  child pivot: {{x: 0, y: 0, z: 0}}
  parent axis: {{x: 0, y: 0, z: 1}}
  child axis: {{x: 0, y: 0, z: 1}}
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_joint_of_a_body_to_itself_is_listed_as_ambf_lists_it_and_moves_nothing(tmp_path, engine):
    # AMBF makes it (its joint list has it) and it moves nothing; both engines left it out and
    # `adfkit parity` said "only in AMBF: joint" (PyBullet printed its own createConstraint failure)
    path = tmp_path / "self.yaml"
    path.write_text(SELF_JOINT)
    opt = Options(visuals=False, ground=False)
    opt.bodies = "ambf"
    world = open_world(load_scene(path), opt, engine=engine)
    try:
        assert made_by(world)["joint"] == ["/ambf/env/aa"]
        assert world.joints_made == []  # nothing built for it
    finally:
        world.close()
    if BUILD is not None:
        r = loader.check_file(path, BUILD)
        assert r.ambf_counts["joint"] == 1 and r.agree, r.as_json()
