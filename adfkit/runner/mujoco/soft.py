"""Soft bodies in the MuJoCo engine: each is the MJCF writer's flex (converters/mjcf_soft.py: a
2-D ``flexcomp`` on the nodes AMBF makes of its collision mesh, elasticity from kLST and
piterations, `fixed nodes` pinned), integrated by MuJoCo's discrete integrator (assemble.py);
a joint between a soft body and a rigid body holds the soft body's nodes at its pivot to the
rigid body (``connect`` equalities, as the PyBullet runner's anchors). What the writer could
not map is warned about once per soft body and listed in its report entry."""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from ...geometry.softmesh import placed_soft_mesh
from ..names import merge_namespace
from ..soft import held_nodes, soft_end, soft_report

HOLD_STEPS = 2  # a held node's connect equality: time constant in physics steps (as the grasp weld's)


@dataclass(eq=False)
class MjSoftBody:
    key: str
    soft: object  # the model's SoftBody
    model: object
    flex: str  # its flex's MJCF name
    world: object = None
    fid: int = -1
    node_count: int = 0
    triangles: int = 0
    rest_size: float = 0.0
    fixed: list = field(default_factory=list)
    attached: dict = field(default_factory=dict)  # rigid body key -> node indices
    unmapped: list = field(default_factory=list)
    young: float = 0.0  # the flex's Young's modulus, Pa (the writer's mapping of kLST and piterations)

    def nodes(self, _cid=None) -> np.ndarray:
        """Node positions in the world, (n, 3)."""
        m, d = self.world.model, self.world.data
        a = m.flex_vertadr[self.fid]
        return np.array(d.flexvert_xpos[a : a + m.flex_vertnum[self.fid]], dtype=float)


class MjSoftBodies:
    """The soft bodies of a MujocoWorld (``world.soft``): planned with the spec, bound to the
    compiled model."""

    def __init__(self, world) -> None:
        self.world = world
        self.items: list[MjSoftBody] = []

    def plan(self, m, prefix: str, flexes: dict, losses) -> None:
        """The soft bodies of model ``m`` the writer made flexes of (``flexes``: identifier ->
        flexcomp name); each one it could not write, and each key it could not map, warned about."""
        w = self.world
        for sb in m.soft_bodies:
            if not sb.defined:
                continue
            mine = [loss for loss in losses if loss.element == sb.identifier]
            if sb.identifier not in flexes:
                why = next((loss.reason for loss in mine if loss.feature == "soft body"), "not written")
                w._warn("runner-soft-body", f"{sb.identifier}: {why}; skipped", sb)
                w.not_played.append({"object": sb.identifier, "what": "soft body", "why": why})
                continue
            key = w.registry.add(merge_namespace(m.namespace or "", sb.namespace) + sb.identifier, None)
            made = MjSoftBody(key, sb, m, prefix + flexes[sb.identifier], w)
            made.unmapped = [loss.feature for loss in mine if "no MuJoCo flex counterpart" in loss.reason]
            if made.unmapped:
                w._warn(
                    "runner-soft-body-approx",
                    f"{sb.identifier}: {', '.join(made.unmapped)} not played (no counterpart in a MuJoCo flex)",
                    sb,
                    "see docs/soft-bodies.md for what is mapped",
                )
            cfg = sb.config
            made.fixed = list(cfg.fixed_nodes or []) if cfg is not None else []
            self.items.append(made)

    def attach(self, spec, models, bodies_by_key) -> None:
        """Each joint of ``models`` between a soft body and a rigid body: ``connect`` equalities
        holding the soft body's nodes at the joint's pivot (plan.held_nodes) to the rigid body.
        A pinned node is fixed to the world already."""
        w = self.world
        by_soft = {id(s.soft): s for s in self.items}
        for m in models:
            for j in m.joints:
                soft, end = soft_end(m, j)
                if soft is None:
                    continue
                made = by_soft.get(id(soft))
                other = j.parent if end == "child" else j.child
                key, rigid = w.registry.find(other)
                if key is None:
                    key, rigid = w.registry.find(merge_namespace(m.namespace or "", j.namespace) + (other or ""))
                plan = bodies_by_key.get(key)
                if made is None or plan is None:
                    w._warn("runner-soft-joint", f"{j.identifier}: soft body or rigid body not found; not attached", j)
                    continue
                nodes = placed_soft_mesh(m, soft).nodes
                chosen = [int(i) for i in held_nodes(soft, j, end, nodes) if int(i) not in made.fixed]
                for i in chosen:
                    spec.add_equality(
                        type=mujoco.mjtEq.mjEQ_CONNECT,
                        name1=f"{made.flex}_{i}",
                        name2=plan.mjname,
                        objtype=mujoco.mjtObj.mjOBJ_BODY,
                        data=np.zeros(12),
                        solref=[HOLD_STEPS * w.dt, 1.0],  # stiff: MuJoCo's default 0.02 s let the node drift 13 mm
                    )
                made.attached.setdefault(key, []).extend(chosen)

    def bind(self, spec) -> None:
        """Flex ids, node and triangle counts and rest sizes from the compiled model."""
        m = self.world.model
        for s in self.items:
            s.young = float(spec.flex(s.flex).young)
            s.fid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_FLEX, s.flex)
            s.node_count = int(m.flex_vertnum[s.fid])
            s.triangles = int(m.flex_elemnum[s.fid])
            p = s.nodes()
            s.rest_size = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
            s.fixed = [i for i in s.fixed if 0 <= i < s.node_count]

    def lowest_z(self) -> float | None:
        zs = [float(s.nodes()[:, 2].min()) for s in self.items]
        return min(zs) if zs else None

    def report(self, floor_z: float) -> tuple[list[dict], list[str], list[str], list[str]]:
        """(per-soft-body entries, nan keys, exploded keys, fell-through-floor keys)."""
        return soft_report(self.items, floor_z, lambda s: {"young_modulus": s.young})


__all__ = ["MjSoftBody", "MjSoftBodies"]
