"""The hinges of a light body joined by limits alone in the MuJoCo world (runner/mujoco/
free_hinges.py): the bundled suture thread's without its springs, whose elements (1.5e-8 kg·m²)
pushed MuJoCo's soft limits 2 rad past their ±30° stops and through the hinges' gimbal lock as
the needle was lifted."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import adfkit.runner.mujoco.build as build
from adfkit.adf import load_scene
from adfkit.model import AxesGains, Vec3
from adfkit.runner import Options, open_world
from adfkit.runner.mujoco import free_hinges
from adfkit.scenes.parity import write_parity

BUNDLED = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"


def _springless():
    """The bundled scene with its thread's joints left without stiffness and damping, their
    ±30° limits kept."""
    scene = load_scene(BUNDLED, None, [])
    zero = Vec3(0.0, 0.0, 0.0)
    for m in scene.all_models():
        for j in m.joints:
            if "Thread" in j.child and j.type == "six dof spring":
                j.stiffness = AxesGains(linear=zero, angular=zero)
                j.damping = AxesGains(linear=zero, angular=zero)
    return scene


def _hinges(world, word: str) -> list[int]:
    m = world.model
    return [j for j in range(m.njnt) if word in m.joint(j).name and "#hinge" in m.joint(j).name]


def test_the_bundled_threads_hinges_are_held_and_heavier_bodies_keep_the_files():
    world = open_world(_springless(), Options(renderer="tiny"), engine="mujoco")
    try:
        m = world.model
        thread = _hinges(world, "Thread_")
        assert len(thread) == 117  # 39 joints, three hinges each
        for j in thread:
            dof = m.jnt_dofadr[j]
            assert m.dof_armature[dof] == free_hinges.FREE_HINGE_ARMATURE
            assert m.dof_damping[dof] == free_hinges.FREE_HINGE_DAMPING
            assert m.jnt_solimp[j, 0] == free_hinges.LIMIT_IMPEDANCE
            assert m.jnt_solref[j, 0] == pytest.approx(free_hinges.LIMIT_TIMECONST_STEPS * world.dt)
    finally:
        world.close()


def test_a_heavy_pendulum_on_free_hinges_keeps_mujocos_own(tmp_path):
    """The parity scene's six-dof and cone-twist pendulums (0.3 kg bobs, 1e-3 kg·m², hinges with
    neither stiffness nor damping) are not light."""
    launch = write_parity(tmp_path)
    world = open_world(load_scene(launch, [6], []), Options(renderer="tiny"), engine="mujoco")
    try:
        m = world.model
        bobs = _hinges(world, "sixbob#") + _hinges(world, "conebob#")
        assert len(bobs) == 5
        for j in bobs:
            assert m.dof_damping[m.jnt_dofadr[j]] == 0.0
            assert m.dof_armature[m.jnt_dofadr[j]] < free_hinges.FREE_HINGE_ARMATURE
            assert m.jnt_solimp[j, 0] != free_hinges.LIMIT_IMPEDANCE
    finally:
        world.close()


def _lift(held: bool, monkeypatch) -> tuple[float, int]:
    """The springless bundled scene settled 1 s, then its needle lifted 45 mm at 30 mm/s (moved kinematically,
    as a grasp carries it): the thread's largest hinge angle and the instabilities MuJoCo met."""
    if not held:
        monkeypatch.setattr(build, "is_free_hinge", lambda *a: False)
    world = open_world(_springless(), Options(renderer="tiny"), engine="mujoco")
    try:
        m, d = world.model, world.data
        needle = next(j for j in range(m.njnt) if m.joint(j).name.endswith("Needle_free"))
        qa, va = m.jnt_qposadr[needle], m.jnt_dofadr[needle]
        thread = m.jnt_qposadr[_hinges(world, "Thread_")]
        world.step(250)
        worst, v, dt = 0.0, 0.03, world.dt * world.opt.control_substeps
        for _ in range(int(round(0.045 / v / dt))):
            d.qpos[qa + 2] += v * dt
            d.qvel[va : va + 6] = [0.0, 0.0, v, 0.0, 0.0, 0.0]
            world.step(1)
            if world.watch.events:
                break
            worst = max(worst, float(np.max(np.abs(d.qpos[thread]))))
        return worst, len(world.watch.events)
    finally:
        world.close()


@pytest.mark.slow
def test_the_lifted_threads_joints_stay_at_their_limits(monkeypatch):
    """Measured: within 0.63 rad of the ±0.52 rad stops, stable; with the file's hinges as MuJoCo
    plays them by default (the negative control) 4.96 rad and a NaN 1.3 s into the lift."""
    worst, unstable = _lift(True, monkeypatch)
    assert unstable == 0 and worst < 0.7, (worst, unstable)
    worst, unstable = _lift(False, monkeypatch)
    assert unstable or worst > 1.0, (worst, unstable)
