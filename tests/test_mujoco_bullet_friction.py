"""MuJoCo's contacts under AMBF's bodies (adfkit run / parity) carry Bullet's combined frictions
(btManifoldResult: the product of the two bodies' frictions, rolling r1·f2 + r2·f1), through the
geoms' own frictions where MuJoCo's rule gives the same and explicit pairs where it does not
(runner/mujoco/contacts.py); the explicit pairs heed set_collision."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.model.semantics import DEFAULT_FRICTION_ROLLING, DEFAULT_FRICTION_STATIC  # noqa: E402
from adfkit.runner import Options  # noqa: E402
from adfkit.runner.mujoco.world import MujocoWorld  # noqa: E402
from adfkit.scenes.parity import write_parity  # noqa: E402


def _ramp(tmp_path, bodies: str) -> MujocoWorld:
    """The parity ramp (-l 8): two balls and a cylinder on a static 25° ramp over the floor; the
    ball `rolling` has no rolling friction of its own (the others and the ramp AMBF's 0.5, 0.01)."""
    scene = load_scene(write_parity(tmp_path), [8], [])
    return MujocoWorld(scene, Options(visuals=False, control_substeps=4, bodies=bodies))


def _surface(sb) -> tuple[float, float]:
    fr = sb.body.friction
    static = fr.static if fr is not None and fr.static is not None else DEFAULT_FRICTION_STATIC
    rolling = fr.rolling if fr is not None and fr.rolling is not None else DEFAULT_FRICTION_ROLLING
    return static, rolling


def _contacts(world, seconds: float) -> list[tuple[str, str, float, float, float, float]]:
    """(body, body, sliding, rolling friction, Bullet's sliding, Bullet's rolling) of each contact
    of each control step over ``seconds``."""
    out = []
    for _ in range(round(seconds / (world.dt * world.opt.control_substeps))):
        world.step(1)
        out.extend(_now(world))
    return out


def _now(world) -> list[tuple[str, str, float, float, float, float]]:
    m, d = world.model, world.data
    out = []
    for c in d.contact[: d.ncon]:
        a = world._body_of_id.get(int(m.geom_bodyid[c.geom1]))
        b = world._body_of_id.get(int(m.geom_bodyid[c.geom2]))
        if a is None or b is None:
            continue
        (fa, ra), (fb, rb) = _surface(a), _surface(b)
        out.append((a.key, b.key, float(c.friction[0]), float(c.friction[3]), fa * fb, ra * fb + rb * fa))
    return out


def test_contacts_on_the_ramp_carry_bullets_combined_frictions(tmp_path):
    """Each ball and the cylinder on the ramp: sliding 0.5 x 0.5 = 0.25 (MuJoCo's rule on 0.5: 0.5),
    rolling 0.01 x 0.5 + 0.01 x 0.5 = 0.01 and, for the ball without its own, 0.005 (MuJoCo's own
    rule: 0.01, the larger). Control: Options' default bodies keep MuJoCo's own (the lower of the
    two: 1, MuJoCo's default, where the file gives none; the ball's 0.5)."""
    world = _ramp(tmp_path, "ambf")
    try:
        seen = _contacts(world, 0.3)
    finally:
        world.close()
    keys = {k for a, b, *_ in seen for k in (a, b)}
    assert {f"/ambf/env/ramp/BODY {n}" for n in ("ball", "roller", "rolling")} <= keys, seen
    for a, b, slide, roll, want_slide, want_roll in seen:
        assert slide == pytest.approx(want_slide, abs=1e-9), (a, b, slide)
        assert roll == pytest.approx(want_roll, abs=1e-9), (a, b, roll)
    assert {round(s[3], 9) for s in seen} == {0.01, 0.005}, seen

    world = _ramp(tmp_path, "pybullet")
    try:
        own = _contacts(world, 0.3)
    finally:
        world.close()
    assert own and all(s[2] in (0.5, 1.0) and s[2] != s[4] for s in own), own


def _touching(world, a, b) -> bool:
    mujoco.mj_forward(world.model, world.data)
    return any({x, y} == {a.key, b.key} for x, y, *_ in _now(world))


def test_set_collision_turns_an_explicit_pair_off_and_on(tmp_path):
    """On the ramp the ball without rolling friction meets the floor by an explicit pair (the
    ramp's classes decide the rest: the floor's friction 0.8 with the ball's rolling 0 is no
    class's combination). Put into the floor, the ball touches it; turned off, the pair makes no
    contact; turned on again, it has its margin back and touches."""
    world = _ramp(tmp_path, "ambf")
    try:
        m, d = world.model, world.data
        floor, ball = world.body("BODY Floor"), world.body("BODY rolling")
        b1, b2 = m.geom_bodyid[m.pair_geom1], m.geom_bodyid[m.pair_geom2]
        assert (((b1 == floor.id) & (b2 == ball.id)) | ((b1 == ball.id) & (b2 == floor.id))).any()
        margins = np.array(m.pair_margin)
        adr = m.jnt_qposadr[m.body_jntadr[ball.id]]
        d.qpos[adr : adr + 3] = [0.5, 0.75, 0.02]  # 1 cm into the floor, clear of the ramp
        assert _touching(world, ball, floor)
        world.set_collision(ball, floor, False)
        assert not _touching(world, ball, floor)
        world.set_collision(ball, floor, True)
        assert np.array_equal(np.array(m.pair_margin), margins)
        assert _touching(world, ball, floor)
    finally:
        world.close()
