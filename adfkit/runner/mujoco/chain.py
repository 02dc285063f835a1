"""A MuJoCo articulation read as AMBF's chain of btRigidBodies for one physics step of its
solver (runner/chain_step.py): each link and the base a body at its centre of mass (MuJoCo's
inertial frame, where its principal inertia is), with the velocities MuJoCo gives it there; each
hinge or slide joint a btHingeConstraint or btSliderConstraint at the joint's anchor; a hinge or
p2p joint MuJoCo closes a loop with (a connect between two of the chain's links) AMBF's
btHingeConstraint or btPoint2PointConstraint at the connect's pivot (runner/loop_rows.py). Only
for an articulation whose joints are all revolute or prismatic and which no other equality ties
(a weld, a connect to a body outside it: left to the joint-space rows), and only where AMBF's
bodies are asked for (MujocoWorld.chain_velocities)."""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import JointKind, body_joint_frames, joint_kind
from ..chain_step import ChainState, ChainStep
from ..loop_rows import Loop, loop_joints
from ..rotations import invert, pose_to_matrix

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
        self.loops = _loops(world, chain, index)
        self.ok = self.ok and self.loops is not None and not _tied(m, set(self.ids.tolist()))
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
        added += range(len(joints), len(joints) + len(self.loops))  # the loops' rows after the chain's own
        self.parents = [self.ids[p] for p, _k, _j in joints]
        self.core = ChainStep(world.dt, bodies, joints, added)

    def velocities(
        self, motors: dict[int, tuple[float, float, float]], efforts: dict[int, float], step: int, ghosted=None
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
            ghosted or {},
        )
        loops = self.loops

        def closing(bodies, coms, rots, drift):
            return loop_joints(loops, bodies, coms, rots, drift)

        return self.core.velocities(state, motors, efforts, step, closing if loops else None)


def _loops(world, chain: list, index: dict[int, int]) -> list[Loop] | None:
    """The hinges and points closing loops between two of the chain's bodies (MuJoCo closes each
    with a connect equality), as AMBF's btHingeConstraint and btPoint2PointConstraint read them:
    the joint's frames AMBF builds, in each body's inertial frame now; None where a loop is
    closed by another kind of joint."""
    m, d = world.model, world.data
    joints = {j.identifier: j for j, _p, _c in world.joints_made}
    loops = []
    for name, _c, parent, child, _pa, _pb, _axis in world.constraints:
        if id(parent) not in index or id(child) not in index:
            continue
        joint = joints.get(name)
        kind = joint_kind(joint.type) if joint is not None else None
        if kind not in (JointKind.REVOLUTE, JointKind.P2P):
            return None
        eq = _connect(m, parent.id, child.id)
        if eq is None:
            return None
        ends = []
        for sb, frame, anchor in zip(
            (parent, child), body_joint_frames(joint, parent.body, child.body), (m.eq_data[eq, :3], m.eq_data[eq, 3:6])
        ):
            com = np.eye(4)
            com[:3, :3], com[:3, 3] = d.ximat[sb.id].reshape(3, 3), d.xipos[sb.id]
            end = invert(com) @ sb.world_matrix() @ pose_to_matrix(frame)
            # the pivot where MuJoCo's connect holds the two bodies together (each anchor in its
            # body's frame): the rows and the equality hold the same points
            end[:3, 3] = invert(com)[:3] @ np.append(d.xmat[sb.id].reshape(3, 3) @ anchor + d.xpos[sb.id], 1.0)
            ends.append(end)
        fa, fb = ends
        a, b = index[id(parent)], index[id(child)]
        if kind is JointKind.P2P:
            loops.append(Loop("p2p", joint, a, b, fa[:3, 3], fb[:3, 3], None, None, None))
        else:
            loops.append(Loop("revolute", joint, a, b, fa[:3, 3], fb[:3, 3], fa[:3, 2], fa, fb))
    return loops


def _connect(m, a: int, b: int) -> int | None:
    """The connect equality MuJoCo closes a loop between bodies ``a`` and ``b`` with."""
    for e in range(m.neq):
        if m.eq_type[e] == mujoco.mjtEq.mjEQ_CONNECT and (int(m.eq_obj1id[e]), int(m.eq_obj2id[e])) == (a, b):
            return e
    return None


def _tied(m, ids: set[int]) -> bool:
    """Whether an equality active from the start other than a connect between two of the
    bodies ``ids`` (a loop the chain step solves: ``_loops``) holds one of them."""
    for e in range(m.neq):
        kind = int(m.eq_type[e])  # numpy's integer is no pybind enum's equal in a tuple
        if kind in _TIES and m.eq_active0[e]:
            one, two = int(m.eq_obj1id[e]) in ids, int(m.eq_obj2id[e]) in ids
            if (one or two) and not (one and two and kind == mujoco.mjtEq.mjEQ_CONNECT):
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


def chain_ghosts(world, art) -> dict:
    """World.chain_ghosts in MuJoCo: the bodies of ``art`` AMBF's ghosts hold at a 1 ms control
    step, with the points found a physics step before (what the rule acts with in this step:
    ghosts._ambf_ghosts), and each ghost parent's velocity at its centre of mass."""
    before = world._ghost_before
    model = world._chains.get(id(art))
    if world.opt.ghosts != "ambf" or world.opt.control_substeps != 1 or before is None or model is None:
        return {}
    index = {int(b): k for k, b in enumerate(model.ids)}
    m, d = world.model, world.data
    out: dict[int, list] = {}
    for g, found in zip(world.ghosts, before[0]):
        acts = [(index[sb.id], n) for sb, n in found if n and sb.id in index]
        if not acts:
            continue
        v_par = np.zeros(3)
        if g.parent is not None and not g.parent.static:
            mujoco.mj_comPos(m, d)
            mujoco.mj_comVel(m, d)
            vel = np.zeros(6)
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, int(g.parent.id), vel, 0)
            v_par = vel[3:]
        for k, n in acts:
            out.setdefault(k, []).append((n, v_par))
    return out


def chain_stepped_ids(world) -> np.ndarray:
    """The bodies of the articulations AMBF's solver was played on for this physics step
    (World.chain_stepped): AMBF's ghosts act on them in their chain's step (chain_ghosts)."""
    ids = [world._chains[a].ids for a, at in world._chain_stepped.items() if at == world.steps and a in world._chains]
    return np.concatenate(ids) if ids else np.zeros(0, dtype=int)
