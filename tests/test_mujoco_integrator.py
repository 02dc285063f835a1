"""The MuJoCo runner steps a rigid scene whose only velocity-dependent force is its dofs' damping
with MuJoCo's Euler integrator, which gives implicit-fast's result without its derivative
(runner/mujoco/integrator.py): the same trajectory to round-off, where another velocity force
(a velocity actuator) makes the two part by far more and keeps implicit-fast."""

from __future__ import annotations

import mujoco
import numpy as np

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world
from adfkit.runner.mujoco.integrator import integrator_for

_ARM = """
<mujoco>
  <option timestep="0.001" integrator="implicitfast"/>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <body pos="0 0 0.5">
      <joint name="hinge" type="hinge" axis="0 1 0" damping="0.4"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/>
      <body pos="0.3 0 0">
        <joint type="hinge" axis="0 1 0" damping="0.2"/>
        <geom type="box" pos="0.1 0 0" size="0.1 0.03 0.03" mass="0.5"/>
      </body>
    </body>
    <body pos="0.2 0.3 0.3">
      <freejoint/>
      <geom type="box" size="0.04 0.04 0.04" mass="0.2"/>
    </body>
  </worldbody>
  {actuator}
</mujoco>
"""
_VELOCITY_ACTUATOR = '<actuator><velocity joint="hinge" kv="0.5"/></actuator>'


def _model(actuator: str = "") -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(_ARM.replace("{actuator}", actuator))


def _trajectory(model: mujoco.MjModel, integrator: int, steps: int = 600) -> np.ndarray:
    """qpos after ``steps`` physics steps: the arm swinging down and hitting the floor, the cube
    falling onto it (contacts and damping both)."""
    model.opt.integrator = integrator
    data = mujoco.MjData(model)
    data.qvel[0] = 2.0
    mujoco.mj_step(model, data, steps)
    return np.array(data.qpos)


def test_damping_alone_steps_with_euler_as_implicit_fast():
    """The two solve one matrix (measured: 2e-16 apart after 0.6 s of swinging, contacts and
    all; the velocity actuator below parts them by 4e-4)."""
    m = _model()
    assert integrator_for(m) == mujoco.mjtIntegrator.mjINT_EULER
    euler = _trajectory(m, mujoco.mjtIntegrator.mjINT_EULER)
    fast = _trajectory(m, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
    assert np.max(np.abs(euler - fast)) < 1e-12
    assert abs(euler[0]) > 0.3  # the arm did swing


def test_a_velocity_actuator_keeps_implicit_fast_where_euler_would_differ():
    """Control: a velocity actuator's -kv·v is in implicit-fast's derivative, not in Euler's
    damping: the trajectories part, and the runner keeps implicit-fast."""
    m = _model(_VELOCITY_ACTUATOR)
    assert integrator_for(m) == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    euler = _trajectory(m, mujoco.mjtIntegrator.mjINT_EULER)
    fast = _trajectory(m, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
    assert np.max(np.abs(euler - fast)) > 1e-5


def test_no_damping_or_another_integrator_is_kept():
    m = _model()
    m.dof_damping[:] = 0.0
    assert integrator_for(m) == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    m = _model()
    m.opt.viscosity = 1e-3  # fluid forces depend on velocity too
    assert integrator_for(m) == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    m = _model()
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_DISCRETE  # a flex's
    assert integrator_for(m) == mujoco.mjtIntegrator.mjINT_DISCRETE


def test_the_runner_picks_euler_for_damped_joints(tmp_path):
    """The parity scene's bobs (damped joints: Euler) and its dropped cubes (free bodies, no
    damping: implicit-fast), as the runner builds them."""
    from adfkit.scenes.parity import write_parity

    launch = write_parity(tmp_path)
    for index, integrator in ((6, mujoco.mjtIntegrator.mjINT_EULER), (3, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)):
        w = open_world(load_scene(launch, [index]), Options(visuals=False), engine="mujoco")
        try:
            assert w.model.opt.integrator == integrator
        finally:
            w.close()
