"""The MuJoCo engine (adfkit/runner/mj/) against physics and against the PyBullet engine: real
MuJoCo and real PyBullet, no mocks."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from conftest import CORPUS, ROOT, box_camera_model, require_corpus

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options  # noqa: E402
from adfkit.runner.mujoco.world import MujocoWorld  # noqa: E402
from adfkit.runner.psm import PSM  # noqa: E402
from adfkit.runner.pybullet.world import PyBulletWorld  # noqa: E402

ENGINES = [MujocoWorld, PyBulletWorld]
G = 9.81


def _model(tmp_path, text: str, name: str = "model.yaml"):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return load_scene(p)


def _pose(x=0.0, y=0.0, z=0.0, p=0.0):
    return f"{{position: {{x: {x}, y: {y}, z: {z}}}, orientation: {{r: 0.0, p: {p}, y: 0.0}}}}"


# ---- pendulum -----------------------------------------------------------------------------
L, M, I_C, THETA0 = 0.3, 1.0, 1e-3, 0.3


def pendulum_model() -> str:
    """A 1 kg bob (I = 1e-3 kg·m²) on a massless hinge 0.3 m below a static pivot, about y,
    released 0.3 rad from the vertical; no motor (max motor impulse 0), no damping."""
    x, z = L * math.sin(THETA0), -L * math.cos(THETA0)
    return f"""
bodies: [BODY pivot, BODY bob]
joints: [JOINT pivot-bob]
BODY pivot:
  name: pivot
  mass: 0.0
  location: {_pose()}
  collision shape: SPHERE
  collision geometry: {{radius: 0.01}}
BODY bob:
  name: bob
  mass: {M}
  inertia: {{ix: {I_C}, iy: {I_C}, iz: {I_C}}}
  location: {_pose(x=x, z=z, p=-THETA0)}
  collision shape: SPHERE
  collision geometry: {{radius: 0.02}}
  damping: {{linear: 0.0, angular: 0.0}}
JOINT pivot-bob:
  name: pivot-bob
  parent: BODY pivot
  child: BODY bob
  type: revolute
  parent pivot: {{x: 0.0, y: 0.0, z: 0.0}}
  child pivot: {{x: 0.0, y: 0.0, z: {L}}}
  parent axis: {{x: 0.0, y: 1.0, z: 0.0}}
  child axis: {{x: 0.0, y: 1.0, z: 0.0}}
  max motor impulse: 0.0
"""


def _swing(world, seconds: float):
    """Bob angle from the vertical (about +y) at every control step."""
    bob = world.body("bob")
    out = []
    for _ in range(int(round(seconds / (world.dt * world.opt.control_substeps)))):
        world.step(1)
        p = bob.com_position()
        out.append((world.sim_time, math.atan2(p[0], -p[2]), np.array(p)))
    return out


def _period(samples) -> float:
    """Mean time between successive downward zero crossings, interpolated."""
    t = [s[0] for s in samples]
    a = [s[1] for s in samples]
    ups = [
        t[i - 1] + (t[i] - t[i - 1]) * a[i - 1] / (a[i - 1] - a[i]) for i in range(1, len(a)) if a[i - 1] > 0 >= a[i]
    ]
    return float(np.mean(np.diff(ups)))


def test_pendulum_period_and_positions_agree_in_both_engines(tmp_path):
    """Compound pendulum: T = 2π·sqrt((I + mL²)/(m·g·L))·(1 + θ0²/16 + ...); both engines
    within 0.5 % of it, and their bob positions within 5 mm of each other over 2 s."""
    scene = _model(tmp_path, pendulum_model())
    t0 = 2 * math.pi * math.sqrt((I_C + M * L * L) / (M * G * L))
    expected = t0 * (1 + THETA0**2 / 16 + 11 * THETA0**4 / 3072)
    runs = {}
    for engine in ENGINES:
        world = engine(scene, Options(gravity=(0, 0, -G), ground=False, visuals=False))
        try:
            assert world.body("bob").com_position()[0] == pytest.approx(L * math.sin(THETA0), abs=1e-9)
            runs[engine.__name__] = _swing(world, 2.0)
        finally:
            world.close()
    for name, samples in runs.items():
        assert _period(samples) == pytest.approx(expected, rel=5e-3), name
        amplitude = max(abs(s[1]) for s in samples[-200:])
        assert amplitude == pytest.approx(THETA0, abs=0.01), name  # no numerical damping to speak of
    gap = max(np.linalg.norm(a[2] - b[2]) for a, b in zip(runs["MujocoWorld"], runs["PyBulletWorld"]))
    assert gap < 5e-3


# ---- thread ------------------------------------------------------------------------------
N_ELEMENTS, SEG, SEG_MASS, K_ANG, C_ANG = 4, 0.02, 0.005, 0.04, 1.5e-4


def thread_model() -> str:
    """A static anchor and N box elements in a horizontal row along +x, joined end to end by
    six-dof springs (linear locked, angular stiffness K_ANG, limits ±1 rad) as the suture is."""
    names = ["anchor"] + [f"e{i}" for i in range(N_ELEMENTS)]
    text = f"bodies: [{', '.join('BODY ' + n for n in names)}]\n"
    text += f"joints: [{', '.join(f'JOINT {a}-{b}' for a, b in zip(names, names[1:]))}]\n"
    text += (
        f"BODY anchor:\n  name: anchor\n  mass: 0.0\n  location: {_pose()}\n"
        "  collision shape: BOX\n  collision geometry: {x: 0.005, y: 0.005, z: 0.005}\n"
    )
    for i in range(N_ELEMENTS):
        ix = SEG_MASS * (SEG**2 + SEG**2) / 12
        iy = ix
        text += (
            f"BODY e{i}:\n  name: e{i}\n  mass: {SEG_MASS}\n  inertia: {{ix: {ix}, iy: {iy}, iz: {iy}}}\n"
            f"  location: {_pose(x=SEG * (i + 0.5))}\n  collision shape: BOX\n"
            f"  collision geometry: {{x: {SEG * 0.9}, y: {SEG * 0.9}, z: {SEG * 0.9}}}\n  damping: {{linear: 0.0, angular: 0.0}}\n"
        )
    for a, b in zip(names, names[1:]):
        pa = 0.0 if a == "anchor" else SEG / 2
        text += textwrap.dedent(f"""\
            JOINT {a}-{b}:
              name: {a}-{b}
              parent: BODY {a}
              child: BODY {b}
              type: six dof spring
              parent pivot: {{x: {pa}, y: 0.0, z: 0.0}}
              child pivot: {{x: {-SEG / 2}, y: 0.0, z: 0.0}}
              parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
              child axis: {{x: 0.0, y: 0.0, z: 1.0}}
              joint limits:
                linear: {{low: {{x: 0.0, y: 0.0, z: 0.0}}, high: {{x: 0.0, y: 0.0, z: 0.0}}}}
                angular: {{low: {{x: -1.0, y: -1.0, z: -1.0}}, high: {{x: 1.0, y: 1.0, z: 1.0}}}}
              stiffness: {{linear: {{x: 0.0, y: 0.0, z: 0.0}}, angular: {{x: {K_ANG}, y: {K_ANG}, z: {K_ANG}}}}}
              damping: {{linear: {{x: 0.0, y: 0.0, z: 0.0}}, angular: {{x: {C_ANG}, y: {C_ANG}, z: {C_ANG}}}}}
              equilibrium point: {{linear: {{x: 0.0, y: 0.0, z: 0.0}}, angular: {{x: 0.0, y: 0.0, z: 0.0}}}}
            """)
    return text


def thread_equilibrium() -> np.ndarray:
    """Element centres at the static equilibrium of the planar chain: minimum of
    Σ ½k·θ_j² + Σ m·g·z_i over the joint angles θ_j (bending in the x-z plane)."""
    from scipy.optimize import minimize

    def centres(th):
        phi = np.cumsum(th)  # absolute angle below the horizontal
        ends = (
            np.concatenate([[0.0], np.cumsum(SEG * np.cos(phi))]),
            np.concatenate([[0.0], -np.cumsum(SEG * np.sin(phi))]),
        )
        return np.stack([(ends[0][:-1] + ends[0][1:]) / 2, (ends[1][:-1] + ends[1][1:]) / 2], axis=1)

    def energy(th):
        return 0.5 * K_ANG * np.sum(th**2) + SEG_MASS * G * np.sum(centres(th)[:, 1])

    th = minimize(energy, np.full(N_ELEMENTS, 0.1), method="BFGS", options={"gtol": 1e-12}).x
    return centres(th)


def test_thread_hangs_to_its_static_equilibrium():
    """The chain starts straight and horizontal and sags under gravity to where the spring
    torques balance it. MuJoCo (springs as joint stiffness) ends within 0.2 mm of the energy
    minimum after 4 s without sleeping, and within 1 mm with island sleeping on (the default:
    the chain falls asleep once slower than the sleep tolerance, 0.6 mm short). PyBullet
    (springs as explicit per-step torques) keeps its pivots together (< 1 mm) and the chain in
    its plane, but does not settle on this chain (it still swings 40-75 mm about after 8 s;
    see docs/mujoco.md), so only that is asserted for it."""
    import tempfile
    from pathlib import Path

    expected = thread_equilibrium()
    assert expected[-1, 1] < -0.01  # a real sag (the tip drops more than 1 cm)
    with tempfile.TemporaryDirectory() as d:
        scene = _model(Path(d), thread_model())
        opt = Options(gravity=(0, 0, -G), ground=False, visuals=False)
        for engine, tol in (
            (lambda s, o: MujocoWorld(s, o, sleep=False), 2e-4),
            (MujocoWorld, 1e-3),
            (PyBulletWorld, None),
        ):
            world = engine(scene, opt)
            try:
                world.run(4.0)
                got = np.array([world.body(f"e{i}").com_position() for i in range(N_ELEMENTS)])
                assert np.abs(got[:, 1]).max() < 1e-6  # stays in its plane
                assert world.constraint_error() < 1e-3
                if tol is not None:
                    err = np.linalg.norm(got[:, [0, 2]] - expected, axis=1).max()
                    assert err < tol, f"{err * 1e3:.3f} mm from the equilibrium (sleep {world.sleep})"
                    assert world.diagnostics == []  # no spring was softened for stability
            finally:
                world.close()


# ---- PSM -----------------------------------------------------------------------------------
PSM1 = "src/ADF/PSMs/LND_400006_SIMPLE/psm1.yaml"


def test_psm_tracks_a_joint_trajectory_in_both_engines():
    """The corpus PSM driven along a smooth joint trajectory (1 s) through PSM.servo_jp:
    calibration residual below 0.2 mm in both; each tracks within 0.06 rad / 4 mm on the way,
    settles within 1e-4 of the last set-point, and the two engines' tool positions differ by
    under 3 mm along the way (their joint servos differ: Bullet's velocity motors, MuJoCo's
    joint equalities, drives.py)."""
    require_corpus()
    scene = load_scene(CORPUS / PSM1)
    tips = {}
    for engine in ENGINES:
        world = engine(scene, Options(visuals=False, ground=False))
        try:
            psm = PSM(world, "psm1")
            assert psm.calibration_error < 2e-4
            lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
            mid = (lo + hi) / 2

            def at(s):
                q = mid + 0.3 * math.sin(2 * math.pi * s) * (hi - mid)
                q[2] = 0.12 + 0.05 * math.sin(2 * math.pi * s)
                return q

            psm.servo_jp(at(0.0))  # to the start, 12 cm in, and settle
            world.run(0.5)
            errs, tip = [], []
            for k in range(1, 251):
                q = at(k / 250)
                psm.servo_jp(q)
                world.step(1)
                errs.append(np.abs(psm.measured_jp() - q))
                tip.append(psm.measured_cp()[:3, 3].copy())
            errs = np.array(errs)
            assert errs[:, [0, 1, 3, 4, 5]].max() < 0.06 and errs[:, 2].max() < 4e-3, engine.__name__
            world.run(0.5)
            assert np.abs(psm.measured_jp() - q).max() < 1e-4, engine.__name__
            tips[engine.__name__] = np.array(tip)
        finally:
            world.close()
    assert np.linalg.norm(tips["MujocoWorld"] - tips["PyBulletWorld"], axis=1).max() < 3e-3


def _finger_and_grip(parent: str, pose: str, size: float) -> str:
    """A finger ghost (a cube of ``size``) and a constraint actuator, both at ``pose`` on ``parent``."""
    return f"""GHOST finger:
  name: finger
  parent: BODY {parent}
  location: {pose}
  collision shape: BOX
  collision geometry: {{x: {size}, y: {size}, z: {size}}}
ACTUATOR grip:
  name: grip
  type: Constraint
  parent: BODY {parent}
  location: {pose}
  max impulse: 1.0
"""


# ---- grasp ---------------------------------------------------------------------------------
GRASP = f"""
bodies: [BODY base, BODY tool, BODY needle]
joints: [JOINT base-tool]
ghost objects: [GHOST finger]
actuators: [ACTUATOR grip]
BODY base:
  name: base
  mass: 0.0
  location: {_pose(z=0.5)}
  collision shape: BOX
  collision geometry: {{x: 0.02, y: 0.02, z: 0.02}}
BODY tool:
  name: tool
  mass: 0.5
  inertia: {{ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}}
  location: {_pose(z=0.4)}
  collision shape: BOX
  collision geometry: {{x: 0.01, y: 0.01, z: 0.01}}
BODY needle:
  name: needle
  mass: 0.05
  inertia: {{ix: 1.0e-5, iy: 1.0e-5, iz: 1.0e-5}}
  location: {_pose(z=0.38)}
  collision shape: BOX
  collision geometry: {{x: 0.01, y: 0.01, z: 0.01}}
JOINT base-tool:
  name: base-tool
  parent: BODY base
  child: BODY tool
  type: prismatic
  parent pivot: {{x: 0.0, y: 0.0, z: -0.1}}
  child pivot: {{x: 0.0, y: 0.0, z: 0.0}}
  parent axis: {{x: 1.0, y: 0.0, z: 0.0}}
  child axis: {{x: 1.0, y: 0.0, z: 0.0}}
  joint limits: {{low: -0.2, high: 0.2}}
  max motor impulse: 1.0
""" + _finger_and_grip("tool", _pose(z=-0.02), 0.02)


def test_grasp_weld_carries_the_body_and_release_drops_it(tmp_path):
    """MuJoCo: the finger ghost finds the needle 2 cm under the tool; grasp switches the weld
    on: the needle hangs on the tool and follows a 5 cm slide with under 0.5 mm drift;
    release switches it off and the needle falls freely (Δz = -g·t²/2 within 5 %)."""
    world = MujocoWorld(_model(tmp_path, GRASP), Options(gravity=(0, 0, -G), visuals=False, ground=False))
    try:
        tool, needle = world.body("tool"), world.body("needle")
        assert world.overlapping(world.ghosts[0]) == [needle]
        assert world.grasp("tool", True) is needle
        act = world.actuators[0]
        assert world.data.eq_active[act.eq] == 1 and world.model.eq_obj2id[act.eq] == needle.id
        rel0 = np.linalg.inv(tool.world_matrix()) @ needle.world_matrix()
        art = tool.articulation
        art.targets[0] = 0.05
        art.drive()
        world.run(1.0)
        assert tool.com_position()[0] == pytest.approx(0.05, abs=1e-3)
        rel1 = np.linalg.inv(tool.world_matrix()) @ needle.world_matrix()
        assert np.linalg.norm(rel1[:3, 3] - rel0[:3, 3]) < 5e-4
        assert world.grasp("tool", False) is None and world.data.eq_active[act.eq] == 0
        z0 = needle.com_position()[2]
        world.run(0.2)
        assert z0 - needle.com_position()[2] == pytest.approx(0.5 * G * 0.2**2, rel=0.05)
    finally:
        world.close()


def wrist_model(impulse: float) -> str:
    """A light wrist link (1 kg, 2e-6 kg·m², as the PSM's tool yaw link) on a horizontal hinge
    with a motor of ``impulse`` max motor impulse, and a 0.5 kg needle (the suturing scene's) 15 mm
    beside the hinge axis, between the wrist's finger ghost."""
    return f"""
bodies: [BODY base, BODY wrist, BODY needle]
joints: [JOINT base-wrist]
ghost objects: [GHOST finger]
actuators: [ACTUATOR grip]
BODY base:
  name: base
  mass: 0.0
  location: {_pose(z=0.5)}
  collision shape: BOX
  collision geometry: {{x: 0.004, y: 0.004, z: 0.004}}
BODY wrist:
  name: wrist
  mass: 1.0
  inertia: {{ix: 2.0e-6, iy: 2.0e-6, iz: 2.0e-6}}
  location: {_pose(z=0.49)}
  collision shape: SPHERE
  collision geometry: {{radius: 0.002}}
BODY needle:
  name: needle
  mass: 0.5
  inertia: {{ix: 1.5e-5, iy: 1.5e-5, iz: 1.5e-5}}
  location: {_pose(x=0.015, z=0.49)}
  collision shape: BOX
  collision geometry: {{x: 0.004, y: 0.004, z: 0.004}}
JOINT base-wrist:
  name: base-wrist
  parent: BODY base
  child: BODY wrist
  type: revolute
  parent pivot: {{x: 0.0, y: 0.0, z: -0.01}}
  child pivot: {{x: 0.0, y: 0.0, z: 0.0}}
  parent axis: {{x: 0.0, y: 1.0, z: 0.0}}
  child axis: {{x: 0.0, y: 1.0, z: 0.0}}
  max motor impulse: {impulse}
""" + _finger_and_grip("wrist", _pose(x=0.015), 0.01)


def _hold_the_needle(tmp_path, impulse: float):
    world = MujocoWorld(
        _model(tmp_path, wrist_model(impulse)), Options(gravity=(0, 0, -G), visuals=False, ground=False)
    )
    assert world.grasp("wrist", True) is world.body("needle")
    art = world.body("wrist").articulation
    q0 = art.joint_values()[0]
    qs, vs = [], []
    for _ in range(250):  # 1 s
        world.step(1)
        q, v = world.joint_state(art, [0])
        qs.append(float(q[0]) - q0)
        vs.append(float(v[0]))
    return world, np.array(qs), np.array(vs)


def test_a_drive_holds_a_light_wrist_under_a_heavy_held_needle(tmp_path):
    """The joint motor (a joint equality, drives.py) holds a 2e-6 kg·m² wrist link still while it
    holds a 0.5 kg needle 15 mm off its axis (0.07 N·m of weight): within 10 mrad (measured 8.4 at
    most, 7.4 settled: MuJoCo's soft constraint yields by (1-d)/d, d = 0.95), settled (under
    1 mrad/s over the last 0.5 s). The PD servo it replaced, its stiffness sized for the link
    alone (kp = (0.25/dt)²·M_ii = 0.125 N·m/rad), gave way by up to 0.85 rad and still swung at
    2.4 rad/s after 0.5 s."""
    world, qs, vs = _hold_the_needle(tmp_path, 50.0)
    try:
        assert np.abs(qs).max() < 1e-2, np.abs(qs).max()
        assert np.abs(vs[125:]).max() < 1e-3
        assert not any(d.rule == "runner-motor-limit" for d in world.diagnostics)
    finally:
        world.close()


def test_a_drive_past_its_motor_limit_is_named(tmp_path):
    """MuJoCo's equalities have no force limit: a motor of 1e-5 max motor impulse per 1 ms step
    (0.01 N·m) holding the 0.07 N·m needle is named in a runner-motor-limit warning (once)."""
    world, _, _ = _hold_the_needle(tmp_path, 1e-5)
    try:
        warned = [d for d in world.diagnostics if d.rule == "runner-motor-limit"]
        assert len(warned) == 1 and "base-wrist" in warned[0].message
    finally:
        world.close()


def _box_body(mass: float, inertia: float, location: str, side: float, friction: float) -> str:
    """An undamped cube ``BODY box`` of ``side`` m, ``mass`` kg, ``inertia`` kg·m² about each axis."""
    return (
        f"BODY box:\n  name: box\n  mass: {mass}\n"
        f"  inertia: {{ix: {inertia}, iy: {inertia}, iz: {inertia}}}\n  location: {location}\n"
        f"  collision shape: BOX\n  collision geometry: {{x: {side}, y: {side}, z: {side}}}\n"
        f"  friction: {{static: {friction}, rolling: 0.0}}\n  damping: {{linear: 0.0, angular: 0.0}}\n"
    )


def _slope(tmp_path, slope_friction: float, box_friction: float, tilt: float = 0.17453):
    """A 20 g box at rest on a static slab tilted ``tilt`` rad (10°) about y."""
    return _model(
        tmp_path,
        f"""
bodies: [BODY slab, BODY box]
BODY slab:
  name: slab
  mass: 0.0
  location: {_pose(z=0.5, p=tilt)}
  collision shape: BOX
  collision geometry: {{x: 0.4, y: 0.1, z: 0.02}}
  friction: {{static: {slope_friction}, rolling: 0.0}}
{_box_body(0.02, 1.0e-6, _pose(x=-0.01 * math.sin(tilt), z=0.5 + 0.02 * math.cos(tilt), p=tilt), 0.02, box_friction)}""",
    )


@pytest.mark.parametrize("engine", ENGINES)
def test_a_frictionless_body_is_frictionless_to_everything(tmp_path, engine):
    """Bullet multiplies the two bodies' frictions (AMBF's scenes rely on it: the suture's hole
    boundaries are frictionless); MuJoCo takes the larger unless told otherwise. A box of
    friction 0.8 on a frictionless 10° slope slides down it as g·sin θ (within 5 %) in both
    engines; on a slope of friction 0.8 it stays put (the box's 0.5: 0.4 or 0.5 > tan 10°)."""
    for slope, moves in ((0.0, True), (0.8, False)):
        world = engine(_slope(tmp_path, slope, 0.8 if slope == 0.0 else 0.5), Options(gravity=(0, 0, -G)))
        try:
            box = world.body("box")
            world.run(0.1)  # settles onto the slab
            p0 = np.array(box.com_position())
            world.run(0.4)
            moved = float(np.linalg.norm(np.array(box.com_position()) - p0))
            v = 0.4 * G * math.sin(0.17453)  # from rest after 0.1 s on the slope: t = 0.1 … 0.5
            expected = 0.5 * G * math.sin(0.17453) * 0.5**2 - 0.5 * G * math.sin(0.17453) * 0.1**2
            if moves:
                assert moved == pytest.approx(expected, rel=0.05), (engine.__name__, moved, expected, v)
            else:
                assert moved < 2e-4, (engine.__name__, moved)
        finally:
            world.close()


def test_a_thin_body_pressed_on_a_capsule_stays_out_of_it(tmp_path):
    """MuJoCo's contacts are as stiff as it keeps stable (contacts.py): a 30 g sphere of 0.19 mm
    (a suturing thread element's radius) pressed onto a 0.6 mm capsule (a hole's boundary) with
    2.4 N sinks under 0.05 mm into it (measured 0.036; with MuJoCo's default 0.02 s time constant
    it falls through, and the suture's thread sank 0.77 mm and slipped out of a hole)."""
    scene = _model(
        tmp_path,
        f"""
bodies: [BODY bar, BODY bead]
BODY bar:
  name: bar
  mass: 0.0
  location: {_pose(z=0.5)}
  collision shape: CAPSULE
  collision geometry: {{radius: 0.0006, height: 0.007, axis: x}}
  friction: {{static: 0.0, rolling: 0.0}}
BODY bead:
  name: bead
  mass: 0.03
  inertia: {{ix: 1.0e-9, iy: 1.0e-9, iz: 1.0e-9}}
  location: {_pose(z=0.5008)}
  collision shape: SPHERE
  collision geometry: {{radius: 0.00019}}
""",
    )
    world = MujocoWorld(scene, Options(gravity=(0, 0, -80.0), visuals=False, ground=False))  # 2.4 N
    try:
        world.run(0.3)
        depth = 0.5 + 0.0006 + 0.00019 - world.body("bead").com_position()[2]  # resting (or asleep) on top
        assert 0.0 <= depth < 5e-5, depth
    finally:
        world.close()


def _box_sent_off(tmp_path, engine, linear: float, angular: float):
    """A free 0.2 kg box with `damping: {linear, angular}`, no gravity, sent off at 1 m/s along x
    turning at 3 rad/s about z: (world, box)."""
    scene = _model(
        tmp_path,
        f"""
bodies: [BODY box]
BODY box:
  name: box
  mass: 0.2
  inertia: {{ix: 1.0e-4, iy: 2.0e-4, iz: 3.0e-4}}
  location: {_pose(z=1.0)}
  collision shape: BOX
  collision geometry: {{x: 0.02, y: 0.02, z: 0.02}}
  damping: {{linear: {linear}, angular: {angular}}}
""",
    )
    world = engine(scene, Options(gravity=(0, 0, 0), visuals=False, ground=False))
    box = world.body("box")
    if engine is MujocoWorld:
        world.data.qvel[:6] = [1.0, 0.0, 0.0, 0.0, 0.0, 3.0]
        mujoco.mj_forward(world.model, world.data)
    else:
        import pybullet as pb

        pb.resetBaseVelocity(box.uid, [1.0, 0.0, 0.0], [0.0, 0.0, 3.0], physicsClientId=world.cid)
    return world, box


@pytest.mark.parametrize("engine", ENGINES)
def test_body_velocity_damping_as_bullet_applies_it(tmp_path, engine):
    """ADF body damping (0.9 linear, 0.5 angular) decays a free body's velocities as Bullet
    does, (1 - d) per second: from 1 m/s and 3 rad/s to 0.1 m/s and 1.5 rad/s after 1 s (1 %),
    in both engines (MuJoCo has no body damping of its own; damping.py)."""
    world, box = _box_sent_off(tmp_path, engine, 0.9, 0.5)
    try:
        world.run(1.0)
        _, _, v, om = box.state()
        assert v[0] == pytest.approx(0.1, rel=0.01) and om[2] == pytest.approx(1.5, rel=0.01)
    finally:
        world.close()


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("d", [1.0, 1.5])
def test_a_damping_of_one_or_more_stops_a_body_as_bullet_clamps_it(tmp_path, engine, d):
    """Bullet clamps a damping to [0, 1] and at 1 zeroes the velocities every physics step: a box
    sent off at 1 m/s with `damping: {linear: 1.0}` (or more) stops within one control step. The
    MuJoCo engine played no damping at all there (the rate -ln(1 - d) undefined), so it flew on."""
    world, box = _box_sent_off(tmp_path, engine, d, d)
    try:
        world.run(0.1)
        p, _, v, om = box.state()
        assert abs(p[0]) < 0.003  # at most one control step's decay (4 ms from 1 m/s)
        assert np.abs(v).max() < 1e-6 and np.abs(om).max() < 1e-6
    finally:
        world.close()


SENSOR = f"""
bodies: [BODY eye, BODY near, BODY far]
sensors: [SENSOR ray]
BODY eye:
  name: eye
  mass: 0.0
  location: {_pose()}
  collision shape: SPHERE
  collision geometry: {{radius: 0.005}}
BODY near:
  name: near
  mass: 0.1
  inertia: {{ix: 1.0e-5, iy: 1.0e-5, iz: 1.0e-5}}
  location: {_pose(x=0.06, z=0.01)}
  collision shape: BOX
  collision geometry: {{x: 0.02, y: 0.02, z: 0.02}}
BODY far:
  name: far
  mass: 0.1
  inertia: {{ix: 1.0e-5, iy: 1.0e-5, iz: 1.0e-5}}
  location: {_pose(x=0.2, z=0.01)}
  collision shape: BOX
  collision geometry: {{x: 0.02, y: 0.02, z: 0.02}}
SENSOR ray:
  name: ray
  type: Proximity
  parent: BODY eye
  location: {_pose(z=0.01)}
  range: 0.1
  array:
  - offset: {{x: 0.0, y: 0.0, z: 0.0}}
    direction: {{x: 1.0, y: 0.0, z: 0.0}}
  - offset: {{x: 0.0, y: 0.0, z: 0.02}}
    direction: {{x: 1.0, y: 0.0, z: 0.0}}
"""


def test_proximity_sensor_rays_see_what_is_in_range(tmp_path):
    """A sensor 1 cm up on a static body, two rays along +x, 10 cm long: the box at 6 cm is
    hit by the lower ray, the one at 20 cm by neither; the sensor's own body is never reported."""
    world = MujocoWorld(_model(tmp_path, SENSOR), Options(gravity=(0, 0, 0), ground=False))
    try:
        world.step(1)
        assert [b.name for b in world.sensors[0].sensed] == ["near"]
    finally:
        world.close()


@pytest.mark.parametrize("engine", ENGINES)
def test_a_proximity_sensor_of_range_0_senses_nothing(tmp_path, engine):
    """Rays of no length: MuJoCo's mj_ray refuses them (a fatal error that ended the process);
    both engines sense nothing."""
    world = engine(
        _model(tmp_path, SENSOR.replace("range: 0.1", "range: 0.0")), Options(gravity=(0, 0, 0), ground=False)
    )
    try:
        world.step(2)
        assert world.sensors[0].sensed == []
    finally:
        world.close()


# ---- cameras and CLI -------------------------------------------------------------------------
def test_mujoco_camera_depth_segmentation_rgb(tmp_path):
    from adfkit.runner.mujoco.render import CameraUnavailable

    world = MujocoWorld(_model(tmp_path, box_camera_model()), Options(gravity=(0, 0, 0)))
    try:
        cam = world.cameras[0]
        assert cam.intrinsics()[1, 1] == pytest.approx(24 / math.tan(0.35))
        try:
            f = cam.render(world)
        except CameraUnavailable as e:
            pytest.skip(f"no headless OpenGL here: {e}")
        assert f["rgb"].shape == (48, 64, 3) and f["depth"].shape == (48, 64)
        assert abs(float(f["depth"][24, 32]) - 0.9) < 2e-3  # box face 0.1 m in front of the centre
        assert np.isinf(f["depth"][0, 0])
        assert f["segmentation"][24, 32] == 0 and f["segmentation"][0, 0] == -1
        rgb = f["rgb"].astype(float)
        assert rgb[24, 32, 0] > 2 * rgb[24, 32, 2]  # the red box
    finally:
        world.close()


def _cli(*args, cwd=None):
    env = {"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}
    import os

    env.update({k: v for k, v in os.environ.items() if k in ("HOME", "MUJOCO_GL", "ADFKIT_CORPUS")})
    return subprocess.run(
        [sys.executable, "-m", "adfkit", *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=300
    )


def test_run_command_with_mujoco_engine(tmp_path):
    model = tmp_path / "box.yaml"
    model.write_text(box_camera_model(mass=1.0, z=0.5))
    out = tmp_path / "out"
    r = _cli("run", str(model), "--engine", "mujoco", "--seconds", "0.5", "--out", str(out))
    assert r.returncode == 0, r.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["engine"] == "mujoco" and report["steps"] == 500 and report["nan"] == []
    assert report["ground_plane_z"] == pytest.approx(0.399, abs=1e-6)  # 1 mm under the box
    assert (
        report["frames"] == ["cam_rgb.png", "cam_depth.npy", "cam_seg.npy", "cam_seg.png"] or report["camera_problem"]
    )
    bad = _cli("run", str(model), "--engine", "mujoco", "--gui")
    assert bad.returncode == 2 and "error[bad-option]" in bad.stderr and "Traceback" not in bad.stderr


# ---- the suturing set ----------------------------------------------------------------------
@pytest.mark.slow
def test_suturing_set_grasp_in_mujoco():
    """The corpus suturing set in MuJoCo: the PSM's tool 12 cm out of the cannula, the needle
    (with its thread, one kinematic tree) moved between the jaws; the finger ghosts find it,
    the weld fixes it; a 5 cm Cartesian move through the IK carries it with <= 1 mm drift;
    opening the jaws drops it. Nothing NaN, exploded or fell through the floor meanwhile."""
    require_corpus()
    world = MujocoWorld(load_scene(CORPUS / "src" / "launch.yaml", [6, 7, 8, 9, 10, 11]), Options())
    try:
        psm = PSM(world, "psm1")
        psm.move_cp(psm.kin.fk([0.0, 0.0, 0.12, 0.0, 0.0, 0.0]), 0.3)
        world.run(0.2)
        act = next(a for a in world.actuators if "psm1" in a.key)
        needle = world.body("BODY Needle")
        at = (act.parent.world_matrix() @ act.location)[:3, 3]
        m, d = world.model, world.data
        q = m.jnt_qposadr[m.body_jntadr[needle.id]]
        d.qpos[q : q + 3] += at - np.array(needle.com_position())
        d.qvel[:] = 0.0
        mujoco.mj_forward(m, d)
        assert psm.grasp(True) is needle
        assert d.eq_active[act.eq] == 1
        world.run(0.2)
        rel0 = np.linalg.inv(psm.tool.world_matrix()) @ needle.world_matrix()
        tool0 = psm.tool.world_matrix()[:3, 3].copy()
        goal = psm.setpoint_cp()
        goal[:3, 3] += 0.05 * np.array([1.0, 1.0, -1.0]) / math.sqrt(3)
        psm.move_cp(goal, 0.5)
        world.run(0.3)
        assert np.linalg.norm(psm.tool.world_matrix()[:3, 3] - tool0) == pytest.approx(0.05, abs=1e-3)
        rel1 = np.linalg.inv(psm.tool.world_matrix()) @ needle.world_matrix()
        assert np.linalg.norm(rel1[:3, 3] - rel0[:3, 3]) <= 1e-3
        assert psm.grasp(False) is None and d.eq_active[act.eq] == 0
        z0 = needle.com_position()[2]
        world.run(0.3)
        assert needle.com_position()[2] < z0 - 0.02
        r = world.report()
        assert r["nan"] == [] and r["exploded"] == [] and r["fell_through_floor"] == []
    finally:
        world.close()


def test_both_engines_answer_the_same_public_api(tmp_path):
    """What PSM, `adfkit run` and tasks use exists on both worlds, and MuJoCo's report has
    every key PyBullet's has (plus its engine, sleeping trees and its other warnings)."""
    scene = _model(tmp_path, box_camera_model(mass=1.0, z=0.5))
    reports = {}
    for engine in ENGINES:
        world = engine(scene, Options())
        try:
            for name in (
                "dt",
                "opt",
                "sim_time",
                "ghosts",
                "actuators",
                "sensors",
                "cameras",
                "articulations",
                "bodies",
                "diagnostics",
                "step",
                "run",
                "body",
                "grasp",
                "overlapping",
                "place_ghosts",
                "joint_state",
                "reset_joints",
                "constraint_error",
                "report",
                "close",
            ):
                assert hasattr(world, name), (engine.__name__, name)
            box = world.body("box")
            for name in ("world_matrix", "com_position", "state", "force", "torque", "static", "mass", "key"):
                assert hasattr(box, name), (engine.__name__, name)
            world.step(10)
            assert world.sim_time == pytest.approx(0.04)
            reports[engine.__name__] = world.report()
        finally:
            world.close()
    assert set(reports["PyBulletWorld"]) <= set(reports["MujocoWorld"])
    assert set(reports["MujocoWorld"]) - set(reports["PyBulletWorld"]) == {"awake_trees", "trees", "engine_warnings"}
    assert reports["MujocoWorld"]["instabilities"] == reports["PyBulletWorld"]["instabilities"] == []
    p_mj, p_pb = reports["MujocoWorld"]["ground_plane_z"], reports["PyBulletWorld"]["ground_plane_z"]
    assert p_mj == pytest.approx(p_pb, abs=1e-6)  # the same floor 1 mm under the box


def test_missing_and_flat_meshes_are_warned_not_fatal(tmp_path):
    """A collision mesh file that is not there: the body is skipped, as AMBF and the PyBullet
    runner do (runner-missing-mesh; the engine made it without a shape before); a flat mesh,
    which MuJoCo cannot hull, collides as its bounding box (runner-flat-mesh): a box dropped
    on a 1 x 1 m flat square comes to rest on it."""
    (tmp_path / "flat.obj").write_text("v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3\nf 1 3 4\n")
    text = f"""
bodies: [BODY floor, BODY ghostly, BODY box]
high resolution path: ./
low resolution path: ./
BODY floor:
  name: floor
  mass: 0.0
  location: {_pose()}
  collision mesh: flat.obj
  mesh: flat.obj
BODY ghostly:
  name: ghostly
  mass: 0.0
  location: {_pose(x=2.0)}
  collision mesh: nowhere.obj
  mesh: nowhere.obj
BODY box:
  name: box
  mass: 0.1
  inertia: {{ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}}
  location: {_pose(z=0.1)}
  collision shape: BOX
  collision geometry: {{x: 0.02, y: 0.02, z: 0.02}}
"""
    world = MujocoWorld(_model(tmp_path, text), Options(gravity=(0, 0, -G), ground=False))
    try:
        rules = sorted({d.rule for d in world.diagnostics})
        assert rules == ["runner-flat-mesh", "runner-missing-mesh"]
        assert world.skipped == ["BODY ghostly"] and "BODY ghostly" not in world.registry.items
        world.run(1.0)
        z = world.body("box").com_position()[2]
        assert z == pytest.approx(0.01 + 5e-4, abs=1e-3)  # on the floor's 1 mm box, not through it
    finally:
        world.close()


BOX_ON_FLOOR = """
bodies: [BODY floor, BODY box, BODY post]
ghost objects: [GHOST hole]
BODY floor:
  name: floor
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 1.0, y: 1.0, z: 0.1}
BODY box:
  name: box
  mass: 0.5
  inertia: {ix: 0.001, iy: 0.001, iz: 0.001}
  location: {position: {x: 0.0, y: 0.0, z: 0.2}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
BODY post:
  name: post
  mass: 0.0
  location: {position: {x: 0.3, y: 0.0, z: 0.3}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: SPHERE
  collision geometry: {radius: 0.02}
GHOST hole:
  name: hole
  parent: BODY post
  location: {position: {x: 0.0, y: 0.01, z: 0.02}, orientation: {r: 0.3, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.01, y: 0.01, z: 0.01}
"""


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.__name__)
def test_task_api_set_collision_move_base_ghost_pose(tmp_path, engine):
    """What the suture asks of a world, the same in both engines: a body pair turned off falls
    through, turned on again it rests; a static body moved by move_base is where it was put,
    its ghost with it (ghost_pose). (0.5 s: at 0.25 s MuJoCo's rigid contact has the box rebound
    8 mm off the ground plane it fell onto at 0.2 s; Bullet's does not.)"""
    world = engine(_model(tmp_path, BOX_ON_FLOOR), Options())
    try:
        floor, box, post = world.body("floor"), world.body("box"), world.body("post")
        world.set_collision(floor, box, False)
        world.run(0.5)
        assert box.world_matrix()[2, 3] < 0.0  # through the floor's top face (0.05)
        world.set_collision(floor, box, True)
        top = post.world_matrix()
        top[:3, 3] = [0.5, -0.2, 0.4]
        world.move_base(post, top)
        assert np.allclose(post.world_matrix()[:3, 3], [0.5, -0.2, 0.4], atol=1e-9)
        g = world.ghost_pose(world.ghosts[0])
        assert np.allclose(g[:3, 3], [0.5, -0.19, 0.42], atol=1e-6)
        assert math.isclose(math.atan2(g[2, 1], g[2, 2]), 0.3, abs_tol=1e-6)
    finally:
        world.close()


def test_set_collision_turned_on_again_collides(tmp_path):
    world = MujocoWorld(_model(tmp_path, BOX_ON_FLOOR), Options())
    try:
        floor, box = world.body("floor"), world.body("box")
        world.set_collision(floor, box, False)
        world.set_collision(floor, box, True)
        world.run(0.5)
        assert abs(box.world_matrix()[2, 3] - 0.1) < 2e-3  # resting on the floor's top face
    finally:
        world.close()


def _box_alone(tmp_path, friction: float):
    """A 0.2 kg box played alone, 1 mm above the floor adfkit gives it."""
    return _model(
        tmp_path,
        f"""
bodies: [BODY box]
{_box_body(0.2, 1.0e-4, _pose(z=0.3), 0.05, friction)}""",
    )


@pytest.mark.parametrize("engine", ENGINES)
def test_the_floor_of_a_model_played_alone_has_bullets_friction_where_ambf_is_asked_for(tmp_path, engine):
    """Under AMBF's bodies (adfkit run / parity) the floor's friction (0.5, as the floor AMBF is
    given) times the box's 0.6, Bullet's product: a box sent along it at 2 m/s slides
    2·0.2 − ½·0.3·g·0.2² = 0.3411 m in 0.2 s in both engines (within 1 %). Control: MuJoCo's
    own rule (the lower of its floor's 1 and the box's 0.6, Options' default) slows it about
    twice as fast: 0.2823 m at 0.6 (0.275 m measured: within 4 %)."""
    cases = [("ambf", 0.3, 0.01)] + ([("pybullet", 0.6, 0.04)] if engine is MujocoWorld else [])
    for bodies, mu, rel in cases:
        world = engine(_box_alone(tmp_path, 0.6), Options(gravity=(0, 0, -G), visuals=False, bodies=bodies))
        try:
            box = world.body("box")
            world.run(0.05)  # onto the floor
            world.set_body_velocity(box, [2.0, 0.0, 0.0], [0.0, 0.0, 0.0])
            x0 = box.com_position()[0]
            world.run(0.2)
            slid = box.com_position()[0] - x0
            assert slid == pytest.approx(2.0 * 0.2 - 0.5 * mu * G * 0.2**2, rel=rel), (engine.__name__, bodies, slid)
        finally:
            world.close()


def _arm_past_its_limit(tmp_path, kind: str):
    """The parity arm (0.5 kg, 30 cm, on a joint about z from a static post: gravity across the
    axis) whose joint's limits [0.2, 1.0] rad put its start 0.2 rad past the lower one."""
    from adfkit.adf.writer import write_file
    from adfkit.model import JointLimits
    from adfkit.scenes.parity import build_arm

    m = build_arm()
    m.joints[0].type = kind
    m.joints[0].joint_limits = JointLimits(low=0.2, high=1.0)
    path = write_file(m, tmp_path / f"arm_{kind.replace(' ', '_')}.yaml")
    return load_scene(path)


@pytest.mark.parametrize(("kind", "rate"), [("revolute", 0.3 * 0.1), ("torsion spring", 0.1), ("prismatic", 0.2)])
def test_a_joint_started_past_its_limit_is_kicked_in_as_ambfs_limit_row_asks(tmp_path, kind, rate):
    """Under AMBF's bodies (adfkit run / parity) a MuJoCo limit asks, as Bullet's limit row,
    for the inward velocity c·error in one physics step and then lets the joint coast: c·dt is
    0.3·erp for a hinge (setLimit's bias 0.3, AMBF's joint erp 0.1) and erp for a torsion
    spring (its 6-dof spring constraint's stop ERP), 0.2 for a slider (the world's ERP). Measured
    in AMBF (adfkit parity): this hinge turns in at 6.0 rad/s from its first step (0.0240 rad in
    4 ms), the torsion spring at 17.6 rad/s over its first 4 ms (20 by the formula), a slider
    0.05 m past its limit at 10 m/s (0.2·0.05/1 ms); this one, along z and 0.2 m past, is asked
    for 40 m/s. Control: MuJoCo's own limit (a 20 ms time constant, Options' default) eases the
    hinge in, 0.0045 rad in 4 ms."""
    speed = rate * 0.2 / 1e-3  # 6 rad/s, 20 rad/s, 40 m/s
    for bodies in ("ambf", "pybullet"):
        world = MujocoWorld(_arm_past_its_limit(tmp_path, kind), Options(visuals=False, ground=False, bodies=bodies))
        try:
            q0 = world.data.qpos[0]
            world.step(1)  # 4 ms
            q, v = world.data.qpos[0] - q0, world.data.qvel[0]
            if bodies == "ambf":
                assert v == pytest.approx(speed, rel=0.02), (kind, v)
                assert q == pytest.approx(4e-3 * speed, rel=0.02), (kind, q)
            elif kind == "revolute":
                assert q < 0.3 * 4e-3 * speed, q  # 0.0045 rad
        finally:
            world.close()


def test_a_cone_twist_joint_between_bodies_without_a_location_plays(tmp_path):
    """`location` is optional (the body frame is then the model's): a six-dof-family joint's start
    (runner/mujoco/start.py, AMBF's bodies) reads such a body at the origin instead of failing.
    The ball hangs from the post's pivot 0.1 m below it, as its joint puts it."""
    f = tmp_path / "cone.yaml"
    f.write_text(
        "bodies: [BODY a, BODY b]\njoints: [JOINT a-b]\n"
        "BODY a:\n  name: a\n  mass: 0.0\n  collision shape: BOX\n  collision geometry: {x: 0.05, y: 0.05, z: 0.05}\n"
        "BODY b:\n  name: b\n  mass: 0.2\n  collision shape: SPHERE\n  collision geometry: {radius: 0.02}\n"
        "JOINT a-b:\n  name: a-b\n  parent: BODY a\n  child: BODY b\n  type: cone twist\n"
        "  parent pivot: {x: 0.0, y: 0.0, z: -0.1}\n  child pivot: {x: 0.0, y: 0.0, z: 0.0}\n"
        "  parent axis: {x: 0.0, y: 0.0, z: 1.0}\n  child axis: {x: 0.0, y: 0.0, z: 1.0}\n"
        "  joint limits: {x: 0.3, y: 0.3, z: 0.2}\n"
    )
    world = MujocoWorld(load_scene(f), Options(visuals=False, bodies="ambf"))
    try:
        world.run(0.1)
        assert np.asarray(world.body("b").com_position()) == pytest.approx([0.0, 0.0, -0.1], abs=1e-3)
    finally:
        world.close()


def test_a_hinge_named_with_a_hash_is_not_read_as_a_six_dof_axis(tmp_path):
    """The six-dof start picks its joints by kind, not by the `#` in the names it gives their
    axes: a revolute joint named `a#b` plays (it failed with a KeyError), its arm falling about
    its hinge (y) from level: 0.1 s later its centre has dropped (gravity across the axis)."""
    f = tmp_path / "hash.yaml"
    f.write_text(
        "bodies: [BODY a, BODY b]\njoints: [JOINT a#b]\n"
        "BODY a:\n  name: a\n  mass: 0.0\n  collision shape: BOX\n  collision geometry: {x: 0.05, y: 0.05, z: 0.05}\n"
        "BODY b:\n  name: b\n  mass: 0.2\n  collision shape: BOX\n  collision geometry: {x: 0.2, y: 0.02, z: 0.02}\n"
        "  location: {position: {x: 0.1, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n"
        "JOINT a#b:\n  name: a#b\n  parent: BODY a\n  child: BODY b\n  type: revolute\n"
        "  parent pivot: {x: 0.0, y: 0.0, z: 0.0}\n  child pivot: {x: -0.1, y: 0.0, z: 0.0}\n"
        "  parent axis: {x: 0.0, y: 1.0, z: 0.0}\n  child axis: {x: 0.0, y: 1.0, z: 0.0}\n"
    )
    world = MujocoWorld(load_scene(f), Options(visuals=False, bodies="ambf", ground=False))
    try:
        world.run(0.1)
        x, _y, z = np.asarray(world.body("b").com_position())
        assert z < -0.01 and math.hypot(x, z) == pytest.approx(0.1, abs=1e-3)
    finally:
        world.close()


def test_a_primitive_of_size_0_is_refused_at_its_body_s_geometry(tmp_path):
    """MuJoCo refuses a geom of size 0; the error names the geom, and is located at its ADF body's
    `collision geometry` (it was put at the scene's first model, here the only one, line 1)."""
    from adfkit.diagnostics import AdfError

    scene = _model(
        tmp_path,
        f"""
bodies: [BODY a, BODY flat]
BODY a:
  name: a
  mass: 0.1
  location: {_pose(z=1.0)}
  collision shape: SPHERE
  collision geometry: {{radius: 0.01}}
BODY flat:
  name: flat
  mass: 0.1
  location: {_pose(z=0.5)}
  collision shape: BOX
  collision geometry: {{x: 0.0, y: 0.02, z: 0.02}}
""",
    )
    with pytest.raises(AdfError) as e:
        MujocoWorld(scene, Options(visuals=False, ground=False))
    d = e.value.diagnostics[0]
    assert d.rule == "mujoco-refused" and d.location.line == 14  # (the text starts with a blank line)
