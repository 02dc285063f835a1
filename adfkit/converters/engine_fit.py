"""What the target engines accept, checked before a URDF or MJCF file is written.

A converted file must load in its engine (PyBullet for URDF, MuJoCo for MJCF), or a loss says
why a part of it was changed or left out:

- a body ``scale`` that is not a positive finite number, or so large that coordinates
  overflow, is written as 1 (the engines would read inf/NaN);
- joint limits with ``low > high`` (Bullet, so AMBF, then applies no limit; MuJoCo refuses
  such a ``range``) or non-finite limits are written as no limit;
- a mesh in a format the engine does not read (.3DS, .DAE, .PLY, ...) is converted to STL
  with trimesh beside the output file, or left out when trimesh cannot read it either;
- (MJCF) a flat mesh, which MuJoCo cannot take as a collision hull, collides as a thin box
  around it; as a visual mesh it gets ``inertia="shell"`` (its volume is zero).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from .. import inputs
from ..adf.writer import atomic_write_bytes
from ..diagnostics import AdfError
from ..geometry.meshcheck import is_ascii_stl, mesh_problem
from .losses import Loss

#: Mesh file suffixes each engine reads itself.
ENGINE_SUFFIXES = {"urdf": (".stl", ".obj"), "mjcf": (".stl", ".obj", ".msh")}
#: Largest usable body scale (coordinates beyond ~1e6 m overflow float32 contact math).
MAX_SCALE = 1e6
#: Thickness of the box a flat collision mesh becomes, relative to its largest side.
FLAT_THICKNESS = 1e-3


def usable_scales(model, losses: list[Loss]):
    """``model`` itself, or a copy whose bodies with an unusable ``scale`` have scale 1."""
    bad = [
        b for b in model.bodies if b.scale is not None and not (math.isfinite(b.scale) and 0.0 < b.scale <= MAX_SCALE)
    ]
    if not bad:
        return model
    for b in bad:
        losses.append(
            Loss(
                b.identifier,
                "scale",
                f"{b.scale!r} is not a positive finite scale up to {MAX_SCALE:g} "
                "(the engine's coordinates would overflow): written as 1",
            )
        )
    swap = {id(b): replace(b, scale=None) for b in bad}
    return replace(model, bodies=[swap.get(id(b), b) for b in model.bodies])


def joint_range(joint, losses: list[Loss]) -> tuple[float, float] | None:
    """The joint's (low, high) when both are set, finite and ordered (equal ones a hair apart);
    else None (with a loss for limits that are set but unusable)."""
    lim = joint.joint_limits
    if lim is None or lim.low is None or lim.high is None:
        return None
    low, high = lim.low, lim.high
    if not (math.isfinite(low) and math.isfinite(high)):
        losses.append(Loss(joint.identifier, "joint limits", f"not finite ({low!r}, {high!r}): written as no limit"))
        return None
    if low > high:
        losses.append(
            Loss(
                joint.identifier,
                "joint limits",
                f"low {low!r} > high {high!r}: Bullet (and so AMBF) applies no limit then; written as no limit",
            )
        )
        return None
    if low == high:  # Bullet holds the joint there; MuJoCo refuses a range that is not low < high
        losses.append(
            Loss(
                joint.identifier,
                "joint limits",
                f"low = high = {low!r} (the joint held there): written {LOCKED_RANGE:g} wide about it",
            )
        )
        return low - LOCKED_RANGE / 2, high + LOCKED_RANGE / 2
    return low, high


#: rad or m, the width of the range written for a joint whose limits are equal (MuJoCo needs low < high)
LOCKED_RANGE = 1e-6


class MeshFiles:
    """Engine-readable mesh files for one output file; converted copies go to
    ``<output stem>_meshes/`` beside it. ``fit`` answers (path or None, flat?)."""

    def __init__(self, engine: str, out_dir: Path, stem: str, tree=None):
        self.engine = engine
        self.tree = tree  # the model's input tree (adfkit.inputs): meshes are read only inside it
        self.folder = out_dir / f"{stem}_meshes"
        self._done: dict[str, tuple[Path | None, bool, object]] = {}

    def _load(self, path: Path):
        from ..diagnostics import AdfError

        try:
            from ..geometry.meshio import load_mesh

            return load_mesh(path, tree=self.tree), None
        except AdfError as exc:
            return None, exc.diagnostics[0].message
        except ImportError:
            return None, "trimesh is not installed"

    def fit(self, path: Path, who: str, losses: list[Loss], check_flat: bool = False) -> tuple[Path | None, object]:
        """(file the engine reads, or None; the mesh when it is flat and ``check_flat``, else None)."""
        key = str(path)
        if key not in self._done:
            try:  # a NUL byte or an over-long name is no file name at all
                inputs.check_path_text(path)
            except AdfError as exc:
                losses.append(Loss(who, "mesh", f"{exc.diagnostics[0].message}: left out"))
                self._done[key] = (None, False, None)
                return None, None
            try:  # only a file the input policy lets in is read here
                inputs.check_file(path, "mesh", tree=self.tree, what="mesh file")
                let_in = True
            except AdfError as exc:
                d = exc.diagnostics[0]
                if d.rule != "outside-tree":  # missing, not a file: left out, so the output loads
                    why = f"{inputs.shown(path)} not found" if d.rule == "file-not-found" else d.message
                    losses.append(Loss(who, "mesh", f"{why}: left out"))
                    self._done[key] = (None, False, None)
                    return None, None
                let_in = False  # outside the model's tree: named as it is, never opened
            if let_in and (problem := mesh_problem(path)) is not None:  # no triangles, a face naming no vertex
                losses.append(Loss(who, "mesh", f"{inputs.shown(path.name)}: {problem}: left out"))
                self._done[key] = (None, False, None)
                return None, None
            ascii_stl = let_in and self.engine == "mjcf" and path.suffix.lower() == ".stl" and is_ascii_stl(path)
            readable = path.suffix.lower() in ENGINE_SUFFIXES[self.engine] and not ascii_stl
            mesh = None
            if not readable or check_flat:
                if path.is_file():
                    mesh, why = self._load(path)
                else:
                    why = "file not found"
            out: Path | None = path
            if not readable:
                if mesh is None:
                    losses.append(
                        Loss(
                            who,
                            "mesh",
                            f"{path.name}: {path.suffix or 'this'} format is not read by "
                            f"{'PyBullet' if self.engine == 'urdf' else 'MuJoCo'} and could "
                            f"not be converted ({why}): left out",
                        )
                    )
                    out = None
                else:
                    out = self.folder / (path.stem + ".stl")
                    n = 1
                    while any(v[0] == out for v in self._done.values()):
                        n += 1
                        out = self.folder / f"{path.stem}_{n}.stl"
                    self.folder.mkdir(parents=True, exist_ok=True)
                    atomic_write_bytes(out, mesh.export(file_type="stl"))
                    what = (
                        "MuJoCo reads binary STL only: converted"
                        if ascii_stl
                        else f"{path.suffix} is not read by the engine: converted"
                    )
                    losses.append(
                        Loss(
                            who,
                            "mesh",
                            f"{path.name}: {what} to {out.parent.name}/{out.name} (normals, UVs and materials dropped)",
                        )
                    )
            flat = mesh if (mesh is not None and _is_flat(mesh)) else None
            self._done[key] = (out, flat is not None, flat)
        out, is_flat, flat = self._done[key]
        return out, flat if (check_flat and is_flat) else None


def obj_objects(text: str) -> list[tuple[list, list]]:
    """The sub-meshes of a Wavefront OBJ text that collide as hulls of their own: each object's
    faces of each material (``adfkit.geometry.objpieces``), each as (vertices, faces with indices
    into its own vertices); one entry when the file has one object and one material."""
    from ..geometry.objpieces import obj_pieces

    return obj_pieces(text)


def split_objects(path: Path, folder: Path) -> list[Path]:
    """An OBJ file of several sub-meshes (a convex decomposition: one hull per object; or one
    object of several materials) as one OBJ per sub-mesh in ``folder``; [path] itself when it
    holds one or is no OBJ."""
    if path.suffix.lower() != ".obj" or not path.is_file():
        return [path]
    try:
        objs = obj_objects(path.read_text(encoding="utf-8", errors="replace"))
    except ValueError:  # a face that names no vertex: MeshFiles.fit left such a mesh out already
        return [path]
    if len(objs) < 2:
        return [path]
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for n, (v, f) in enumerate(objs):
        p = folder / f"{path.stem}_part{n:03d}.obj"
        text = "".join(f"v {' '.join(x)}\n" for x in v) + "".join(
            "f " + " ".join(str(i + 1) for i in face) + "\n" for face in f
        )
        atomic_write_bytes(p, text.encode())
        out.append(p)
    return out


def concave_parts(model, body, cmesh: Path, folder: Path, losses: list[Loss]) -> list[Path] | None:
    """The convex parts a moving body's concave collision mesh ``cmesh`` collides as in the
    engines (``geometry.concave``: the runner's decision), one mesh file each in ``folder``, with
    a ``concave collision mesh`` loss; None where its hull per sub-mesh stands in."""
    from ..geometry.concave import body_parts
    from ..geometry.decompose import write_hull_files

    stand_in = body_parts(model, body)
    if stand_in is None:
        return None
    folder.mkdir(parents=True, exist_ok=True)
    losses.append(
        Loss(body.identifier, "concave collision mesh", f"{stand_in.describe()} (AMBF collides the mesh itself)")
    )
    return write_hull_files(stand_in.hulls, folder, f"{cmesh.stem.replace(' ', '_')}_convex")


def _is_flat(mesh) -> bool:
    """True when the mesh spans (almost) no volume: all its vertices on one plane."""
    import numpy as np

    v = np.asarray(mesh.vertices, dtype=float)
    if len(v) < 4:
        return True
    c = v - v.mean(axis=0)
    s = np.linalg.svd(c, compute_uv=False)
    return bool(s[0] == 0.0 or s[2] <= 1e-9 * s[0])


def flat_box(mesh, scale: float):
    """(centre, rotation matrix, full sizes) of the thin box that stands in for a flat mesh:
    the smallest rectangle around it in its plane, ``FLAT_THICKNESS`` of its size thick."""
    import numpy as np
    from trimesh.bounds import oriented_bounds_2D

    v = np.asarray(mesh.vertices, dtype=float) * scale
    mean = v.mean(axis=0)
    _u, _s, vt = np.linalg.svd(v - mean, full_matrices=True)  # 3x3: a plane even for < 3 vertices
    e1, e2 = vt[0], vt[1]
    normal = np.cross(e1, e2)
    flat2d = np.column_stack(((v - mean) @ e1, (v - mean) @ e2))
    spread = np.linalg.svd(flat2d - flat2d.mean(axis=0), compute_uv=False) if len(flat2d) > 1 else np.zeros(2)
    if len(flat2d) < 3 or spread[-1] <= 1e-12 * max(spread[0], 1e-300):
        # a point or a line (a garbage mesh): its bounds in the plane, no rectangle to fit
        lo, hi = flat2d.min(axis=0), flat2d.max(axis=0)
        c2, a2, extents = (lo + hi) / 2, np.array([1.0, 0.0]), hi - lo
    else:
        to_rect, extents = oriented_bounds_2D(flat2d)  # 3x3 homogeneous: points -> rectangle frame
        back = np.linalg.inv(to_rect)
        c2 = back[:2, 2]
        a2 = back[:2, 0]
    u = a2[0] * e1 + a2[1] * e2
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    rot = np.column_stack((u, w, normal))
    centre = mean + c2[0] * e1 + c2[1] * e2
    thick = (v - mean) @ normal
    centre = centre + normal * (thick.max() + thick.min()) / 2
    sizes = np.array(
        [extents[0], extents[1], max(thick.max() - thick.min(), FLAT_THICKNESS * max(extents.max(), 1e-6))]
    )
    return centre, rot, sizes
