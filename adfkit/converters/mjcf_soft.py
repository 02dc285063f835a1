"""ADF soft bodies → MuJoCo ``flexcomp`` (format-mapping.md; docs/soft-bodies.md).

A soft body becomes a 2-D flex (``type="direct"``, ``dim="2"``) on the nodes AMBF makes of
its collision mesh (unique vertices, placed by `location` and `scale`) and its triangles, in
``<worldbody>``. Where the mapping holds:

- `mass` → ``mass`` (MuJoCo spreads it over the vertices); `fixed nodes` → ``<pin id>``;
- `kLST` and `piterations` → the same spring stiffness the PyBullet runner uses,
  k = (1 − (1 − kLST)^piterations)·m/dt² (m per node, dt AMBF's 1 ms step), written as
  ``<elasticity young=k/thickness thickness>`` (a membrane of Young's modulus E and
  thickness t resists stretch about like edges of stiffness E·t; t is twice the collision
  margin, at most 2 mm: MAX_THICKNESS);
- `bending constraint` → ``elastic2d="both"`` (bending from the same modulus), else ``"stretch"``;
- `kDP` → ``elasticity damping``; `kDF` → contact ``friction``; `collision margin` →
  ``radius``: a node rests that far from what it touches, as on Bullet's margin (a contact
  ``margin`` as well held a pad on a tray twice as high: 2 mm against PyBullet's 1 mm);
  `flags` bit CL_SELF → ``selfcollide``.
Everything else a file sets is a named loss, as is a soft body whose mesh cannot be read
and a joint between a soft body and a rigid body.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from ..diagnostics import AdfError
from ..model.files import ModelFile
from ..model.spec import adf_fields
from .losses import Loss
from .urdf import _material, _num

AMBF_DT = 0.001  # AMBF's fixed internal step, s
DEFAULT_MARGIN = 0.001  # adf-format.md §7.4
CL_SELF = 0x40  # btSoftBody::fCollision::CL_SELF
MAPPED = {"kLST", "piterations", "bending constraint", "kDP", "kDF", "fixed nodes", "flags"}
# the membrane's thickness t sets its bending stiffness (E·t³/12 with E·t kept at k): twice the
# collision margin, at most this. Measured on the corpus cloth2 (0.1 m margin): t = 0.2 or even
# 0.02 m left MuJoCo's discrete integrator unable to solve M + K (a singular-inertia warning every
# step, the cloth stretched to 2x), 2 mm plays it; AMBF's bending links barely resist a small fold
MAX_THICKNESS = 0.002


def _flex_name(identifier: str, used: set[str]) -> str:
    base = re.sub(r"[^A-Za-z0-9_]+", "_", identifier).strip("_") or "soft"
    name, n = base, 1
    while name in used:
        n += 1
        name = f"{base}_{n}"
    used.add(name)
    return name


def write_soft_bodies(
    model: ModelFile, world: ET.Element, used: dict, losses: list[Loss], flexes_out: dict | None = None
) -> int:
    """Append a flexcomp per soft body to ``world``; returns how many were written.
    ``flexes_out`` receives {soft body identifier: flexcomp name}."""
    from ..geometry.softmesh import link_stiffness, placed_soft_mesh  # noqa: PLC0415 - numpy/trimesh at the edge

    flex_names = used.setdefault("flex", set())
    written = 0
    for sb in model.soft_bodies:
        if not sb.defined:
            continue
        who = sb.identifier
        try:
            mesh = placed_soft_mesh(model, sb)
        except AdfError as exc:
            losses.append(Loss(who, "soft body", f"not written: {exc.diagnostics[0].message}"))
            continue
        cfg = sb.config
        get = lambda k, d, cfg=cfg: getattr(cfg, k) if cfg is not None and getattr(cfg, k) is not None else d
        margin = sb.collision_margin if sb.collision_margin is not None else DEFAULT_MARGIN
        thickness = min(2.0 * margin, MAX_THICKNESS)
        k = link_stiffness(sb, mesh.node_count, AMBF_DT)
        bending = get("bending_constraint", 0) >= 2
        flex = _flex_name(sb.name or who, flex_names)
        if flexes_out is not None:
            flexes_out[who] = flex
        fc = ET.SubElement(
            world,
            "flexcomp",
            name=flex,
            type="direct",
            dim="2",
            radius=_num(margin),
            point=" ".join(_num(round(float(x), 9)) for x in mesh.nodes.reshape(-1)),
            element=" ".join(str(int(i)) for i in mesh.triangles.reshape(-1)),
        )
        if sb.mass is not None and sb.mass > 0:
            fc.set("mass", _num(sb.mass))
        rgba = _material(sb)
        if rgba is not None:
            fc.set("rgba", " ".join(_num(x) for x in rgba))
        ET.SubElement(
            fc,
            "elasticity",
            young=_num(k / thickness),
            poisson="0.0",
            thickness=_num(thickness),
            damping=_num(min(max(get("kDP", 0.0), 0.0), 1.0) * AMBF_DT),
            elastic2d="both" if bending else "stretch",
        )
        ET.SubElement(
            fc,
            "contact",
            friction=_num(get("kDF", 0.2)),
            selfcollide="auto" if get("flags", 1) & CL_SELF else "none",
        )
        fixed = [i for i in (cfg.fixed_nodes or []) if 0 <= i < mesh.node_count] if cfg is not None else []
        if fixed:
            ET.SubElement(fc, "pin", id=" ".join(map(str, fixed)))
        if cfg is not None and len(fixed) != len(cfg.fixed_nodes or []):
            losses.append(Loss(who, "fixed nodes", f"indices outside the {mesh.node_count} nodes are dropped"))
        for key in _unmapped(sb):
            losses.append(Loss(who, key, "no MuJoCo flex counterpart"))
        if sb.mass is None:
            losses.append(Loss(who, "mass", "not in the ADF file: MuJoCo's default flex mass is written (AMBF: 1 kg)"))
        losses.append(
            Loss(
                who,
                "soft body",
                "Bullet's position-based links become a MuJoCo flex membrane "
                "(elasticity from kLST and piterations; docs/soft-bodies.md)",
            )
        )
        written += 1
    return written


def _unmapped(sb) -> list[str]:
    out = []
    if sb.config is not None:
        for f in adf_fields(sb.config):
            key = f.metadata["adf_key"]
            if key not in MAPPED and getattr(sb.config, f.name) is not None:
                out.append(f"config.{key}")
    if sb.randomize_constraints is not None:
        out.append("randomize constraints")
    for attr, key in (("collision_groups", "collision groups"), ("plugins", "plugins")):
        if getattr(sb, attr) not in (None, []):
            out.append(key)
    off = sb.inertial_offset
    if off is not None and (off.position.norm() > 1e-12 or off.orientation.angle_to(type(off.orientation)()) > 1e-12):
        out.append("inertial offset")
    return out


__all__ = ["write_soft_bodies"]
