"""The springs and dampers of six-dof springs, linear and torsion springs in the MuJoCo world as
AMBF's Bullet plays them (btGeneric6DofSpring2Constraint::get_limit_motor_info2), where AMBF's
springs are asked for (``Options.springs`` "ambf": ``adfkit run``, ``adfkit parity``), as the
PyBullet runner's SpringSet plays them (runner/pybullet/spring_forces.py).

Bullet's spring row is explicit, evaluated at every physics step from the joint's position and
velocity, and its impulse is bounded by the spring-damper's and the damper's alone: where the
damper opposes the spring and outweighs it (a spring released toward its equilibrium, damped
hard) the damper acts alone. MuJoCo's joint damping is implicit and unbounded: a torsion spring
so released swung 9.8° from AMBF's (0.001° now). Here each such axis (one MuJoCo slide or hinge:
build.py) keeps MuJoCo's stiffness (explicit, as Bullet's), and its damping, taken out of the
model, is -c·v in ``qfrc_applied`` before each physics step, with the spring taken back out where
the damper acts alone (the world then steps one physics step at a time). A tree at rest gets no
force, so that MuJoCo still lets it sleep (a nonzero ``qfrc_applied`` keeps a tree awake: the
suturing set's stepping took 2.5x as long). The axes' values are Bullet's (slides along frame A's
axes, hinges R = Rx·Ry·Rz: RO_XYZ), and so are their rates about a single axis; about tilted
gimbals Bullet drives each row along its own axis, here the hinge's (the same to first order).

Bullet caps k at m/(16·dt²) and c at m/dt (m: the two bodies in series, each one's mass, or about
an angular axis its inertia about the axis plus its mass times the squared distance from its
centre of mass to the joint frame). A joint whose file asks for more (capped_joints) keeps
MuJoCo's own stiffness, damping and limits: MuJoCo's tree cannot play it as Bullet does.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import ONE_AXIS_SPRINGS, JointKind
from .damping import SLOW

#: the joints AMBF makes btGeneric6DofSpring2Constraints (afJoint::createFromAttribs)
BULLET_SPRINGS = (JointKind.SIX_DOF_SPRING, JointKind.LINEAR_SPRING, JointKind.TORSION_SPRING)


def bullet_mass(model, data, jid: int, parent: int) -> float:
    """Bullet's m of MuJoCo joint ``jid`` (its child the joint's body, its parent body ``parent``,
    static when welded to the world): a slide's the masses in series, a hinge's each dynamic
    body's inertia about the axis (1/|I⁻¹·a|) plus its mass times the squared distance from its
    centre of mass to the joint frame, in series."""
    child = int(model.jnt_bodyid[jid])
    axis, anchor = data.xaxis[jid], data.xanchor[jid]
    hinge = model.jnt_type[jid] == mujoco.mjtJoint.mjJNT_HINGE

    def own(b: int) -> float | None:
        mass = float(model.body_mass[b])
        if mass <= 0.0 or int(model.body_weldid[b]) == 0:
            return None  # static
        if not hinge:
            return mass
        r = data.ximat[b].reshape(3, 3)
        inv = r @ np.diag(1.0 / np.maximum(model.body_inertia[b], 1e-12)) @ r.T
        return mass * float(np.sum((anchor - data.xipos[b]) ** 2)) + 1.0 / float(np.linalg.norm(inv @ axis))

    a, b = own(parent), own(child)
    if a is None or b is None:
        return b if a is None else a  # type: ignore[return-value]
    return a * b / (a + b)


def _axes(model, joints):
    """(MuJoCo joint names, [(joint id, dof, parent body id)]) of each Bullet spring in ``joints``."""
    m = model
    for _j, kind, parent, _child, names in joints:
        if kind not in BULLET_SPRINGS:
            continue
        pid = 0 if parent.mjname == "world" else mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, parent.mjname)
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names]
        yield names, [(j, int(m.jnt_dofadr[j]), pid) for j in ids if j >= 0]


def spring_dofs(model, joints) -> dict[int, int]:
    """{id(the file's joint): its dof} of each limited torsion or linear spring of ``joints``
    (build.Plan.joints), whose one free axis is a MuJoCo hinge or slide (MujocoWorld.spring_effort)."""
    m = model
    return {
        id(getattr(j, "joint", j)): int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, names[0])])
        for j, kind, _p, _c, names in joints
        if kind in ONE_AXIS_SPRINGS and len(names) == 1
    }


def capped_joints(model, data, joints, dt: float) -> frozenset:
    """The MuJoCo joint names of every Bullet spring in ``joints`` with an axis stiffer than
    m/(16·dt²) or more damped than m/dt (Bullet's m: bullet_mass): its bodies too light for
    it, as the suturing thread's elements are for theirs. Bullet then plays a far weaker spring
    than the file's; in MuJoCo's tree, where the joint turns all the chain below it, that spring
    left the parity thread flapping (180 mm from AMBF's where MuJoCo's own springs keep it within
    38 mm), and Bullet's limit rows on it alone took it from 38.4 to 43.1 mm. Such a joint keeps
    MuJoCo's own stiffness, damping and limits."""
    out: set[str] = set()
    for names, axes in _axes(model, joints):
        for jid, dof, pid in axes:
            k, c = float(model.jnt_stiffness[jid]), float(model.dof_damping[dof])
            if k > 0.0 or c > 0.0:
                mass = bullet_mass(model, data, jid, pid)
                if k > mass / (16.0 * dt * dt) or c > mass / dt:
                    out.update(names)
                    break
    return frozenset(out)


class SpringRows:
    """Every spring axis of ``joints`` (build.Plan.joints) with a stiffness or a damping, but those
    of the joints named in ``capped`` (capped_joints: MuJoCo's own)."""

    def __init__(self, world, joints, capped=frozenset()) -> None:
        m, d = world.model, world.data
        qadr, dofs, k, eq = [], [], [], []
        for names, axes in _axes(m, joints):
            if capped.intersection(names):
                continue
            for jid, dof, _pid in axes:
                if not (m.jnt_stiffness[jid] > 0.0 or m.dof_damping[dof] > 0.0):
                    continue
                qadr.append(int(m.jnt_qposadr[jid]))
                dofs.append(dof)
                eq.append(float(m.qpos_spring[m.jnt_qposadr[jid]]))
                k.append(float(m.jnt_stiffness[jid]))
        self.qadr, self.dofs = np.array(qadr, dtype=int), np.array(dofs, dtype=int)
        self.k, self.c = np.array(k, dtype=float), np.array(m.dof_damping[self.dofs])
        m.dof_damping[self.dofs] = 0.0  # explicit, here
        self.eq = np.array(eq, dtype=float)
        self._qpos, self._qvel, self._qfrc = d.qpos, d.qvel, d.qfrc_applied
        # the trees the springs are in, their dofs one after another (BodyDamping's rule: a tree
        # whose every dof moves slower than SLOW·sleep_tolerance is not damped, so that it can sleep)
        tree = np.array(m.body_treeid[m.dof_bodyid[self.dofs]], dtype=int)
        self.trees, self.tree_of = np.unique(tree, return_inverse=True)
        self.tree_dofs = (
            np.concatenate([np.arange(m.tree_dofadr[t], m.tree_dofadr[t] + m.tree_dofnum[t]) for t in self.trees])
            if len(self.trees)
            else np.zeros(0, dtype=int)
        )
        self.starts = np.concatenate([[0], np.cumsum(m.tree_dofnum[self.trees])[:-1]]).astype(int)
        self.slow = SLOW * float(getattr(m.opt, "sleep_tolerance", 0.0)) if world.sleep else None
        self.efforts = np.zeros(len(self.dofs))  # each axis's effort command (MujocoWorld.spring_effort)
        self._qacc, self._awake = d.qacc, d.tree_awake

    def __len__(self) -> int:
        return len(self.dofs)

    def apply(self, ahead: float = 0.0) -> bool:
        """This physics step's dampers and bounds (MuJoCo's stiffness plays the springs): each
        damper -c·v, explicit, and where it opposes the spring and outweighs it, the spring taken
        back out. A tree at rest gets 0 (all bytes zero: MuJoCo lets it sleep). ``ahead`` (s, the
        control step, at its first physics step): False when no awake sprung tree would reach the
        damper's speed within it (each dof's speed plus its last acceleration times ``ahead``):
        the world then steps the control step at once, without these forces."""
        v = self._qvel[self.dofs]
        damper = -self.c * v
        if self.slow is not None:
            speed = np.abs(self._qvel[self.tree_dofs])
            if (
                ahead
                and not np.count_nonzero(
                    self._awake[self.trees]
                    * np.maximum.reduceat(speed + np.abs(self._qacc[self.tree_dofs]) * ahead, self.starts)
                    >= self.slow
                )
                and not np.count_nonzero(self.efforts)
            ):  # (a sleeping tree's qacc is the last it had awake)
                self._qfrc[self.dofs] = 0.0
                return False
            moving = np.maximum.reduceat(speed, self.starts) >= self.slow
            damper = np.where(moving[self.tree_of], damper, 0.0)
        spring = -self.k * (self._qpos[self.qadr] - self.eq)
        alone = (spring * damper < 0.0) & (np.abs(damper) > np.abs(spring))
        self._qfrc[self.dofs] = np.where(alone, -spring, 0.0) + damper + self.efforts + 0.0  # + 0.0: no -0.0
        return True
