"""Checks shared by the converter tests: models equal up to a tree format's spelling."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from adfkit.adf.paths import visual_mesh_path
from adfkit.converters.inertia import world_tensor
from adfkit.model.pose import Pose, Quat, Vec3
from adfkit.model.semantics import JointKind, body_joint_frames, inertial_offset, joint_kind
from adfkit.model.tree import build_tree


def close_pose(a: Pose, b: Pose, tol=1e-6) -> bool:
    return (a.position - b.position).norm() < tol and a.orientation.angle_to(b.orientation) < tol


def joint_transform(joint, q: float, model) -> Pose:
    """The child's body frame in the parent's at joint value ``q``, as AMBF reads the joint (its
    frames built in the bodies' inertial frames)."""
    a, b = body_joint_frames(joint, model.body(joint.parent), model.body(joint.child))
    kind = joint_kind(joint.type)
    motion = (
        Pose(Vec3(), Quat.from_axis_angle(Vec3(0, 0, 1), q))
        if kind is JointKind.REVOLUTE
        else Pose(Vec3(q, 0, 0))
        if kind is JointKind.PRISMATIC
        else Pose()
    )
    return a * motion * b.inverse()


def assert_same_kinematics(orig, back, lost: set[str]):
    """Equal models up to URDF's spelling: the same bodies (mass, inertia in the world, meshes),
    the same joints (kind, limits, parent→child transform at several values). Normalisation:
    URDF starts every joint at 0, so each body comes back where the joints put it at 0 (the
    file's `location` differs by its rounding or by a reported initial value)."""
    at_zero = build_tree(orig).fk({j.identifier: 0.0 for j in orig.joints})
    ob = {b.identifier: b for b in orig.bodies if b.identifier not in lost}
    bb = {b.identifier: b for b in back.bodies if b.identifier not in lost}
    assert set(bb) == set(ob)
    for ident, b in ob.items():
        c = bb[ident]
        assert close_pose(c.location, at_zero[ident], 1e-9), ident
        assert (c.mass or 0.0) == pytest.approx(b.mass or 0.0, rel=1e-12)
        if b.mesh:
            assert Path(c.mesh).resolve() == visual_mesh_path(orig, b).resolve(), ident
        if b.inertia is not None and (b.mass or 0.0) > 0:  # a static body has no inertial frame to keep
            wb = world_tensor(
                (b.inertia.ix, b.inertia.iy, b.inertia.iz), (at_zero[ident] * inertial_offset(b)).orientation
            )
            wc = world_tensor((c.inertia.ix, c.inertia.iy, c.inertia.iz), (c.location * inertial_offset(c)).orientation)
            assert np.allclose(wb, wc, rtol=1e-9, atol=1e-15), ident
            assert (
                (at_zero[ident] * inertial_offset(b)).position - (c.location * inertial_offset(c)).position
            ).norm() < 1e-9
    oj = {j.identifier: j for j in orig.joints if j.identifier not in lost}
    bj = {j.identifier: j for j in back.joints if j.identifier not in lost}
    assert set(bj) == set(oj)
    for ident, j in oj.items():
        k = bj[ident]
        assert joint_kind(k.type) is joint_kind(j.type)
        assert (k.parent.removeprefix("BODY "), k.child.removeprefix("BODY ")) == (
            j.parent.removeprefix("BODY "),
            j.child.removeprefix("BODY "),
        )
        if j.joint_limits is not None and joint_kind(j.type) is not JointKind.FIXED:
            assert (k.joint_limits.low, k.joint_limits.high) == pytest.approx((j.joint_limits.low, j.joint_limits.high))
        # AMBF's shortest arc is the identity below 1e-3 rad (§8.2): a child frame tilted less
        # than that from the axis has no exact ADF spelling; such joints come back within it.
        tilt = Vec3(*k.parent_axis).normalized().cross(Vec3(*k.child_axis).normalized()).norm()
        rot_tol = 1e-9 if tilt < 1e-12 or tilt >= 1e-3 else 1e-3
        for q in (0.0, 0.3, -1.1):
            ta, tb = joint_transform(k, q, back), joint_transform(j, q, orig)
            assert (ta.position - tb.position).norm() < 1e-9, (ident, q)
            assert ta.orientation.angle_to(tb.orientation) < rot_tol, (ident, q)


def assert_located_error(read_fn, path: Path, text: str, rule: str, line: int | None) -> None:
    """Reading ``text`` raises AdfError with ``rule``, this file, ``line`` (when given) and a hint."""
    from adfkit.diagnostics import AdfError

    path.write_text(text)
    with pytest.raises(AdfError) as exc:
        read_fn(path)
    d = exc.value.diagnostics[0]
    assert d.rule == rule
    assert d.location.file == str(path)
    if line is not None:
        assert d.location.line == line
    assert d.hint


def convert_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "adfkit", "convert", *map(str, args)], capture_output=True, text=True)


def expected_losses(model, body_keys=(), joint_keys=()) -> list[tuple[str, str]]:
    """(identifier, key) for every body/joint that sets one of the ADF keys a format cannot hold,
    plus the inertia the writers estimate for bodies with mass and no `inertia`."""

    def is_set(obj, key):
        return getattr(obj, key.replace(" ", "_")) not in (None, [], False)

    out = [(b.identifier, k) for b in model.bodies for k in body_keys if is_set(b, k)]
    out += [(b.identifier, "inertia") for b in model.bodies if b.inertia is None and (b.mass or 0) > 0]
    out += [(j.identifier, k) for j in model.joints for k in joint_keys if is_set(j, k)]
    return sorted(out)
