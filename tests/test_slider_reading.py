"""A slider under a position command as AMBF's controller reads it: btSliderConstraint::
getLinearPos returns the position cached when the last physics step's solve began, a physics step
old (a hinge's angle is read fresh), so AMBF's D term sees no motion on the step after its first
kick. adfkit read the slider fresh: a 0.4 kg block on a vertical slider told to rise 0.1 m by
P 200, D 5 stood 1.76 mm from AMBF's at 0.08 s; read a step old, 0.000 mm over 1.5 s. AMBF's
side skips, with the reason, where no AMBF build is present."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf, session  # noqa: E402

BUILD, WHY = ambf.available()

SLIDER = """\
namespace: /ambf/env/
bodies: [BODY base, BODY slide]
joints: [JOINT base-slide]
BODY base:
  name: base
  mass: 0
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
  location: {position: {x: 0, y: 0, z: 0.5}}
BODY slide:
  name: slide
  mass: 0.4
  collision shape: BOX
  collision geometry: {x: 0.05, y: 0.05, z: 0.05}
  location: {position: {x: 0.0, y: 0.2, z: 0.5}}
JOINT base-slide:
  name: base-slide
  parent: BODY base
  child: BODY slide
  type: prismatic
  parent pivot: {x: 0.0, y: 0.2, z: 0}
  child pivot: {x: 0, y: 0, z: 0}
  parent axis: {x: 0, y: 0, z: 1}
  child axis: {x: 0, y: 0, z: 1}
  joint limits: {low: -0.2, high: 0.2}
  controller: {P: 200, D: 5}
"""


@pytest.mark.skipif(BUILD is None, reason=WHY)
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_slider_under_a_position_command_follows_ambfs_step_old_reading(tmp_path, engine):
    (tmp_path / "slider.yaml").write_text(SLIDER)
    (tmp_path / "c.txt").write_text("0.0, position, base-slide, 0.1\n")
    req = session.Request(
        Path(tmp_path / "slider.yaml"),
        None,
        BUILD,
        seconds=0.5,
        every=0.005,
        engines=(engine,),
        commands=tmp_path / "c.txt",
    )
    c = session.run(req, progress=False).comparisons[0]
    slide = next(g for g in c.bodies if g.name.endswith("slide"))
    assert slide.max_position < 0.05e-3, slide.max_position  # read fresh: 1.76 mm at 0.08 s
