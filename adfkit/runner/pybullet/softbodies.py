"""Soft bodies (adf-format.md §7.8) in PyBullet's deformable world.

AMBF makes a btSoftBody (position-based links, Bullet's classic soft-body solver) from the
collision mesh. PyBullet's deformable world (``RESET_USE_DEFORMABLE_WORLD``) is a different
solver: implicit mass-spring on the same nodes and triangles. We map the ADF settings onto
it as follows (docs/soft-bodies.md gives the reasoning):

- nodes: the unique collision-mesh vertices (``adfkit.geometry.softmesh``), placed by
  `location` and `scale`, written to a temporary OBJ that ``loadSoftBody`` reads;
- `mass` → total mass (PyBullet spreads it over the nodes);
- `kLST` (1) and `piterations` (1) → spring stiffness k = (1 − (1 − kLST)^piterations)·m/dt²,
  m = mass per node, dt = the physics step: the share of a stretch Bullet's position solver
  removes in one step, removed by a spring in one step;
- `bending constraint` → bending springs of the same stiffness (Bullet gives bending links
  the same material; PyBullet links nodes two edges apart whatever the distance);
- `kDP` (0) → damping kDP·m/dt of the nodes' velocity in every direction (Bullet's kDP
  damps node velocity, not only along links); `kDF` (0.2) → friction; `collision margin` → margin;
- `fixed nodes` → anchors to the world; a joint between a rigid body and a soft body →
  the soft body's nodes at the joint's pivot anchored to the rigid body;
- `flags` bit CL_SELF (0x40) → self-collision.
Everything else a file sets (kAST, kVST, kVC, kPR, kMT, clusters, the hardness keys,
randomize constraints, ...) has no PyBullet counterpart and is reported once per soft body.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, field

import numpy as np
import pybullet as pb

from ... import scratch
from ...adf.paths import collision_mesh_path, visual_mesh_path
from ...diagnostics import AdfError
from ...geometry.softmesh import DEFAULT_SOFT_MASS, link_stiffness, placed_soft_mesh, write_obj
from ..names import merge_namespace
from ..plan import rgba
from ..soft import DEFAULT_MARGIN, held_nodes, soft_end, soft_report
from .meshfiles import obj_colour

CL_SELF = 0x40  # btSoftBody::fCollision::CL_SELF
ELASTIC_CAP = 0.4  # largest stable spring stiffness, in m_node/dt² (see parameters())
BENDING_CAP = 0.15
# ADF config keys the mapping above uses; every other key a file sets is reported as not played
MAPPED = {"kLST", "piterations", "bending constraint", "kDP", "kDF", "fixed nodes", "flags"}


@dataclass(eq=False)
class SimSoftBody:
    key: str
    soft: object  # the model's SoftBody
    model: object
    uid: int
    node_count: int
    triangles: int
    rest_size: float  # diagonal of the nodes' bounding box at build, m
    params: dict  # what loadSoftBody was given
    fixed: list = field(default_factory=list)
    attached: dict = field(default_factory=dict)  # rigid body key -> node indices
    unmapped: list = field(default_factory=list)

    cid: int = 0  # the PyBullet client

    def nodes(self, cid: int | None = None) -> np.ndarray:
        """Node positions in the world, (n, 3)."""
        cid = self.cid if cid is None else cid
        _, pos = pb.getMeshData(self.uid, -1, flags=pb.MESH_DATA_SIMULATION_MESH, physicsClientId=cid)
        return np.asarray(pos, dtype=float)


def enable_deformable_world(cid: int) -> None:
    """Must run before anything is created in the client (it resets the simulation)."""
    pb.resetSimulation(pb.RESET_USE_DEFORMABLE_WORLD, physicsClientId=cid)


class SoftBodies:
    """Builds and reports the soft bodies of a SimWorld (``world.soft``)."""

    def __init__(self, world) -> None:
        self.world = world
        self.items: list[SimSoftBody] = []
        self.joints: list[tuple] = []  # (model, joint) naming a soft body, claimed from the rigid build
        self._tmp = scratch.mkdtemp("adfkit-soft-")

    def claim(self, m, j) -> bool:
        """Keep a joint that joins a soft body (built as anchors later); False for rigid joints."""
        if soft_end(m, j)[0] is None:
            return False
        self.joints.append((m, j))
        return True

    # ---- building ------------------------------------------------------------------------
    def build(self, models) -> None:
        by_obj = {}
        for m in models:
            for sb in m.soft_bodies:
                if not sb.defined:
                    continue
                made = self._make(m, sb)
                if made is not None:
                    self.items.append(made)
                    by_obj[id(sb)] = made
        for m, j in self.joints:
            self._attach(m, j, by_obj)
        shutil.rmtree(self._tmp, ignore_errors=True)  # loadSoftBody has read the OBJ files
        planes = [b for b in self.world.bodies if getattr(b, "_parts", None) is not None and b._parts.plane is not None]
        if self.items and planes:
            self.world._warn(
                "runner-soft-plane",
                f"{', '.join(b.key for b in planes)}: PyBullet's soft bodies stop centimetres above a PLANE "
                "(36-100 mm measured)",
                planes[0].body,
                "give the floor a thick BOX collision shape instead",
            )

    def _make(self, m, sb) -> SimSoftBody | None:
        w = self.world
        if not sb.mesh:
            w._warn("runner-soft-body", f"{sb.identifier}: no mesh; skipped (AMBF skips it too)", sb)
            return None
        try:
            mesh = placed_soft_mesh(m, sb)
        except AdfError as exc:
            w._warn("runner-soft-body", f"{sb.identifier}: {exc.diagnostics[0].message}; skipped", sb)
            return None
        obj = write_obj(mesh, self._tmp / f"soft{len(self.items)}.obj")
        params = self.parameters(sb, mesh.node_count)
        uid = pb.loadSoftBody(str(obj), basePosition=[0, 0, 0], physicsClientId=w.cid, **params)
        if uid < 0:
            w._warn("runner-soft-body", f"{sb.identifier}: PyBullet could not load the soft body; skipped", sb)
            return None
        colour = rgba(sb)
        if colour is None and getattr(sb, "use_material", None) is not False:  # its mesh's material, as AMBF
            for where in (visual_mesh_path(m, sb), collision_mesh_path(m, sb)):
                if colour is None and where is not None:
                    colour = obj_colour(where, getattr(m, "tree", None))
        if colour is not None:
            pb.changeVisualShape(uid, -1, rgbaColor=colour, physicsClientId=w.cid)
        span = mesh.nodes.max(axis=0) - mesh.nodes.min(axis=0)
        key = w.registry.add(merge_namespace(m.namespace or "", sb.namespace) + sb.identifier, None)
        made = SimSoftBody(
            key, sb, m, uid, mesh.node_count, len(mesh.triangles), float(np.linalg.norm(span)), params, cid=w.cid
        )
        cfg = sb.config
        for i in (cfg.fixed_nodes or []) if cfg is not None else []:
            if 0 <= i < mesh.node_count:
                pb.createSoftBodyAnchor(uid, i, -1, -1, physicsClientId=w.cid)
                made.fixed.append(i)
            else:
                w._warn(
                    "runner-soft-body",
                    f"{sb.identifier}: fixed node {i} is not one of its {mesh.node_count} nodes; ignored",
                    cfg,
                )
        made.unmapped = self._unmapped(sb)
        if made.unmapped:
            w._warn(
                "runner-soft-body-approx",
                f"{sb.identifier}: {', '.join(made.unmapped)} not played "
                "(no counterpart in PyBullet's deformable world)",
                sb,
                "see docs/soft-bodies.md for what is mapped",
            )
        return made

    def parameters(self, sb, nodes: int) -> dict:
        """loadSoftBody keywords for a soft body of ``nodes`` nodes (the module doc's mapping)."""
        cfg = sb.config
        get = lambda k, d: getattr(cfg, k) if cfg is not None and getattr(cfg, k) is not None else d
        mass = sb.mass if sb.mass is not None and sb.mass > 0 else DEFAULT_SOFT_MASS
        dt = self.world.dt
        m_node = mass / max(nodes, 1)
        k = link_stiffness(sb, nodes, dt)
        bending = cfg is not None and cfg.bending_constraint is not None and cfg.bending_constraint >= 2
        margin = sb.collision_margin if sb.collision_margin is not None else DEFAULT_MARGIN
        # PyBullet's mass-spring solver diverges above about these stiffnesses (measured on a
        # 21 x 21 grid, 0.1 mm nodes: docs/soft-bodies.md); stiffer links are capped there
        k_bend = min(k, BENDING_CAP * m_node / dt**2)
        k = min(k, ELASTIC_CAP * m_node / dt**2)
        return dict(
            mass=float(mass),
            useMassSpring=1,
            useBendingSprings=int(bending),
            springElasticStiffness=float(k),
            springBendingStiffness=float(k_bend) if bending else 0.0,
            springDampingStiffness=float(min(max(get("kDP", 0.0), 0.0), 1.0) * m_node / dt),
            frictionCoeff=float(get("kDF", 0.2)),
            collisionMargin=float(margin),
            useSelfCollision=int(bool(get("flags", 1) & CL_SELF)),
            useFaceContact=1,
            springDampingAllDirections=1,
        )

    @staticmethod
    def _unmapped(sb) -> list[str]:
        out = []
        cfg = sb.config
        if cfg is not None:
            from ...model.spec import adf_fields

            for f in adf_fields(cfg):
                key = f.metadata["adf_key"]
                if key not in MAPPED and getattr(cfg, f.name) is not None:
                    out.append(f"config.{key}")
        if sb.randomize_constraints is not None:
            out.append("randomize constraints")
        if sb.gravity is not None:
            out.append("gravity (AMBF ignores it too)")
        return out

    def _attach(self, m, j, by_obj) -> None:
        w = self.world
        soft, end = soft_end(m, j)
        made = by_obj.get(id(soft))
        other_ref = j.parent if end == "child" else j.child
        key, rigid = w.registry.find(other_ref)
        if key is None:
            key, rigid = w.registry.find(merge_namespace(m.namespace or "", j.namespace) + (other_ref or ""))
        if made is None or key is None or rigid is None or rigid.uid is None:
            w._warn("runner-soft-joint", f"{j.identifier}: soft body or rigid body not found; not attached", j)
            return
        chosen = held_nodes(soft, j, end, made.nodes())
        for i in chosen:
            pb.createSoftBodyAnchor(made.uid, int(i), rigid.uid, rigid.link, physicsClientId=w.cid)
        made.attached.setdefault(key, []).extend(int(i) for i in chosen)

    def ground_slab(self, top_z: float, half: float = 50.0, thickness: float = 1.0) -> int:
        """A static box whose top is at ``top_z``: the floor of a deformable world. (PyBullet's
        soft bodies stop well above a GEOM_PLANE, measured 36 mm above one at z = -0.036 and
        100 mm above one at z = -0.5, and that contact is several times slower; on a box they
        rest within the collision margin.)"""
        cid = self.world.cid
        shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[half, half, thickness / 2], physicsClientId=cid)
        return pb.createMultiBody(0.0, shape, -1, [0.0, 0.0, top_z - thickness / 2], physicsClientId=cid)

    # ---- queries -------------------------------------------------------------------------
    def lowest_z(self) -> float | None:
        zs = [float(s.nodes()[:, 2].min()) for s in self.items]
        return min(zs) if zs else None

    def report(self, floor_z: float) -> tuple[list[dict], list[str], list[str], list[str]]:
        """(per-soft-body entries, nan keys, exploded keys, fell-through-floor keys)."""
        return soft_report(self.items, floor_z, lambda s: {"spring_stiffness": s.params["springElasticStiffness"]})

    def close(self) -> None:
        shutil.rmtree(self._tmp, ignore_errors=True)


__all__ = ["SimSoftBody", "SoftBodies", "enable_deformable_world"]
