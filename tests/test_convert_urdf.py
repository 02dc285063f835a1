"""ADF ⇄ URDF, checked in real PyBullet: kinematics, masses and inertias of the source in its
own engine against the converted file in the target engine; round trips; exact losses."""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
import pytest

pb = pytest.importorskip("pybullet", reason="pybullet (sim extra) is not installed")
pybullet_data = pytest.importorskip("pybullet_data")

from conftest import CORPUS  # noqa: E402
from convert_checks import assert_located_error, convert_cli, expected_losses  # noqa: E402
from convert_checks import assert_same_kinematics as _assert_same_kinematics  # noqa: E402
from convert_checks import close_pose as _close_pose  # noqa: E402

from adfkit.adf.reader import load  # noqa: E402
from adfkit.converters import read, write  # noqa: E402
from adfkit.converters.inertia import world_tensor  # noqa: E402
from adfkit.converters.losses import loss_keys  # noqa: E402
from adfkit.diagnostics import AdfError  # noqa: E402
from adfkit.model.pose import Pose, Quat, Vec3  # noqa: E402
from adfkit.model.semantics import JointKind, inertial_offset  # noqa: E402
from adfkit.model.tree import build_tree  # noqa: E402

ROBOTS = CORPUS / "ambf" / "ambf_models" / "descriptions" / "multi-bodies" / "robots"
needs_corpus = pytest.mark.skipif(not CORPUS.is_dir(), reason="../shared/corpus is absent (public ADF corpus)")
DATA = Path(pybullet_data.getDataPath())
# revolute, continuous, prismatic and fixed joints; meshes and primitives; fixed and floating
# bases; a `world` link with moving joints; full inertia tensors (some breaking the triangle
# inequality, which PyBullet zeroes on both sides); PyBullet's <contact> inertia scaling
URDFS = [
    "kuka_iiwa/model.urdf",
    "r2d2.urdf",
    "franka_panda/panda.urdf",
    "racecar/racecar.urdf",
    "cartpole.urdf",
    "kuka_iiwa/model_free_base.urdf",
    "quadruped/minitaur.urdf",
    "xarm/xarm6_robot.urdf",
    "TwoJointRobot_w_fixedJoints.urdf",
    "cube_no_rotation.urdf",
    "cube_small.urdf",
]
CORPUS_ROBOTS = ["blender-kuka.yaml", "blender-psm.yaml", "blender-ecm.yaml", "blender-mtm.yaml"]
TOL = 1e-6


@pytest.fixture(scope="module")
def client():
    cid = pb.connect(pb.DIRECT)
    yield cid
    pb.disconnect(cid)


def _load(cid, path: Path) -> int:
    pb.resetSimulation(physicsClientId=cid)
    return pb.loadURDF(str(path), useFixedBase=False, flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=cid)


def _movable(cid, uid):
    out = []
    for j in range(pb.getNumJoints(uid, physicsClientId=cid)):
        info = pb.getJointInfo(uid, j, physicsClientId=cid)
        if info[2] in (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC):
            out.append((j, info))
    return out


def _random_q(info, rng):
    lo, hi = info[8], info[9]
    if hi < lo or hi - lo > 100:  # continuous (PyBullet reports 0, -1) or effectively unlimited
        lo, hi = -math.pi, math.pi
    return rng.uniform(lo, hi)


def _link_names(cid, uid) -> dict[str, int]:
    names = {pb.getBodyInfo(uid, physicsClientId=cid)[0].decode(): -1}
    for j in range(pb.getNumJoints(uid, physicsClientId=cid)):
        names[pb.getJointInfo(uid, j, physicsClientId=cid)[12].decode()] = j
    return names


def _frames(cid, uid, link: int):
    """(link frame, COM frame) world poses as Pose."""
    if link == -1:
        pos, orn = pb.getBasePositionAndOrientation(uid, physicsClientId=cid)
        dyn = pb.getDynamicsInfo(uid, -1, physicsClientId=cid)
        com = Pose(Vec3(*pos), Quat(*orn))
        return com * Pose(Vec3(*dyn[3]), Quat(*dyn[4])).inverse(), com
    st = pb.getLinkState(uid, link, computeForwardKinematics=True, physicsClientId=cid)
    return Pose(Vec3(*st[4]), Quat(*st[5])), Pose(Vec3(*st[0]), Quat(*st[1]))


def _inertia_world(cid, uid, link: int, com: Pose) -> np.ndarray:
    dyn = pb.getDynamicsInfo(uid, link, physicsClientId=cid)
    return world_tensor(dyn[2], com.orientation)


def _visual_frames(cid, uid) -> dict[int, Pose]:
    out = {}
    for row in pb.getVisualShapeData(uid, physicsClientId=cid):
        out.setdefault(row[1], Pose(Vec3(*row[5]), Quat(*row[6])))
    return out


# --- URDF -> ADF -> URDF, both in PyBullet ----------------------------------------------------


def _urdf_round_trip(client, rel: str, tmp_path, configs: int):
    src = DATA / rel
    model, read_losses = read(src)
    adf = tmp_path / (src.stem + ".yaml")
    write(model, adf)  # through ADF on disk, as a user would
    back_model, _ = read(adf)
    out = tmp_path / (src.stem + "_back.urdf")
    write(back_model, out)
    # ADF cannot spell a child-frame tilt below AMBF's 1e-3 rad threshold: such joints are
    # reported, with the angle, and the comparison allows what was reported
    tilts = sum(float(l.reason.split(" by ")[1].split(" rad")[0]) for l in read_losses if l.feature == "axis tilt")
    tol = TOL + 2 * tilts
    a = _load(client, src)
    state_a = _snapshot(client, a, configs, None)
    b = _load(client, out)
    state_b = _snapshot(client, b, configs, state_a["qs"])
    assert state_b["types"] == state_a["types"]
    assert set(state_b["links"]) >= set(state_a["links"]) - {"world"}
    # reported: welded to the world (static), or no <inertial> (ADF mass 0, PyBullet 1 kg)
    welded = {l.element.removeprefix("BODY ") for l in read_losses if l.feature in ("mass", "inertial")}
    # reported: extra or primitive visuals, which ADF does not carry
    revisualised = {l.element.removeprefix("BODY ") for l in read_losses if l.feature.startswith("visual")}
    for name in state_a["links"]:
        if name not in state_b["links"] or name in welded:  # reported: welded to the world, static
            continue
        ma, mb = state_a["mass"][name], state_b["mass"][name]
        assert mb == pytest.approx(ma, rel=TOL, abs=1e-12), name
        assert _same_tensor(state_b["inertia"][name], state_a["inertia"][name]), name
    for k, (qa, qb) in enumerate(zip(state_a["poses"], state_b["poses"])):
        for name, pa in qa.items():
            pbose = qb[name]
            for key in ("anchor", "com", "visual"):
                if pa.get(key) is None:
                    continue
                if pbose.get(key) is None:  # the base of one file is a link of the other (a welded root)
                    continue
                if key == "com" and (state_a["mass"][name] == 0.0 or name in welded):
                    continue  # a massless link's COM frame is not defined
                if key == "visual" and name in revisualised:
                    continue
                if key == "anchor" and name not in state_a["moving_children"]:
                    continue  # a link frame is only physical at a moving joint (ADF keeps the visual frame)
                if key == "visual":  # PyBullet keeps visual frames in single precision
                    assert _close_pose(pa[key], pbose[key], max(tol, 1e-5)), (k, name, key)
                else:
                    assert (pa[key] - pbose[key]).norm() < tol, (k, name, key)
            if pa.get("axis") is not None:
                assert (pa["axis"] - pbose["axis"]).norm() < tol, (k, name, "axis")
    return read_losses


def _same_tensor(a, b) -> bool:
    """Equal to 1e-6 relative to the tensor's size: PyBullet diagonalises a full URDF tensor
    iteratively (to about 1e-6 of its largest element), so off-diagonal terms many orders below
    the moments cannot be compared element by element."""
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max()) <= TOL * max(float(np.abs(a).max()), 1e-12 / TOL)


def _snapshot(cid, uid, configs, qs):
    names = _link_names(cid, uid)
    moving = _movable(cid, uid)
    rng = random.Random(7)
    if qs is None:
        qs = [
            {pb.getJointInfo(uid, j, physicsClientId=cid)[1].decode(): _random_q(info, rng) for j, info in moving}
            for _ in range(configs)
        ]
    vis = _visual_frames(cid, uid)
    state = {
        "links": names,
        "qs": qs,
        "mass": {},
        "inertia": {},
        "poses": [],
        "types": sorted((info[1].decode(), info[2]) for _j, info in moving),
        "moving_children": {info[12].decode() for _j, info in moving},
    }
    for name, link in names.items():
        _lf, com = _frames(cid, uid, link)
        state["mass"][name] = pb.getDynamicsInfo(uid, link, physicsClientId=cid)[0]
        state["inertia"][name] = _inertia_world(cid, uid, link, com)
    by_name = {pb.getJointInfo(uid, j, physicsClientId=cid)[1].decode(): (j, info) for j, info in moving}
    for q in qs:
        for jname, value in q.items():
            pb.resetJointState(uid, by_name[jname][0], value, physicsClientId=cid)
        poses = {}
        for name, link in names.items():
            lf, com = _frames(cid, uid, link)
            entry = {
                "com": com.position,
                "visual": lf * vis[link] if link in vis else None,
                "anchor": lf.position if link >= 0 else None,
                "axis": None,
            }
            poses[name] = entry
        for jname, (j, info) in by_name.items():  # world axis, measured: move the joint a little
            # measured on the COM frame: PyBullet's reported URDF link frame carries ~1e-6 rad of
            # noise (the body itself moves the same whichever of its frames is watched)
            child = info[12].decode()
            before = _frames(cid, uid, j)[1]
            pb.resetJointState(uid, j, q[jname] + 0.5, physicsClientId=cid)
            after = _frames(cid, uid, j)[1]
            pb.resetJointState(uid, j, q[jname], physicsClientId=cid)
            if info[2] == pb.JOINT_PRISMATIC:
                poses[child]["axis"] = (after.position - before.position).normalized()
            else:
                d = after.orientation * before.orientation.conjugate()
                poses[child]["axis"] = Vec3(d.x, d.y, d.z).scaled(1.0 if d.w >= 0 else -1.0).normalized()
        state["poses"].append(poses)
    return state


@pytest.mark.parametrize("rel", URDFS)
def test_pybullet_urdf_round_trip_through_adf(client, rel, tmp_path):
    if not (DATA / rel).is_file():
        pytest.skip(f"{rel} is not in this pybullet_data")
    losses = _urdf_round_trip(client, rel, tmp_path, configs=100)
    assert all(l.element and l.feature and l.reason for l in losses)


# pybullet_data files adfkit refuses, each with a located error: not URDF as the spec (or
# PyBullet's own parser) reads it, or a non-uniform mesh scale, which ADF cannot hold
REFUSED = {
    "bicycle/bike.urdf",
    "biped/biped2d_pybullet.urdf",
    "differential/diff_ring.urdf",
    "humanoid/humanoid.urdf",
    "husky/husky.urdf",
    "jenga/jenga.urdf",
    "quadruped/microtaur/microtaur.urdf",
    "racecar/racecar_differential.urdf",
    "spherical_joint_limit.urdf",
    "table/table.urdf",
    "table_square/table_square.urdf",
    "torus_deform.urdf",
}
# files PyBullet itself cannot load (a missing mesh, a .cdf collision file)
UNLOADABLE = {"kuka_iiwa/model_for_sdf.urdf", "toys/concave_box.urdf"}


@pytest.mark.slow
def test_every_pybullet_data_urdf_round_trips_through_adf(client, tmp_path):
    """All ~1100 URDF files shipped with pybullet_data: each is read with a located error
    (REFUSED) or round-trips with the same kinematics, masses and inertias at 100 configurations."""
    done, refused, failures = 0, set(), []
    for n, src in enumerate(sorted(DATA.rglob("*.urdf"))):
        rel = src.relative_to(DATA).as_posix()
        if rel in UNLOADABLE:
            continue
        out = tmp_path / str(n)
        out.mkdir()
        try:
            _urdf_round_trip(client, rel, out, configs=100)
            done += 1
        except AdfError as exc:
            assert exc.diagnostics[0].location.line, rel
            refused.add(rel)
        except AssertionError as exc:
            failures.append(f"{rel}: {exc}")
    assert failures == []
    assert refused <= REFUSED
    assert done > 1000


def test_kuka_read_losses_are_exact():
    _m, losses = read(DATA / "kuka_iiwa" / "model.urdf")
    # the links' colours are named robot-level materials (Grey, Orange, Blue): carried over
    assert loss_keys(losses) == [(f"JOINT lbr_iiwa_joint_{i}", "effort/velocity limit") for i in range(1, 8)]


# --- ADF -> URDF against the ADF model's own kinematics -----------------------------------------


def _adf_to_urdf(client, name: str, tmp_path, configs: int):
    src = ROBOTS / name
    model = load(src)
    out = tmp_path / (src.stem + ".urdf")
    losses = write(model, out)
    tree = build_tree(model)
    uid = _load(client, out)
    names = _link_names(client, uid)
    links = {lk.body.identifier: lk for lk in tree.ordered()}
    in_urdf = {bid: names[lk.body.name] for bid, lk in links.items() if lk.body.name in names}
    moving = {
        pb.getJointInfo(uid, j, physicsClientId=client)[1].decode(): (j, info) for j, info in _movable(client, uid)
    }
    assert len(moving) == sum(
        1
        for lk in tree.ordered()
        if lk.kind in (JointKind.REVOLUTE, JointKind.PRISMATIC) and lk.body.identifier in in_urdf
    )
    rng = random.Random(3)
    for _ in range(configs):
        q = {}
        for lk in tree.ordered():
            if lk.joint is None or lk.joint.name not in moving:
                continue
            j, info = moving[lk.joint.name]
            q[lk.joint.identifier] = _random_q(info, rng)
            pb.resetJointState(uid, j, q[lk.joint.identifier], physicsClientId=client)
        expected = tree.fk(q)
        for bid, link in in_urdf.items():
            lf, com = _frames(client, uid, link)
            body_world = lf * links[bid].frame_in_body.inverse()
            assert _close_pose(body_world, expected[bid]), (name, bid)
            body = links[bid].body
            assert (com.position - (expected[bid] * inertial_offset(body)).position).norm() < TOL
    for bid, link in in_urdf.items():
        body = links[bid].body
        dyn = pb.getDynamicsInfo(uid, link, physicsClientId=client)
        assert dyn[0] == pytest.approx(body.mass or 0.0, rel=TOL, abs=1e-12)
        if body.inertia is not None and (body.mass or 0) > 0:
            _lf, com = _frames(client, uid, link)
            want = world_tensor(
                (body.inertia.ix, body.inertia.iy, body.inertia.iz), (expected[bid] * inertial_offset(body)).orientation
            )
            assert np.allclose(_inertia_world(client, uid, link, com), want, rtol=TOL, atol=1e-12), bid
    return model, tree, losses


@needs_corpus
@pytest.mark.parametrize("name", CORPUS_ROBOTS)
def test_corpus_robot_to_urdf_matches_adf_kinematics(client, name, tmp_path):
    _adf_to_urdf(client, name, tmp_path, configs=100)


def _adf_to_urdf_against_runner(client, name: str, tmp_path, configs: int) -> tuple[int, float]:
    """The ADF file played by adfkit's own PyBullet runner (``SimWorld``: multibodies built from
    the ADF joint frames, independently of ``tree.py`` and the URDF writer) against the URDF
    written from it: every body's COM frame (a full rigid-body pose) at ``configs`` random
    joint values, masses and principal inertias. The runner picks its spanning tree breadth
    first, the converter depth first, so on the PSM's and ECM's parallelograms the two trees
    differ; a body is compared when both reach it through joints both trees hold (the
    `tree.fk` test above covers every body). Returns (bodies compared, largest error)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    scene = load_scene(ROBOTS / name)
    (model,) = scene.all_models()
    out = tmp_path / (Path(name).stem + ".urdf")
    write(model, out)
    uid = _load(client, out)
    names = _link_names(client, uid)
    urdf_joint = {
        pb.getJointInfo(uid, j, physicsClientId=client)[1].decode(): (j, info) for j, info in _movable(client, uid)
    }
    sim = open_world(scene, Options(visuals=False, gravity=(0.0, 0.0, 0.0)))
    try:
        tree = build_tree(model)
        tree_path, runner_path, runner_joint = {}, {}, {}
        for lk in tree.ordered():
            up = tree_path.get(lk.parent.body.identifier, set()) if lk.parent is not None else set()
            tree_path[lk.body.identifier] = up | ({lk.joint.identifier} if lk.joint is not None else set())
        for art in sim.articulations:
            runner_path[art.root.body.identifier] = set()
            for n, (joint, kind, parent, child) in enumerate(art.records):
                runner_path[child.body.identifier] = runner_path[parent.body.identifier] | {joint.identifier}
                if kind in (JointKind.REVOLUTE, JointKind.PRISMATIC):
                    runner_joint[joint.identifier] = (art.uid, n)
        for sb in sim.bodies:
            runner_path.setdefault(sb.body.identifier, set())
        ident = {j.identifier: j.name for j in model.joints}
        common = {j for j in runner_joint if ident[j] in urdf_joint and j in {x for p in tree_path.values() for x in p}}
        bodies = {sb.body.identifier: sb for sb in sim.bodies}
        compared = [
            b
            for b in tree_path
            if b in bodies
            and bodies[b].body.name in names
            and tree_path[b] <= common | _fixed(model)
            and runner_path[b] <= common | _fixed(model)
        ]
        rng = random.Random(11)
        worst = 0.0
        for _ in range(configs):
            for jid in sorted(common):
                j, info = urdf_joint[ident[jid]]
                q = _random_q(info, rng)
                pb.resetJointState(uid, j, q, physicsClientId=client)
                pb.resetJointState(*runner_joint[jid], q, physicsClientId=sim.cid)
            for b in compared:
                sb = bodies[b]
                p, o, _v, _w = sb.state()
                runner_com = Pose(Vec3(*p), Quat(*o))
                _lf, urdf_com = _frames(client, uid, names[sb.body.name])
                err = max(
                    (runner_com.position - urdf_com.position).norm(),
                    runner_com.orientation.angle_to(urdf_com.orientation),
                )
                worst = max(worst, err)
                assert err < TOL, (name, b, err)
        for b in compared:
            sb, link = bodies[b], names[bodies[b].body.name]
            dyn = pb.getDynamicsInfo(uid, link, physicsClientId=client)
            ref = pb.getDynamicsInfo(sb.uid, sb.link, physicsClientId=sim.cid)
            assert dyn[0] == pytest.approx(ref[0], rel=TOL, abs=1e-12), b
            if sb.body.inertia is not None and ref[0] > 0:
                assert np.allclose(dyn[2], ref[2], rtol=TOL, atol=1e-12), b
        return len(compared), worst
    finally:
        sim.close()


def _fixed(model) -> set[str]:
    from adfkit.model.semantics import joint_kind

    return {j.identifier for j in model.joints if joint_kind(j.type) is JointKind.FIXED}


@needs_corpus
@pytest.mark.parametrize(
    "name, bodies",
    [("blender-kuka.yaml", 8), ("blender-mtm.yaml", 10), ("blender-psm.yaml", 5), ("blender-ecm.yaml", 5)],
)
def test_corpus_robot_to_urdf_matches_adfkit_runner(client, name, bodies, tmp_path):
    compared, _worst = _adf_to_urdf_against_runner(client, name, tmp_path, configs=100)
    assert compared == bodies


@needs_corpus
@pytest.mark.parametrize("name", CORPUS_ROBOTS)
def test_tree_at_initial_values_reproduces_the_files_locations(name):
    """The frames the converters use are AMBF's: FK at the initial joint values puts every
    body where the file's `location` does (to the file's rounding)."""
    model = load(ROBOTS / name)
    tree = build_tree(model)
    world = tree.fk()
    for b in model.bodies:
        if b.identifier in tree.links and b.location is not None:
            assert (world[b.identifier].position - b.location.position).norm() < 2e-3, b.identifier
            assert world[b.identifier].orientation.angle_to(b.location.orientation) < 2e-3, b.identifier


# --- ADF -> URDF -> ADF -------------------------------------------------------------------------


@needs_corpus
def test_kuka_adf_urdf_adf_round_trip_and_exact_losses(tmp_path):
    orig = load(ROBOTS / "blender-kuka.yaml")
    out = tmp_path / "kuka.urdf"
    losses = write(orig, out)
    expected = expected_losses(
        orig,
        ("collision groups", "collision margin", "damping", "friction", "passive"),
        ("max motor impulse", "controller"),
    )
    # links 1-5, moving concave meshes filling 70-76 % of their hulls, collide as convex parts
    # (geometry.concave), a <collision> each, as in the runner's engines
    parts = [(f"BODY link{n}", "concave collision mesh") for n in range(1, 6)]
    assert loss_keys(losses) == sorted(expected + parts)
    assert len(losses) == 51  # friction, damping, margin, groups on 8 links; 7 inertias, 7 controllers; 5 parts
    back, read_losses = read(out)
    assert loss_keys(read_losses) == sorted((b, "collision mesh") for b, _ in parts)  # ADF keeps one mesh
    _assert_same_kinematics(orig, back, set())


@needs_corpus
def test_psm_adf_urdf_adf_round_trip_and_exact_losses(tmp_path):
    orig = load(ROBOTS / "blender-psm.yaml")
    out = tmp_path / "psm.urdf"
    losses = write(orig, out)
    keys = loss_keys(losses)
    structural = [k for k in keys if k[1] in ("joint", "body", "initial value")]
    assert structural == sorted(
        [
            ("BODY target_fk", "body"),
            ("BODY target_ik", "body"),
            ("JOINT pitch back link-pitch bottom link", "joint"),  # closes the parallelogram
            ("JOINT pitch top link-pitch end link", "joint"),  # closes the parallelogram
            ("JOINT yaw link-pitch end link", "joint"),  # p2p
        ]
    )
    # and per body/joint, exactly: the ADF keys URDF has no element for, and the inertias the
    # file leaves out (written as Bullet's estimate), on what is written
    not_written = {k[0] for k in structural if k[1] in ("joint", "body")}
    per_key = [
        k
        for k in expected_losses(
            orig,
            ("collision groups", "collision margin", "damping", "friction", "passive", "restitution"),
            ("max motor impulse", "controller"),
        )
        if k[0] not in not_written
    ]
    # the moving links' concave meshes that fill too little of their hulls are written as parts
    parts = [k for k in keys if k[1] == "concave collision mesh"]
    assert parts and all(orig.body(b).mass for b, _ in parts)
    assert keys == sorted(structural + per_key + parts)
    assert len(keys) == 80 + len(parts)  # 5 structural; 64 keys on the 12 bodies written, 11 on the joints written
    back, read_losses = read(out)
    # the file's own 0.36 mrad tilt between this joint's axes, which AMBF ignores, is reported;
    # a link written as parts keeps one of them
    assert loss_keys(read_losses) == sorted(
        [("JOINT pitch back link-pitch top link", "axis tilt")] + [(b, "collision mesh") for b, _ in parts]
    )
    lost = {
        "BODY target_fk",
        "BODY target_ik",
        "JOINT pitch back link-pitch bottom link",
        "JOINT pitch top link-pitch end link",
        "JOINT yaw link-pitch end link",
    }
    _assert_same_kinematics(orig, back, lost)


# --- bad input and the command line ------------------------------------------------------------

BAD = {
    "entity bomb": ('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY a "aaaa">]>\n<robot name="r"/>\n', "xml-unsafe", 2),
    "not xml": ('<robot name="r">\n  <link name="a">\n</robot>\n', "xml-syntax", 3),
    "missing parent": (
        '<robot name="r">\n  <link name="a"/>\n  <joint name="j" type="fixed">\n'
        '    <parent link="nope"/>\n    <child link="a"/>\n  </joint>\n</robot>\n',
        "urdf-reference",
        4,
    ),
    "cycle": (
        '<robot name="r">\n  <link name="a"/>\n  <link name="b"/>\n'
        '  <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>\n'
        '  <joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint>\n</robot>\n',
        "urdf-tree",
        None,
    ),
    "bad origin": (
        '<robot name="r">\n  <link name="a"/>\n  <link name="b"/>\n'
        '  <joint name="j" type="fixed">\n    <origin xyz="0 zero 0"/>\n'
        '    <parent link="a"/><child link="b"/>\n  </joint>\n</robot>\n',
        "urdf-number",
        5,
    ),
    "wrong root": ('<mujoco model="m"/>\n', "urdf-root", 1),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_urdf_is_a_located_diagnostic(case, tmp_path):
    text, rule, line = BAD[case]
    assert_located_error(read, tmp_path / "bad.urdf", text, rule, line)


def test_convert_command_exit_codes(tmp_path):
    src = DATA / "r2d2.urdf"
    res = convert_cli(src, tmp_path / "r2d2.yaml")
    assert res.returncode == 0, res.stderr
    assert "item(s) not carried over" in res.stdout and "visual primitive" in res.stdout
    assert (tmp_path / "r2d2.yaml").is_file()
    assert convert_cli(src, tmp_path / "again.yaml", "--fail-on-loss").returncode == 1
    bad = tmp_path / "bad.urdf"
    bad.write_text(BAD["missing parent"][0])
    res = convert_cli(bad, tmp_path / "bad.yaml")
    assert res.returncode == 2
    assert f"{bad}:4" in res.stderr and "urdf-reference" in res.stderr
    assert not (tmp_path / "bad.yaml").exists()
