"""A MuJoCo articulation read as AMBF's chain of btRigidBodies for one physics step of its
solver (runner/chain_step.py): each link and the base a body at its centre of mass (MuJoCo's
inertial frame, where its principal inertia is), with the velocities MuJoCo gives it there; each
hinge or slide joint a btHingeConstraint or btSliderConstraint at the joint's anchor. Only for
an articulation whose joints are all revolute or prismatic and whose bodies no equality ties
elsewhere (a loop MuJoCo closes with a connect or weld equality is left to the joint-space
rows), and only where AMBF's bodies are asked for (MujocoWorld.chain_velocities)."""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import JointKind
from ..chain_step import ChainState, ChainStep

_TIES = (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD)


class ChainModel:
    """What does not change of an articulation's bodies and joints."""

    def __init__(self, world, art) -> None:
        m = world.model
        self.world = world
        kinds = {JointKind.REVOLUTE: "revolute", JointKind.PRISMATIC: "prismatic"}
        chain = [art.root] + [rec[3] for rec in art.records]
        self.ids = np.array([sb.id for sb in chain], dtype=int)
        index = {id(sb): k for k, sb in enumerate(chain)}
        self.ok = all(k in kinds for k in art.kinds) and bool(np.all(art.vadr >= 0))
        self.ok = self.ok and not _tied(m, set(self.ids.tolist()))
        if not self.ok:
            return
        self.jids = np.array([int(m.dof_jntid[a]) for a in art.vadr], dtype=int)
        self.qadr, self.vadr = art.qadr, art.vadr
        bodies = []
        for sb in chain:
            b = sb.id
            g = sb.gravity if sb.gravity is not None else world.gravity
            static = bool(sb.static) or int(m.body_weldid[b]) == 0
            bodies.append((sb.body, float(m.body_mass[b]), m.body_inertia[b].copy(), static, g))
        joints = [(index[id(rec[2])], kinds[kind], rec[0]) for rec, kind in zip(art.records, art.kinds)]
        in_file = {id(j): i for i, j in enumerate(j for mf in world.scene.all_models() for j in mf.joints)}
        added = sorted(range(len(joints)), key=lambda k: in_file.get(id(art.records[k][0]), k))
        self.parents = [self.ids[p] for p, _k, _j in joints]
        self.core = ChainStep(world.dt, bodies, joints, added)

    def velocities(
        self, motors: dict[int, tuple[float, float, float]], efforts: dict[int, float], step: int
    ) -> np.ndarray:
        """The joints' velocities (by record index) after one step of AMBF's solver (physics
        step ``step``): ChainStep.velocities on MuJoCo's state now."""
        m, d = self.world.model, self.world.data
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        vel = np.zeros((len(self.ids), 6))
        for k, b in enumerate(self.ids):  # (angular, linear) at the centre of mass, world axes
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, int(b), vel[k], 0)
        joints = []
        for jid, qa, va, parent in zip(self.jids, self.qadr, self.vadr, self.parents):
            axis = d.xaxis[jid].copy()
            frame = d.xmat[parent].reshape(3, 3)
            across = frame[:, int(np.argmin(np.abs(frame.T @ axis)))]  # fixed in the parent
            y = across - axis * (across @ axis)
            joints.append((d.xanchor[jid].copy(), axis, y / np.linalg.norm(y), float(d.qpos[qa]), float(d.qvel[va])))
        state = ChainState(
            d.xipos[self.ids].copy(),
            d.ximat[self.ids].reshape(-1, 3, 3).copy(),
            vel[:, 3:].copy(),
            vel[:, :3].copy(),
            joints,
            _contact_pushes(m, d, self.ids),
        )
        return self.core.velocities(state, motors, efforts, step)


def _tied(m, ids: set[int]) -> bool:
    """Whether an equality active from the start (a loop's connect or weld) holds one of the
    bodies ``ids``."""
    for e in range(m.neq):
        if m.eq_type[e] in _TIES and m.eq_active0[e]:
            if int(m.eq_obj1id[e]) in ids or int(m.eq_obj2id[e]) in ids:
                return True
    return False


def _contact_pushes(m, d, ids: np.ndarray) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """(chain body index, force, point) of every contact on the chain's bodies from the last
    step: MuJoCo's contact force (normal and friction), in its contact frame, whose normal
    points from the first geom to the second, which it pushes."""
    at = {int(b): k for k, b in enumerate(ids)}
    out = []
    f = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        b1, b2 = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
        if b1 not in at and b2 not in at:
            continue
        mujoco.mj_contactForce(m, d, i, f)
        force = c.frame.reshape(3, 3).T @ f[:3]
        point = c.pos.copy()
        if b2 in at:
            out.append((at[b2], force, point))
        if b1 in at:
            out.append((at[b1], -force, point))
    return out
