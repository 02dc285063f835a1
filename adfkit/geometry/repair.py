"""Making a mesh closed and manifold before decomposition or mass computation.

trimesh does the cheap clean-up (merge vertices, drop degenerate and duplicate faces, make
the winding consistent and outward, fill simple holes); manifold3d then checks the result is
a 2-manifold and unions overlapping shells so their volume is not counted twice. What was
changed is reported in a ``RepairReport``. A mesh manifold3d still rejects after that is
"beyond repair": ``AdfError`` with rule ``mesh-not-manifold``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import manifold3d
import numpy as np
import trimesh

from ..diagnostics import AdfError, SourceLocation, error


@dataclass
class RepairReport:
    vertices_merged: int = 0
    faces_removed: int = 0  # degenerate or duplicate triangles
    faces_flipped: bool = False  # winding made consistent / turned outwards
    holes_filled: int = 0  # faces added to close holes
    shells_unioned: int = 0  # overlapping closed shells merged into one solid
    volume_before: float = float("nan")
    volume_after: float = float("nan")
    notes: list[str] = field(default_factory=list)

    @property
    def changed(self) -> bool:
        return bool(
            self.vertices_merged or self.faces_removed or self.faces_flipped or self.holes_filled or self.shells_unioned
        )

    def summary(self) -> str:
        if not self.changed:
            return "mesh already closed and manifold"
        parts = []
        if self.vertices_merged:
            parts.append(f"merged {self.vertices_merged} duplicate vertices")
        if self.faces_removed:
            parts.append(f"removed {self.faces_removed} degenerate/duplicate faces")
        if self.faces_flipped:
            parts.append("fixed face winding")
        if self.holes_filled:
            parts.append(f"filled holes with {self.holes_filled} faces")
        if self.shells_unioned:
            parts.append(f"unioned {self.shells_unioned} overlapping shells")
        return "; ".join(parts) + f" (volume {self.volume_before:.6g} -> {self.volume_after:.6g} m³)"


def to_manifold(mesh: trimesh.Trimesh) -> manifold3d.Manifold:
    # Mesh64 keeps double precision: corpus meshes are in metres with millimetre detail.
    return manifold3d.Manifold(
        manifold3d.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
        )
    )


def from_manifold(m: manifold3d.Manifold) -> trimesh.Trimesh:
    out = m.to_mesh64()
    return trimesh.Trimesh(
        vertices=np.asarray(out.vert_properties)[:, :3].astype(np.float64),
        faces=np.asarray(out.tri_verts, dtype=np.int64),
        process=True,
    )


def _not_manifold(mesh, why: str) -> AdfError:
    where = mesh.metadata.get("file_path")
    return AdfError(
        error(
            "mesh-not-manifold",
            f"the mesh cannot be made a closed 2-manifold: {why}",
            SourceLocation(where) if where else None,
            "close the mesh in a modelling tool (e.g. Blender's 3D-Print toolbox) or use a primitive collision shape",
        )
    )


def repair_mesh(mesh: trimesh.Trimesh) -> tuple[trimesh.Trimesh, RepairReport]:
    """A closed, outward-facing, self-union'd copy of ``mesh`` and what was done to it."""
    report = RepairReport()
    work = mesh.copy()
    report.volume_before = float(work.volume) if work.is_watertight else float("nan")

    n_vertices, n_faces = len(work.vertices), len(work.faces)
    work.merge_vertices(merge_tex=True, merge_norm=True)
    report.vertices_merged = n_vertices - len(work.vertices)
    if not (work.is_watertight and work.is_winding_consistent):
        # Dropping zero-area faces from a closed mesh would open slits, so only when open.
        work.update_faces(work.nondegenerate_faces(height=1e-12))
        work.update_faces(work.unique_faces())
        work.remove_unreferenced_vertices()
    report.faces_removed = n_faces - len(work.faces)
    if len(work.faces) == 0:
        raise _not_manifold(mesh, "no faces left after removing degenerate ones")

    before = work.faces.copy()
    if not work.is_winding_consistent:
        trimesh.repair.fix_winding(work)
    if not work.is_watertight:
        n = len(work.faces)
        trimesh.repair.fill_holes(work)
        report.holes_filled = len(work.faces) - n
    if work.is_watertight:
        trimesh.repair.fix_inversion(work, multibody=True)
    report.faces_flipped = len(before) == len(work.faces[: len(before)]) and not np.array_equal(
        before, work.faces[: len(before)]
    )

    if not work.is_watertight:
        raise _not_manifold(mesh, f"{_open_edges(work)} open edges remain after filling holes")

    shells = work.split(only_watertight=False) if work.body_count > 1 else [work]
    solids = []
    for shell in shells:
        m = to_manifold(shell)
        if m.status() != manifold3d.Error.NoError:
            raise _not_manifold(mesh, f"manifold3d says {m.status().name}")
        solids.append(m)
    if len(solids) > 1:
        solid = manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add)
        out = from_manifold(solid)
        if abs(out.volume - sum(s.volume() for s in solids)) > 1e-9 * max(abs(out.volume), 1e-30):
            report.shells_unioned = len(solids)
        else:
            out = work  # disjoint shells: keep the original triangles
    else:
        out = work
    report.volume_after = float(out.volume)
    if report.volume_after <= 0:
        raise _not_manifold(mesh, f"it encloses no volume ({report.volume_after:g} m³)")
    out.metadata.update(mesh.metadata)
    return out, report


def _open_edges(mesh: trimesh.Trimesh) -> int:
    edges = mesh.edges_sorted
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts != 2).sum())


def manifold_volume(meshes: list[trimesh.Trimesh]) -> float:
    """Volume of the boolean union of closed meshes (manifold3d)."""
    solids = [to_manifold(m) for m in meshes]
    return float(manifold3d.Manifold.batch_boolean(solids, manifold3d.OpType.Add).volume())
