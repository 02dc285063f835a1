"""Six-dof springs in the MuJoCo world as AMBF's Bullet plays them (runner/mujoco/spring_rows.py,
Options.springs "ambf"): explicit, the damper alone where it opposes the spring and outweighs it,
at every 1 ms physics step, where Bullet does not cap the spring; and a resting tree still sleeps."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from test_runner_springs import SPRING_SCENE

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

INERTIA, X0, DT, SUB = 1e-4, 0.2, 1e-3, 4


def _twist_after_one_control_step(tmp_path, springs: str, k: float, c: float) -> tuple[float, float]:
    """The bob of test_runner_springs' scene (a six-dof spring about z from a static post, its pivot
    at the bob's centre of mass: Bullet's m is the bob's inertia) turned X0 about z at rest in
    MuJoCo: its twist and twist rate after one control step (4 physics steps of 1 ms)."""
    path = tmp_path / f"spring-{springs}-{k:g}-{c:g}.yaml"
    path.write_text(SPRING_SCENE.format(i=INERTIA, k=k, c=c))
    world = open_world(
        load_scene(path, None, []), Options(ground=False, visuals=False, springs=springs), engine="mujoco"
    )
    try:
        m, d = world.model, world.data
        jid = next(j for j in range(m.njnt) if m.joint(j).name.endswith("#hingez"))
        d.qpos[m.jnt_qposadr[jid]] = X0
        mujoco.mj_forward(m, d)
        world.step(1)
        return float(d.qpos[m.jnt_qposadr[jid]]), float(d.qvel[m.jnt_dofadr[jid]])
    finally:
        world.close()


def test_ambfs_springs_are_explicit_and_bounded_at_every_physics_step(tmp_path):
    """The torque -k·x - c·w at each 1 ms physics step, semi-implicit Euler, the damper alone where
    it opposes the spring and outweighs it (the second case: at c = I/dt, Bullet's cap, it stops the
    bob at once), as test_runner_springs asks of PyBullet. MuJoCo's own stiffness and damping (its
    damping implicit) land elsewhere: the control. A spring stiffer than Bullet's cap, I/(16·dt²),
    keeps MuJoCo's own (capped_joints)."""
    k_cap, c_cap = INERTIA / (16 * DT * DT), INERTIA / DT
    for k, c in ((0.5 * k_cap, 0.3 * c_cap), (0.5 * k_cap, c_cap)):
        x, w = X0, 0.0
        for _ in range(SUB):  # by hand
            spring, damper = -k * x, -c * w
            outweighs = spring * damper < 0 and abs(damper) > abs(spring)
            w += (damper if outweighs else spring + damper) * DT / INERTIA
            x += w * DT
        got_x, got_w = _twist_after_one_control_step(tmp_path, "ambf", k, c)
        # the hinge's armature (1e-9 kg m², build.SPRING_HINGE_ARMATURE) is 1e-5 of the inertia
        assert got_x == pytest.approx(x, rel=1e-4) and got_w == pytest.approx(w, rel=1e-4, abs=1e-4), (k, c)
        own_x, _ = _twist_after_one_control_step(tmp_path, "implicit", k, c)
        assert abs(own_x - x) > 1e-3, (k, c, own_x, x)
    stiff = (2 * k_cap, 0.3 * c_cap)
    assert _twist_after_one_control_step(tmp_path, "ambf", *stiff) == _twist_after_one_control_step(
        tmp_path, "implicit", *stiff
    )


def test_a_resting_sprung_tree_still_sleeps(tmp_path):
    """A damped bob at rest on its spring gets no force (every byte 0): MuJoCo lets its tree sleep,
    as it does with the spring and damper in the model. A damper force written at rest (-0.0, or
    -c·v at a velocity below the sleep tolerance) kept the suturing set's thread awake (74 contacts
    a step against 11, 2.5x the stepping time)."""
    path = tmp_path / "rest.yaml"
    path.write_text(SPRING_SCENE.format(i=INERTIA, k=0.01, c=1e-3))
    world = open_world(
        load_scene(path, None, []), Options(ground=False, visuals=False, springs="ambf"), engine="mujoco"
    )
    try:
        if not world.sleep:
            pytest.skip("this MuJoCo has no island sleeping")
        assert world.spring_rows is not None
        world.run(1.0)
        assert world.data.ntree_awake == 0
        assert not np.any(world.data.qfrc_applied)
    finally:
        world.close()
