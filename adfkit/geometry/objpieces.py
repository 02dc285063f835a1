"""The convex pieces of an OBJ collision mesh as AMBF makes them: a collision hull is built per
sub-mesh, and AMBF's mesh loader (CHAI3D) makes a sub-mesh of each object's faces of each
material. PyBullet, MuJoCo (through the MJCF writer) and the suture planner's clearance all
take their pieces from here, so an OBJ of one object with faces of several materials (the
corpus suturing set's needle and phantom collision meshes) is several hulls in each, as in
AMBF, not the hull of them all (a curved needle's fills its arc; a phantom's covers its holes)."""

from __future__ import annotations


def obj_pieces(text: str) -> list[tuple[list, list]]:
    """The sub-meshes of a Wavefront OBJ text: the faces of each object (``o``/``g``) of each
    material (``usemtl``), in the order they first appear, each as (vertices as strings, faces
    with indices into its own vertices). One entry when the file has one object and material.
    ValueError for a face corner that names no vertex of the file (geometry.meshcheck says so
    first, where it is asked)."""
    verts: list[list[str]] = []
    groups: dict[tuple[str, str], list[list[int]]] = {}
    obj, mtl = "", ""
    for line in text.splitlines():
        head, _, rest = line.strip().partition(" ")
        if head == "v":
            verts.append(rest.split()[:3])
        elif head in ("o", "g"):
            obj = rest.strip()
        elif head == "usemtl":
            mtl = rest.strip()
        elif head == "f":
            idx = []
            for tok in rest.split():
                i = int(tok.split("/")[0])
                idx.append(i - 1 if i > 0 else len(verts) + i)
            groups.setdefault((obj, mtl), []).append(idx)
    out = []
    for fs in groups.values():
        used = sorted({i for f in fs for i in f})
        if used and not (0 <= used[0] and used[-1] < len(verts)):
            bad = used[-1] + 1 if used[-1] >= len(verts) else used[0] - len(verts)
            raise ValueError(f"a face names vertex {bad}; the file has {len(verts)} vertices")
        remap = {old: new for new, old in enumerate(used)}
        out.append(([verts[i] for i in used], [[remap[i] for i in f] for f in fs]))
    return out


def pieces_obj_text(pieces: list[tuple[list, list]]) -> str:
    """An OBJ text with each piece an object of its own (vertex positions and faces only)."""
    lines, base = [], 0
    for n, (v, f) in enumerate(pieces):
        lines.append(f"o piece_{n}")
        lines += [f"v {' '.join(x)}" for x in v]
        lines += ["f " + " ".join(str(base + i + 1) for i in face) for face in f]
        base += len(v)
    return "\n".join(lines) + "\n"
