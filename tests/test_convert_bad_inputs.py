"""Converters never crash and never write what the target engine rejects (issue 14).

Classes of bug, each with its test: a bad URDF/MJCF attribute is a located error (line AND
column >= 1); MJCF includes are resolved by us inside the model's folder or refused; a chain
of 1,000 bodies needs no recursion; converted output loads in PyBullet (URDF) and MuJoCo
(MJCF), or a loss says why a part was changed.
"""

from __future__ import annotations

import sys
import textwrap
import xml.etree.ElementTree as ET

import pytest

from adfkit.converters import read, write
from adfkit.converters.losses import loss_keys
from adfkit.diagnostics import AdfError

BAD_VALUES = ("abc", "", "nan", "-inf", "1e999", "1 2", "-1", "0")


def _chain_adf(n: int) -> str:
    out = [
        "bodies: [" + ", ".join(f"BODY b{i}" for i in range(n)) + "]",
        "joints: [" + ", ".join(f"JOINT j{i}" for i in range(1, n)) + "]",
    ]
    for i in range(n):
        out.append(
            textwrap.dedent(f"""\
            BODY b{i}:
              name: b{i}
              mass: {0.0 if i == 0 else 0.1}
              inertia: {{ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}}
              location: {{position: {{x: 0.0, y: 0.0, z: {0.01 * i}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
              collision shape: SPHERE
              collision geometry: {{radius: 0.005}}""")
        )
    for i in range(1, n):
        out.append(
            textwrap.dedent(f"""\
            JOINT j{i}:
              name: j{i}
              parent: BODY b{i - 1}
              child: BODY b{i}
              type: {"revolute" if i % 2 else "prismatic"}
              parent pivot: {{x: 0, y: 0, z: 0.01}}
              parent axis: {{x: 1, y: 0, z: 0}}
              child pivot: {{x: 0, y: 0, z: 0}}
              child axis: {{x: 1, y: 0, z: 0}}
              joint limits: {{low: -0.5, high: 0.5}}
              damping: 0.01""")
        )
    return "\n".join(out) + "\n"


def _assert_located(exc: AdfError, path) -> None:
    for d in exc.diagnostics:
        loc = d.location
        assert loc is not None and loc.line and loc.line >= 1 and loc.column and loc.column >= 1, d.format()
        assert ":None" not in d.format() and f"{loc.line}:0:" not in d.format()


def _mutants(text: str):
    """(description, text) for every attribute of every element set to every bad value."""
    root = ET.fromstring(text)
    count = sum(len(el.attrib) for el in root.iter())
    for k in range(count):
        for bad in BAD_VALUES:
            r = ET.fromstring(text)
            n = 0
            for el in r.iter():
                for key in list(el.attrib):
                    if n == k:
                        el.set(key, bad)
                        name = f"<{el.tag} {key}={bad!r}>"
                    n += 1
            yield name, ET.tostring(r, encoding="unicode")


@pytest.fixture(scope="module")
def small_chain(tmp_path_factory):
    d = tmp_path_factory.mktemp("chain")
    (d / "chain.yaml").write_text(_chain_adf(4))
    model, _ = read(d / "chain.yaml")
    write(model, d / "chain.urdf")
    write(model, d / "chain.xml")
    return d


def test_urdf_limit_with_bad_velocity_is_a_located_error(tmp_path):
    f = tmp_path / "r.urdf"
    f.write_text(
        '<robot name="r">\n  <link name="a"/>\n  <link name="b"/>\n'
        '  <joint name="j" type="revolute">\n    <parent link="a"/>\n    <child link="b"/>\n'
        '    <limit lower="0" upper="1" effort="0" velocity="abc"/>\n  </joint>\n</robot>\n'
    )
    with pytest.raises(AdfError) as exc:
        read(f)
    d = exc.value.diagnostics[0]
    assert (d.rule, d.location.line, d.location.column) == ("urdf-number", 7, 5)
    assert 'velocity="abc"' in d.message


@pytest.mark.parametrize("fmt", ["urdf", "xml"])
def test_every_bad_attribute_value_is_read_or_a_located_error(small_chain, tmp_path, fmt):
    """Each attribute of a converted chain set to each bad value: the reader either accepts it
    or raises AdfError at a line and a column >= 1 (never a traceback, column 0 or None)."""
    text = (small_chain / f"chain.{fmt}").read_text()
    checked = errors = 0
    for _name, mutant in _mutants(text):
        f = tmp_path / f"m.{fmt}"
        f.write_text(mutant)
        try:
            read(f)
        except AdfError as exc:
            _assert_located(exc, f)
            errors += 1
        checked += 1
    assert checked > 300 and errors > checked // 4, (checked, errors)


def test_mjcf_error_points_at_the_element_mujoco_names(tmp_path):
    f = tmp_path / "m.xml"
    f.write_text(
        '<mujoco>\n  <worldbody>\n    <body name="a">\n      <joint type="hinge"/>\n'
        '    </body>\n    <body name="b">\n        <geom size="abc"/>\n    </body>\n  </worldbody>\n</mujoco>\n'
    )
    with pytest.raises(AdfError) as exc:
        read(f)
    d = exc.value.diagnostics[0]
    assert (d.rule, d.location.line, d.location.column) == ("mjcf-compile", 7, 9)


def _include_tree(tmp_path):
    (tmp_path / "model" / "parts").mkdir(parents=True)
    (tmp_path / "outside.xml").write_text(
        '<mujoco><worldbody><body name="secret"><geom size="1"/></body></worldbody></mujoco>'
    )
    (tmp_path / "model" / "parts" / "body.xml").write_text(
        '<mujoco>\n  <body name="arm" pos="0 0 1">\n    <freejoint/>\n    <geom size="0.1" mass="2"/>\n'
        "  </body>\n</mujoco>\n"
    )
    (tmp_path / "model" / "parts" / "bad.xml").write_text(
        '<mujoco>\n  <body name="arm">\n      <joint type="hinge"/>\n  </body>\n</mujoco>\n'
    )
    return tmp_path / "model"


def _main(folder, include):
    f = folder / "main.xml"
    f.write_text(f'<mujoco model="m">\n  <worldbody>\n    <include file="{include}"/>\n  </worldbody>\n</mujoco>\n')
    return f


def test_mjcf_include_inside_the_model_folder_is_resolved(tmp_path):
    model, _ = read(_main(_include_tree(tmp_path), "parts/body.xml"))
    (arm,) = model.bodies
    assert arm.name == "arm" and arm.mass == pytest.approx(2.0)
    assert arm.location.position[2] == pytest.approx(1.0)


@pytest.mark.parametrize(
    "include,rule",
    [
        ("{abs}", "mjcf-include"),  # absolute: never followed
        ("../outside.xml", "outside-tree"),  # out of the model's folder
        ("main.xml", "mjcf-include"),  # itself
        ("/dev/zero", "mjcf-include"),
        ("parts/missing.xml", "file-not-found"),
    ],
)
def test_mjcf_include_out_of_the_tree_is_refused_where_it_is_written(tmp_path, include, rule):
    folder = _include_tree(tmp_path)
    f = _main(folder, include.format(abs=tmp_path / "outside.xml"))
    with pytest.raises(AdfError) as exc:
        read(f)
    d = exc.value.diagnostics[0]
    assert (d.rule, d.location.file, d.location.line, d.location.column) == (rule, str(f), 3, 5)
    assert "secret" not in str(exc.value)


def test_mjcf_error_inside_an_included_file_points_into_that_file(tmp_path):
    folder = _include_tree(tmp_path)
    with pytest.raises(AdfError) as exc:
        read(_main(folder, "parts/bad.xml"))
    d = exc.value.diagnostics[0]
    assert d.rule == "mjcf-compile" and d.location.file.endswith("bad.xml")
    assert (d.location.line, d.location.column) == (2, 3)


@pytest.mark.slow
@pytest.mark.parametrize("n", [1200])
def test_chain_of_bodies_deeper_than_the_recursion_limit_converts(tmp_path, n):
    assert n > sys.getrecursionlimit()
    (tmp_path / "chain.yaml").write_text(_chain_adf(n))
    model, _ = read(tmp_path / "chain.yaml")
    assert write(model, tmp_path / "chain.urdf") == []
    back, _ = read(tmp_path / "chain.urdf")
    assert len(back.bodies) == n and len(back.joints) == n - 1
    losses = write(model, tmp_path / "chain.xml")
    assert loss_keys(losses) == [("BODY b496", "body nesting")]  # MuJoCo's parser stops at ~500 levels
    with pytest.raises(AdfError) as exc:
        read(tmp_path / "chain.xml")
    assert "nested too deep" in exc.value.diagnostics[0].message
    _assert_located(exc.value, tmp_path / "chain.xml")


def test_chain_as_deep_as_mujoco_reads_loads_in_mujoco(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    (tmp_path / "chain.yaml").write_text(_chain_adf(496))
    model, _ = read(tmp_path / "chain.yaml")
    assert write(model, tmp_path / "chain.xml") == []
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "chain.xml")).nbody == 497


FIT_ADF = """\
bodies: [BODY base, BODY cloth, BODY arm, BODY big, BODY odd]
joints: [JOINT j1, JOINT j2]
high resolution path: meshes/
low resolution path: meshes/
BODY base:
  name: base
  mass: 0.0
  location: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.2, z: 0.2}
BODY cloth:
  name: cloth
  mass: 0.1
  inertia: {ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}
  mesh: flat.stl
  location: {position: {x: 0, y: 0, z: 0.5}, orientation: {r: 0, p: 0, y: 0}}
BODY arm:
  name: arm
  mass: 0.5
  inertia: {ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}
  mesh: cube.ply
  location: {position: {x: 0, y: 0, z: 0.2}, orientation: {r: 0, p: 0, y: 0}}
BODY big:
  name: big
  mass: 0.5
  inertia: {ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}
  mesh: cube.ply
  scale: 1.0e+308
  location: {position: {x: 1, y: 0, z: 0.2}, orientation: {r: 0, p: 0, y: 0}}
BODY odd:
  name: odd
  mass: 0.5
  inertia: {ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}
  mesh: thing.3ds
  location: {position: {x: 2, y: 0, z: 0.2}, orientation: {r: 0, p: 0, y: 0}}
JOINT j1:
  name: j1
  parent: BODY base
  child: BODY arm
  type: revolute
  parent pivot: {x: 0, y: 0, z: 0.1}
  parent axis: {x: 0, y: 0, z: 1}
  child pivot: {x: 0, y: 0, z: -0.1}
  child axis: {x: 0, y: 0, z: 1}
  joint limits: {low: 1.0, high: -1.0}
JOINT j2:
  name: j2
  parent: BODY arm
  child: BODY cloth
  type: prismatic
  parent pivot: {x: 0, y: 0, z: 0.1}
  parent axis: {x: 0, y: 0, z: 1}
  child pivot: {x: 0, y: 0, z: -0.2}
  child axis: {x: 0, y: 0, z: 1}
  joint limits: {low: 0.5, high: -0.5}
"""


@pytest.fixture()
def odd_model(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    (tmp_path / "meshes").mkdir()
    trimesh.Trimesh(vertices=[[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0], [0, 0.1, 0]], faces=[[0, 1, 2], [0, 2, 3]]).export(
        tmp_path / "meshes" / "flat.stl"
    )
    trimesh.creation.box((0.1, 0.1, 0.1)).export(tmp_path / "meshes" / "cube.ply")
    (tmp_path / "meshes" / "thing.3ds").write_bytes(b"MM\x00\x00not a 3ds file")
    (tmp_path / "fit.yaml").write_text(FIT_ADF)
    return read(tmp_path / "fit.yaml")[0]


def test_mjcf_output_with_flat_mesh_inverted_limits_odd_formats_and_huge_scale_loads_in_mujoco(odd_model, tmp_path):
    mujoco = pytest.importorskip("mujoco")
    losses = write(odd_model, tmp_path / "out" / "fit.xml")
    assert set(loss_keys(losses)) >= {
        ("BODY cloth", "collision mesh"),
        ("BODY arm", "mesh"),
        ("BODY odd", "mesh"),
        ("BODY big", "scale"),
        ("JOINT j1", "joint limits"),
        ("JOINT j2", "joint limits"),
    }
    assert (tmp_path / "out" / "fit_meshes" / "cube.stl").is_file()
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "fit.xml"))
    assert m.nbody == 6 and not m.jnt_limited.any()
    cloth = m.body("cloth").id
    boxes = [g for g in range(m.ngeom) if m.geom_bodyid[g] == cloth and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX]
    assert len(boxes) == 1 and m.geom_size[boxes[0]] == pytest.approx([0.05, 0.05, 5e-5])


def test_urdf_output_with_odd_meshes_and_inverted_limits_loads_in_pybullet(odd_model, tmp_path):
    pybullet = pytest.importorskip("pybullet")
    losses = write(odd_model, tmp_path / "out" / "fit.urdf")
    assert set(loss_keys(losses)) >= {("BODY arm", "mesh"), ("JOINT j1", "joint limits"), ("JOINT j2", "joint limits")}
    text = (tmp_path / "out" / "fit.urdf").read_text()
    assert "cube.ply" not in text and "fit_meshes/cube.stl" in text and "continuous" in text
    cid = pybullet.connect(pybullet.DIRECT)
    try:
        rid = pybullet.loadURDF(str(tmp_path / "out" / "fit.urdf"), physicsClientId=cid)
        info = {
            pybullet.getJointInfo(rid, i, physicsClientId=cid)[1]: pybullet.getJointInfo(rid, i, physicsClientId=cid)
            for i in range(pybullet.getNumJoints(rid, physicsClientId=cid))
        }
        assert set(info) == {b"world_to_base", b"j1", b"j2"}
        assert info[b"j1"][8:10] == (0.0, -1.0)  # continuous: no limit
    finally:
        pybullet.disconnect(cid)


@pytest.mark.parametrize("points", [[(0, 0, 0)], [(0, 0, 0), (1, 0, 0)], [(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0)]])
def test_flat_box_of_a_point_or_a_line_is_its_bounds(points):
    """A garbage collision mesh (one vertex, or all on a line) stands in as a box around it
    instead of an IndexError/QhullError in the MJCF writer (found by the fuzz run)."""
    import numpy as np
    import trimesh

    from adfkit.converters.engine_fit import FLAT_THICKNESS, flat_box

    mesh = trimesh.Trimesh(vertices=np.array(points, float), faces=np.zeros((0, 3), int), process=False)
    centre, rot, sizes = flat_box(mesh, 2.0)
    span = 2.0 * (len(points) - 1)
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-9)
    assert np.allclose(centre, [span / 2, 0, 0], atol=1e-9)
    assert sorted(np.round(sizes[:2], 9).tolist()) == [0.0, span]
    assert sizes[2] == pytest.approx(FLAT_THICKNESS * max(span, 1e-6))


def test_mjcf_output_of_an_inertia_breaking_the_triangle_inequality_loads_in_mujoco(tmp_path):
    """Bullet (so AMBF) plays principal moments (0.01, 0.001, 0.001); MuJoCo refuses them ("inertia
    must satisfy A + B >= C"), and the MuJoCo engine refused the whole scene. Written with the
    largest lowered to the sum of the other two, and a loss that says so."""
    mujoco = pytest.importorskip("mujoco")
    (tmp_path / "m.yaml").write_text(
        "bodies: [BODY odd]\nBODY odd:\n  name: odd\n  mass: 0.2\n  inertia: {ix: 0.01, iy: 0.001, iz: 0.001}\n"
        "  collision shape: BOX\n  collision geometry: {x: 0.05, y: 0.05, z: 0.05}\n"
        "  location: {position: {x: 0, y: 0, z: 0.3}, orientation: {r: 0, p: 0, y: 0}}\n"
    )
    losses = write(read(tmp_path / "m.yaml")[0], tmp_path / "m.xml")
    assert ("BODY odd", "inertia") in set(loss_keys(losses))
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "m.xml"))
    assert sorted(m.body("odd").inertia) == pytest.approx([0.001, 0.001, 0.002])
