"""Blender meshes to files: OBJ + MTL (base-colour texture, normal map), or STL, PLY, 3DS
(adfkit.geometry.meshwrite), and content hashes (sha-256 of the bytes written).

``mesh_arrays`` is the only Blender-level function; the OBJ/MTL text writers are plain
Python over NumPy arrays, so exports of unchanged meshes can be skipped by hash.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from adfkit.adf.writer import atomic_write_bytes


@dataclass
class MeshArrays:
    name: str
    co: np.ndarray  # (n, 3) float32 vertex positions in the object frame
    loops: np.ndarray  # (m,) int32 vertex index per face corner
    loop_start: np.ndarray  # (f,) int32
    loop_total: np.ndarray  # (f,) int32
    uv: np.ndarray | None = None  # (m, 2) float32 per corner
    material_index: np.ndarray | None = None
    materials: list = field(default_factory=list)  # [MaterialInfo]
    tris: np.ndarray | None = None  # (t, 3) int32 vertex indices: Blender's triangulation of the faces


@dataclass
class MaterialInfo:
    name: str
    base_color: tuple = (0.8, 0.8, 0.8, 1.0)
    texture: str | None = None  # image file path
    normal_map: str | None = None


def mesh_arrays(obj, name: str | None = None, evaluated: bool = False, low_res: bool = False) -> MeshArrays:
    """Arrays of an object's mesh in its frame: its own data, or with ``evaluated`` the mesh
    its modifiers make (Blender's depsgraph): the visual one, or with ``low_res`` the one its
    low-res modifiers make too (addon/lowres.py), whether the viewport shows them or not."""
    if evaluated and len(obj.modifiers):
        import bpy

        from .lowres import shown

        with shown([obj], low_res):
            eo = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
            me = eo.to_mesh()
            try:
                return _arrays(obj, me, name)
            finally:
                eo.to_mesh_clear()
    return _arrays(obj, obj.data, name)


def objects_from_3ds(path: Path, scene) -> list:
    """A mesh object holding the triangles of a .3DS file (Blender 4.2+ has no 3DS importer;
    adfkit.geometry.softmesh reads the chunks, vertices as stored). Raises AdfError for a
    broken file."""
    import bpy

    from adfkit.geometry.softmesh import read_3ds

    verts, faces = read_3ds(path)
    me = bpy.data.meshes.new(path.stem)
    me.from_pydata(verts.tolist(), [], faces.tolist())
    me.update()
    obj = bpy.data.objects.new(path.stem, me)
    scene.collection.objects.link(obj)
    return [obj]


def decimated_arrays(obj, ratio: float) -> MeshArrays:
    """The object's evaluated mesh decimated (Blender's Decimate modifier, collapse, added
    last for the moment) to ``ratio`` of its faces: a low-resolution collision mesh."""
    import bpy

    mod = obj.modifiers.new("adfkit-low-res", "DECIMATE")
    try:
        mod.ratio = float(ratio)
        bpy.context.view_layer.update()
        arr = mesh_arrays(obj, evaluated=True)
    finally:
        obj.modifiers.remove(mod)
        bpy.context.view_layer.update()
    arr.uv, arr.materials, arr.material_index = None, [], None
    return arr


def _arrays(obj, me, name: str | None) -> MeshArrays:
    n, m, f = len(me.vertices), len(me.loops), len(me.polygons)
    co = np.empty(n * 3, np.float32)
    me.vertices.foreach_get("co", co)
    loops = np.empty(m, np.int32)
    me.loops.foreach_get("vertex_index", loops)
    start = np.empty(f, np.int32)
    me.polygons.foreach_get("loop_start", start)
    total = np.empty(f, np.int32)
    me.polygons.foreach_get("loop_total", total)
    uv = None
    if me.uv_layers.active is not None and m:
        uv = np.empty(m * 2, np.float32)
        me.uv_layers.active.data.foreach_get("uv", uv)
        uv = uv.reshape(-1, 2)
    mi = np.empty(f, np.int32)
    me.polygons.foreach_get("material_index", mi)
    mats = [material_info(s.material) for s in obj.material_slots if s.material is not None]
    me.calc_loop_triangles()  # Blender's own triangulation (right for concave n-gons too)
    tris = np.empty(len(me.loop_triangles) * 3, np.int32)
    me.loop_triangles.foreach_get("vertices", tris)
    return MeshArrays(name or obj.name, co.reshape(-1, 3), loops, start, total, uv, mi, mats, tris.reshape(-1, 3))


def material_info(mat) -> MaterialInfo:
    info = MaterialInfo(mat.name, tuple(mat.diffuse_color))
    if mat.node_tree is None:
        return info
    bsdf = next((n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if bsdf is None:
        return info
    base = bsdf.inputs["Base Color"]
    info.base_color = tuple(base.default_value)
    img = _linked_image(base)
    if img is not None:
        info.texture = _image_file(img)
    normal = bsdf.inputs["Normal"]
    if normal.is_linked and normal.links[0].from_node.type == "NORMAL_MAP":
        img = _linked_image(normal.links[0].from_node.inputs["Color"])
        if img is not None:
            info.normal_map = _image_file(img)
    return info


def _linked_image(socket):
    if socket.is_linked and socket.links[0].from_node.type == "TEX_IMAGE":
        return socket.links[0].from_node.image
    return None


def _image_file(img) -> str | None:
    import bpy

    path = bpy.path.abspath(img.filepath) if img.filepath else ""
    return path if path and Path(path).is_file() else None


def digest(parts: list[MeshArrays]) -> str:
    h = hashlib.sha1()
    for p in parts:
        for a in (p.co, p.loops, p.loop_start, p.loop_total, p.uv, p.material_index):
            if a is not None:
                h.update(np.ascontiguousarray(a).tobytes())
        for mi in p.materials:
            h.update(repr((mi.name, mi.base_color, mi.texture, mi.normal_map)).encode())
    return h.hexdigest()


def obj_text(parts: list[MeshArrays], mtl_name: str | None) -> str:
    """OBJ with one ``o`` per part (AMBF makes one collision child shape per sub-mesh)."""
    out = ["# written by adfkit (Blender add-on)\n"]
    if mtl_name:
        out.append(f"mtllib {mtl_name}\n")
    from adfkit.geometry.meshwrite import vertex_normals

    v_base = vt_base = 1
    for p in parts:
        out.append(f"o {p.name}\n")
        if len(p.co):
            out.append("".join(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in p.co.tolist()))
        if p.uv is not None:
            out.append("".join(f"vt {u:.9g} {v:.9g}\n" for u, v in p.uv.tolist()))
        # a normal per vertex at its own index: AMBF's OBJ reader needs full triplets
        # (adfkit.geometry.meshwrite.obj_faces)
        polys = [p.loops[s : s + t].tolist() for s, t in zip(p.loop_start.tolist(), p.loop_total.tolist())]
        out.append("".join("vn {:.6g} {:.6g} {:.6g}\n".format(*n) for n in vertex_normals(p.co, polys)))
        vidx = (p.loops + v_base).tolist()
        cur_mat = None
        for fi, (s, t) in enumerate(zip(p.loop_start.tolist(), p.loop_total.tolist())):
            if p.materials and p.material_index is not None:
                mi = min(int(p.material_index[fi]), len(p.materials) - 1)
                if mi != cur_mat:
                    out.append(f"usemtl {p.materials[mi].name}\n")
                    cur_mat = mi
            if p.uv is not None:
                out.append("f " + " ".join(f"{vidx[k]}/{k + vt_base}/{vidx[k]}" for k in range(s, s + t)) + "\n")
            else:
                out.append("f " + " ".join(f"{vidx[k]}//{vidx[k]}" for k in range(s, s + t)) + "\n")
        v_base += len(p.co)
        vt_base += 0 if p.uv is None else len(p.uv)
    return "".join(out)


def mtl_text(materials: list[MaterialInfo], texture_names: dict[str, str]) -> str:
    out = ["# written by adfkit (Blender add-on)\n"]
    for m in materials:
        r, g, b, a = m.base_color
        out.append(f"newmtl {m.name}\nKa 0.2 0.2 0.2\nKd {r:.6g} {g:.6g} {b:.6g}\nKs 0.5 0.5 0.5\nNs 64\nd {a:.6g}\n")
        if m.texture:
            out.append(f"map_Kd {texture_names[m.texture]}\n")
        if m.normal_map:
            out.append(f"map_bump {texture_names[m.normal_map]}\n")
    return "".join(out)


def obj_files(parts: list[MeshArrays], filename: str) -> dict[str, bytes | Path]:
    """What an OBJ export writes, by file name: the OBJ, its MTL when the parts have materials,
    and the images the MTL names (as the paths to copy them from)."""
    mats = {m.name: m for p in parts for m in p.materials}
    files: dict[str, bytes | Path] = {}
    mtl = None
    if mats:
        mtl = Path(filename).stem + ".mtl"
        tex: dict[str, str] = {}
        for m in mats.values():
            for src in (m.texture, m.normal_map):
                if src and src not in tex:
                    tex[src] = Path(src).name
                    files[tex[src]] = Path(src)
        files[mtl] = mtl_text(list(mats.values()), tex).encode()
    files[filename] = obj_text(parts, mtl).encode()
    return files


def write_obj(parts: list[MeshArrays], directory: Path, filename: str) -> list[Path]:
    """Write OBJ (+ MTL and copied textures when materials exist). Returns the files written."""
    return list(write_files(directory, obj_files(parts, filename)))


MESH_SUFFIXES = (".OBJ", ".STL", ".PLY", ".3DS", ".DAE", ".OFF", ".GLB", ".GLTF", ".FBX")
MESH_SUFFIXES_LOWER = tuple(s.lower() for s in MESH_SUFFIXES)


def with_format(name: str, fmt: str) -> str:
    """The mesh file name with the suffix of ``fmt`` ('OBJ', 'STL', 'PLY', '3DS'): a name that
    has it is kept, another mesh suffix is replaced, anything else (an object name such as
    'Tray.001' or '/ambf/env/base') gets the suffix after its last part."""
    from adfkit.geometry.meshwrite import SUFFIXES

    suffix = SUFFIXES[fmt]
    if Path(name).suffix.upper() == suffix:
        return name
    if Path(name).suffix.upper() in MESH_SUFFIXES:
        return Path(name).stem + suffix
    return name.rsplit("/", 1)[-1] + suffix


def mesh_files(parts: list[MeshArrays], filename: str, split: bool = True) -> dict[str, bytes | Path]:
    """The files of the parts in the format the file name's suffix names: OBJ (+ MTL, images),
    else STL, PLY or 3DS through adfkit.geometry.meshwrite (triangles only, no materials)."""
    if Path(filename).suffix.lower() == ".obj":
        return obj_files(parts, filename)
    from adfkit.geometry.meshwrite import encode_parts, format_of

    return {filename: encode_parts(format_of(filename) or "", [(p.name, p.co, p.tris) for p in parts], split=split)}


def source_files(src: Path, filename: str) -> dict[str, bytes | Path]:
    """An unchanged mesh file to copy as ``filename`` (and, for OBJ, its MTL and the images the
    MTL names), by file name."""
    files: dict[str, bytes | Path] = {filename: src}
    if src.suffix.lower() != ".obj":
        return files
    for line in src.read_text(encoding="utf-8", errors="replace").splitlines():
        if not line.startswith("mtllib "):
            continue
        mtl = src.parent / line[7:].strip()
        if not mtl.is_file():
            continue
        files[mtl.name] = mtl
        for ml in mtl.read_text(encoding="utf-8", errors="replace").splitlines():
            parts = ml.strip().split()
            if parts and parts[0].lower() in ("map_kd", "map_bump", "bump", "norm", "map_ks") and len(parts) > 1:
                img = src.parent / parts[-1]
                if img.is_file():
                    files[img.name] = img
    return files


def content_hash(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def write_files(directory: Path, files: dict[str, bytes | Path]) -> dict[Path, tuple[str, bool]]:
    """Write each file into ``directory`` (atomically; a Path is copied) unless the file there
    already holds those bytes. Returns {path: (sha-256 of its bytes, written?)}."""
    out = {}
    for name, content in files.items():
        data = content if isinstance(content, bytes) else content.read_bytes()
        dst = directory / name
        digest = content_hash(data)
        same = dst.is_file() and content_hash(dst.read_bytes()) == digest
        if not same:
            atomic_write_bytes(dst, data)
        out[dst] = (digest, not same)
    return out
