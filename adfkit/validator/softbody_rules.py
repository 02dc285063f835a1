"""Rules for soft bodies (adf-format.md §7.8): what AMBF needs to build a btSoftBody, and
values Bullet documents as coefficients in [0, 1].

``check`` works on the model alone; ``mesh_rules`` opens the collision mesh (only when a
soft body names fixed nodes) to check node indices against the nodes AMBF will make.
"""

from __future__ import annotations

from ..adf.paths import collision_mesh_path
from ..diagnostics import AdfError, Diagnostic, SourceLocation
from ..geometry.softnodes import node_count
from ..model import ModelFile
from .rules import RULES

# Bullet's documented ranges (btSoftBody.h): material stiffness and these coefficients are
# fractions in [0, 1]; kDG, kLF, kVC are >= 0; kPR may take any sign.
UNIT_INTERVAL = (
    "kLST",
    "kAST",
    "kVST",
    "kDP",
    "kDF",
    "kMT",
    "kCHR",
    "kKHR",
    "kSHR",
    "kAHR",
    "kSRHR_CL",
    "kSKHR_CL",
    "kSSHR_CL",
    "kSR_SPLT_CL",
    "kSK_SPLT_CL",
    "kSS_SPLT_CL",
)
NON_NEGATIVE = ("kDG", "kLF", "kVC", "kVCF", "maxvolume", "timescale")
ITERATIONS = ("viterations", "piterations", "diterations", "citerations")


def _d(rule: str, message: str, loc: SourceLocation | None, file: str, hint: str | None = None) -> Diagnostic:
    return Diagnostic(RULES[rule].severity, rule, message, loc or SourceLocation(file, 1, 1), hint)


def check(m: ModelFile) -> list[Diagnostic]:
    """Model-only soft-body rules."""
    file = str(m.path) if m.path else "<input>"
    out: list[Diagnostic] = []
    for sb in m.soft_bodies:
        if not sb.defined:
            continue
        who = f"soft body '{sb.identifier}'"
        out.append(
            _d(
                "rigid-through-soft-body",
                f"{who}: in AMBF 2.0 rigid bodies pass through it: Bullet 2.88's soft-body collision (its sparse "
                "distance field) sees convex shapes only, and AMBF wraps every body's shape in a compound (a lone "
                "PLANE aside); adfkit's engines collide it with every rigid body",
                sb.where(),
                file,
                "in AMBF, hold it up with `fixed nodes` and do not rely on it to stop a rigid body",
            )
        )
        if not sb.mesh:
            out.append(
                _d(
                    "soft-body-mesh",
                    f"{who} has no `mesh`; AMBF builds soft bodies from a mesh only and skips it",
                    sb.where("mesh") if sb.mesh is not None else sb.where(),
                    file,
                    "name a triangle mesh (its collision mesh gives the nodes)",
                )
            )
        elif sb.collision_shape or sb.compound_collision_shape:
            out.append(
                _d(
                    "soft-body-mesh",
                    f"{who}: a collision primitive is not used; the soft body is generated from the collision mesh",
                    sb.where("collision shape") if sb.collision_shape else sb.where("compound collision shape"),
                    file,
                    "remove the primitive; use `collision mesh` for a coarser node mesh",
                )
            )
        if sb.mass is None:
            out.append(
                _d(
                    "soft-body-mass",
                    f"{who} has no mass; AMBF uses 1 kg",
                    sb.where(),
                    file,
                    "add `mass:` (the total over all nodes)",
                )
            )
        elif sb.mass <= 0:
            out.append(
                _d(
                    "soft-body-mass",
                    f"{who} has mass {sb.mass:g}; a soft body needs a positive total mass "
                    "(use `fixed nodes` to pin nodes)",
                    sb.where("mass"),
                    file,
                    "give a positive mass in kg",
                )
            )
        cfg = sb.config
        if cfg is None:
            continue
        for key in UNIT_INTERVAL + NON_NEGATIVE:
            v = getattr(cfg, key)
            if v is None:
                continue
            if key in UNIT_INTERVAL and not 0.0 <= v <= 1.0:
                out.append(
                    _d(
                        "soft-body-coefficient",
                        f"{who}: config `{key}` is {v:g}, outside Bullet's range 0..1",
                        cfg.where(key),
                        file,
                        "stiffness, damping, friction and hardness are fractions in 0..1",
                    )
                )
            elif key in NON_NEGATIVE and v < 0:
                out.append(
                    _d(
                        "soft-body-coefficient",
                        f"{who}: config `{key}` is {v:g}; Bullet expects >= 0",
                        cfg.where(key),
                        file,
                        "use a non-negative value",
                    )
                )
        for key in ITERATIONS:
            v = getattr(cfg, key)
            if v is not None and v < 0:
                out.append(
                    _d(
                        "soft-body-iterations",
                        f"{who}: config `{key}` is {v}; iterations are >= 0",
                        cfg.where(key),
                        file,
                        "use 0 or more",
                    )
                )
        if cfg.piterations == 0:
            out.append(
                _d(
                    "soft-body-iterations",
                    f"{who}: `piterations: 0` solves no link constraint; the soft body falls apart",
                    cfg.where("piterations"),
                    file,
                    "use 1 or more (AMBF's corpus uses 6)",
                )
            )
        if cfg.bending_constraint is not None and cfg.bending_constraint < 2:
            out.append(
                _d(
                    "soft-body-iterations",
                    f"{who}: `bending constraint: {cfg.bending_constraint}` adds no "
                    "link (Bullet links nodes 2 or more edges apart)",
                    cfg.where("bending constraint"),
                    file,
                    "use 2 for bending resistance, or remove the key",
                )
            )
        if cfg.clusters is not None and cfg.clusters < 0:
            out.append(
                _d(
                    "soft-body-iterations",
                    f"{who}: `clusters: {cfg.clusters}` is negative",
                    cfg.where("clusters"),
                    file,
                    "use a positive cluster count, or remove the key",
                )
            )
    return out


def mesh_rules(m: ModelFile) -> list[Diagnostic]:
    """`fixed nodes` against the nodes of the collision mesh (when the file is readable)."""
    file = str(m.path) if m.path else "<input>"
    out: list[Diagnostic] = []
    for sb in m.soft_bodies:
        cfg = sb.config
        if not sb.defined or cfg is None or not cfg.fixed_nodes or not sb.mesh:
            continue
        path = collision_mesh_path(m, sb)
        if path is None:
            continue  # missing-mesh says so
        tree = getattr(m, "tree", None)
        try:  # through the input policy: a mesh outside the tree, a device or a bad name is not read
            n = node_count(path, tree)
            if n is None:  # numpy and trimesh, only when a format other than 3DS needs them
                from ..geometry.softmesh import load_soft_mesh  # noqa: PLC0415

                n = load_soft_mesh(path, sb.scale or 1.0, tree=tree).node_count
        except AdfError:
            continue  # the path rules report why it cannot be read
        bad = [i for i in cfg.fixed_nodes if not 0 <= i < n]
        if bad:
            out.append(
                _d(
                    "soft-body-fixed-nodes",
                    f"soft body '{sb.identifier}': fixed node(s) "
                    f"{', '.join(map(str, bad[:5]))}{' ...' if len(bad) > 5 else ''} outside the "
                    f"{n} nodes of {path.name} (0..{n - 1}); AMBF writes past the node array",
                    cfg.where("fixed nodes"),
                    file,
                    "node indices count the mesh's unique vertices from 0",
                )
            )
    return out


__all__ = ["check", "mesh_rules", "UNIT_INTERVAL"]
