"""The 3DS writer (adfkit.geometry.mesh3ds) and the STL/PLY/3DS dispatch (meshwrite), read back
by a reader written here from the chunk format, by assimp (the independent reader, Debian's
assimp-utils, when installed) and by adfkit's own soft-mesh reader."""

from __future__ import annotations

import shutil
import struct
import subprocess

import numpy as np
import pytest

from adfkit.geometry.mesh3ds import LIMIT, TooLarge, encode_3ds, write_3ds
from adfkit.geometry.meshwrite import write_parts
from adfkit.geometry.softmesh import read_3ds, unique_nodes

# an irregular tetrahedron: every axis has its own extent, so a swapped or flipped axis shows
TET_V = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]])
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def spec_read(data: bytes) -> dict:
    """A 3DS reader from the chunk layout alone (u16 id, u32 length with the 6-byte header):
    {'ids': chunk ids in file order with their depth, 'objects': [(name, vertices, faces, flags)]}."""
    ids, objects = [], []

    def walk(off: int, end: int, depth: int) -> None:
        while off < end:
            cid, length = struct.unpack_from("<HI", data, off)
            assert length >= 6 and off + length <= end, f"chunk 0x{cid:04x} overruns its parent"
            ids.append((depth, cid))
            body = off + 6
            if cid in (0x4D4D, 0x3D3D, 0x4100):
                walk(body, off + length, depth + 1)
            elif cid == 0x4000:
                nul = data.index(b"\0", body)
                objects.append([data[body:nul].decode("ascii"), None, None, None])
                walk(nul + 1, off + length, depth + 1)
            elif cid == 0x4110:
                (n,) = struct.unpack_from("<H", data, body)
                assert length == 6 + 2 + 12 * n
                objects[-1][1] = np.frombuffer(data, "<f4", 3 * n, body + 2).reshape(n, 3)
            elif cid == 0x4120:
                (n,) = struct.unpack_from("<H", data, body)
                assert length == 6 + 2 + 8 * n
                f = np.frombuffer(data, "<u2", 4 * n, body + 2).reshape(n, 4)
                objects[-1][2], objects[-1][3] = f[:, :3], f[:, 3]
            off += length
        assert off == end, "chunks do not fill their parent exactly"

    walk(0, len(data), 0)
    return {"ids": ids, "objects": objects}


def test_a_3ds_file_has_the_chunk_tree_and_the_numbers_given():
    got = spec_read(encode_3ds([("Tetrahedron", TET_V, TET_F)]))
    assert got["ids"] == [(0, 0x4D4D), (1, 0x0002), (1, 0x3D3D), (2, 0x3D3E), (2, 0x4000), (3, 0x4100)] + [
        (4, 0x4110),
        (4, 0x4120),
    ]
    ((name, v, f, flags),) = got["objects"]
    assert name == "Tetrahedro"  # cut to 10 characters, the format's limit
    assert v.tolist() == TET_V.astype(np.float32).tolist() and f.tolist() == TET_F.tolist()
    assert flags.tolist() == [7, 7, 7, 7]


@pytest.mark.skipif(shutil.which("assimp") is None, reason="assimp (Debian assimp-utils) is not installed")
def test_assimp_reads_the_3ds_file_back(tmp_path):
    src = write_3ds(tmp_path / "tet.3ds", [("Tet", TET_V, TET_F), ("Moved", TET_V + [1.0, 0.0, 0.0], TET_F)])
    out = tmp_path / "tet.obj"
    res = subprocess.run(["assimp", "export", str(src), str(out)], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stdout + res.stderr
    v = np.array([[float(c) for c in ln.split()[1:4]] for ln in out.read_text().splitlines() if ln.startswith("v ")])
    # assimp turns 3DS's Z-up into its Y-up frame: (x, y, z) -> (x, z, -y)
    back = np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])
    want = np.vstack([TET_V, TET_V + [1.0, 0.0, 0.0]])
    assert len(back) == 8
    assert sorted(map(tuple, np.round(back, 6))) == sorted(map(tuple, np.round(want, 6)))
    info = subprocess.run(["assimp", "info", str(src)], capture_output=True, text=True, timeout=60).stdout
    assert "Meshes:             2" in info and "Faces:              8" in info


def _grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    xs = np.linspace(0.0, 1.0, n)
    v = np.array([(x, y, 0.0) for y in xs for x in xs])
    f = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            f += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    return v, np.array(f)


def test_a_part_over_65535_vertices_is_split_into_objects_within_the_limits(tmp_path):
    v, f = _grid(300)  # 90000 vertices, 178802 triangles
    path = write_3ds(tmp_path / "big.3ds", [("Sheet", v, f)])
    objects = spec_read(path.read_bytes())["objects"]
    assert len(objects) == 3 and [o[0] for o in objects] == ["Sheet_0", "Sheet_1", "Sheet_2"]
    assert all(len(o[1]) <= LIMIT and len(o[2]) <= LIMIT for o in objects)
    assert sum(len(o[2]) for o in objects) == len(f)
    # the same surface: every triangle's corners, and every vertex once the seams are merged
    verts, faces = read_3ds(path)
    want = np.sort(np.round(v[f].reshape(-1, 9), 5), axis=0)
    assert np.array_equal(np.sort(np.round(verts[faces].reshape(-1, 9), 5), axis=0), want)
    assert unique_nodes(verts, faces).node_count == len(v)
    with pytest.raises(TooLarge, match="90000 vertices and 178802 triangles; a 3DS object holds at most 65535"):
        encode_3ds([("Sheet", v, f)], split=False)


def test_long_object_names_are_cut_to_ten_characters_and_kept_apart():
    objects = spec_read(encode_3ds([("collision_part", TET_V, TET_F), ("collision_part", TET_V, TET_F)]))["objects"]
    assert [o[0] for o in objects] == ["collision_", "collisio~1"]


@pytest.mark.parametrize("suffix", [".STL", ".PLY"])
def test_stl_and_ply_are_written_by_trimesh_and_read_back(tmp_path, suffix):
    trimesh = pytest.importorskip("trimesh")
    path = write_parts(tmp_path / f"tet{suffix}", [("a", TET_V, TET_F), ("b", TET_V + [0, 0, 1.0], TET_F)])
    back = trimesh.load(path, process=False)
    assert len(back.faces) == 8
    assert np.allclose(back.bounds, [[0, 0, 0], [0.1, 0.2, 1.3]])
    if suffix == ".PLY":  # the vertex list as given (a soft body's node numbering depends on it)
        assert np.allclose(back.vertices, np.vstack([TET_V, TET_V + [0, 0, 1.0]]))
    assert not list(tmp_path.glob(".*tmp"))  # written beside the target, then renamed


def test_the_validator_says_where_a_3ds_mesh_is_broken(tmp_path):
    from adfkit.validator import validate_file

    good = encode_3ds([("Tet", TET_V, TET_F)])
    (tmp_path / "tet.3ds").write_bytes(good[:-10])  # cut short: the last chunk overruns its parent
    model = tmp_path / "m.yaml"
    model.write_text("bodies: [BODY t]\nBODY t:\n  name: t\n  mass: 0.0\n  mesh: tet.3ds\n")
    (d,) = [d for d in validate_file(model).diagnostics if d.rule == "mesh-unreadable"]
    assert "mesh tet.3ds of 'BODY t': corrupt 3DS chunk 0x4d4d at byte 0" in d.message
    assert (d.location.line, d.location.column) == (5, 9)
    (tmp_path / "tet.3ds").write_bytes(good)
    assert [d for d in validate_file(model).diagnostics if d.rule == "mesh-unreadable"] == []


# --- the validator's node count (geometry.softnodes): softmesh's count without numpy ------------


def _count_both(path, data: bytes):
    from adfkit.geometry.softnodes import node_count_3ds

    path.write_bytes(data)
    return node_count_3ds(path, data), unique_nodes(*read_3ds(path)).node_count


def test_the_validators_node_count_is_the_soft_bodys(tmp_path):
    """Two objects: the second repeats the first's vertices, one of them 1e-12 m off (the same
    float32: one node) and one 1e-6 m off (a node of its own)."""
    b_v = np.array([TET_V[0], TET_V[1], TET_V[2] + 1e-12, TET_V[3] + [0.0, 0.0, 1e-6]])
    assert _count_both(tmp_path / "two.3ds", encode_3ds([("a", TET_V, TET_F), ("b", b_v, TET_F)])) == (5, 5)


def test_the_node_count_rounds_as_numpy_does(tmp_path):
    """Near 1 mm a float32 step is 1.2e-10 m: the next float32 after 0.001 rounds to the same
    nanometre (its vertex and that one are one node), the one 9 steps on to the next (two)."""
    x = np.float32(0.001)
    step = np.nextafter(x, np.float32(1)) - x
    for k, nodes in ((1, 3), (9, 4)):
        v = np.array([[x, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [x + k * step, 0, 0]], dtype=np.float32)
        f = np.array([[0, 1, 2], [3, 1, 2]])
        assert _count_both(tmp_path / f"near{k}.3ds", encode_3ds([("a", v.astype(float), f)])) == (nodes, nodes)


def test_the_node_count_refuses_what_the_soft_mesh_refuses(tmp_path):
    """A face naming a vertex past the file's: mesh-unreadable from both readers."""
    from adfkit.diagnostics import AdfError
    from adfkit.geometry.softmesh import load_soft_mesh
    from adfkit.geometry.softnodes import node_count

    data = bytearray(encode_3ds([("a", TET_V, TET_F)]))
    at = data.index(struct.pack("<H", 0x4120)) + 8  # the first face's first index
    data[at : at + 2] = struct.pack("<H", 9)
    p = tmp_path / "bad.3ds"
    p.write_bytes(bytes(data))
    rules = []
    for read in (lambda: node_count(p), lambda: load_soft_mesh(p)):
        with pytest.raises(AdfError) as e:
            read()
        rules.append(e.value.diagnostics[0].rule)
    assert rules == ["mesh-unreadable", "mesh-unreadable"]


def test_the_node_count_of_every_corpus_3ds(tmp_path):
    from conftest import CORPUS, require_corpus

    require_corpus()
    found = [p for p in CORPUS.rglob("*") if p.suffix.lower() == ".3ds"]
    assert found
    for p in found:
        ours, softmesh = _count_both(tmp_path / p.name, p.read_bytes())
        assert ours == softmesh, p


def test_a_3ds_file_nested_deeper_than_pythons_recursion_is_a_located_finding(tmp_path):
    """50,000 nested editor chunks (300 kB) around no triangle object: `mesh-empty` from the
    chunk walk, and `adfkit validate` of a soft body naming it answers with findings (a
    recursive walk met RecursionError there: a traceback)."""
    from adfkit.diagnostics import AdfError
    from adfkit.geometry.format3ds import walk_3ds
    from adfkit.validator.engine import validate_file

    data = struct.pack("<HI", 0x3D3D, 6)
    for _ in range(50_000):
        data = struct.pack("<HI", 0x3D3D, 6 + len(data)) + data
    data = struct.pack("<HI", 0x4D4D, 6 + len(data)) + data
    mesh = tmp_path / "deep.3ds"
    mesh.write_bytes(data)
    with pytest.raises(AdfError) as e:
        walk_3ds(mesh, data)
    assert e.value.diagnostics[0].rule == "mesh-empty"
    model = tmp_path / "soft.yaml"
    model.write_text(
        "bodies: []\nsoft bodies: [SOFTBODY cloth]\nSOFTBODY cloth:\n  name: cloth\n  mass: 0.1\n"
        "  mesh: deep.3ds\n  collision mesh: deep.3ds\n  config: {fixed nodes: [0, 1]}\n"
    )
    found = validate_file(model).diagnostics
    assert any("deep.3ds" in d.message and "no triangle object" in d.message for d in found)
