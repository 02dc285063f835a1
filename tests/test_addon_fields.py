"""Pure parts of the Blender add-on (no bpy): joint frames from a placed frame, field merge."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from addon import fields  # noqa: E402
from addon.joint_frames import derive  # noqa: E402
from adfkit.model import Body, Joint, Pose  # noqa: E402
from adfkit.model.pose import Vec3, rpy_to_quat  # noqa: E402
from adfkit.model.semantics import joint_frames  # noqa: E402

P = Pose(Vec3(0.1, 0.2, 0.3), rpy_to_quat(0.3, -0.2, 1.0))
C = Pose(Vec3(0.4, 0.1, 0.2), rpy_to_quat(-1.0, 0.5, 0.2))
F = Pose(Vec3(0.2, 0.3, 0.1), rpy_to_quat(0.7, 0.1, -0.4))


@pytest.mark.parametrize("jtype", ["revolute", "prismatic", "six dof spring", "torsion spring", "fixed"])
def test_derived_joint_frames_coincide_at_the_placed_frame(jtype):
    j = Joint(type=jtype, **derive(jtype, P, C, F, parent_scale=2.0, child_scale=0.5))
    a, b = joint_frames(j, 2.0, 0.5)
    wa, wb = P * a, C * b
    assert (wa.position - F.position).norm() < 1e-9 and (wb.position - F.position).norm() < 1e-9
    assert wa.orientation.angle_to(F.orientation) < 1e-9 and wb.orientation.angle_to(F.orientation) < 1e-9


def test_revolute_axis_is_the_frame_z_in_the_parent_frame():
    d = derive("revolute", Pose(), Pose(Vec3(0, 0, 1)), Pose(Vec3(0, 0, 0.5), rpy_to_quat(0, 1.5707963267948966, 0)))
    assert d["parent_axis"] == pytest.approx((1, 0, 0)) and d["child_pivot"] == pytest.approx((0, 0, -0.5))
    assert d["offset"] == 0.0


def test_merge_keeps_exact_values_that_float32_storage_did_not_change():
    b = Body(mass=0.123456789, restitution=0.1)
    values = {f.prop: fields.get_value(b, f) for f in fields.BODY}
    values["mass"] = fields.f32(0.123456789)  # what Blender stores
    values["friction_static"] = 0.7  # user edit creates the friction block
    values["restitution"] = None  # user unticked it
    fields.merge(b, fields.BODY, values)
    assert b.mass == 0.123456789 and b.friction.static == 0.7 and b.friction.rolling is None
    assert b.restitution is None
    values["friction_static"] = None
    fields.merge(b, fields.BODY, values)
    assert b.friction is None  # no empty 'friction: {}' left behind


def test_collision_groups_are_checked():
    assert fields.parse_groups("0, 3,12") == [0, 3, 12]
    with pytest.raises(ValueError, match="outside 0-999"):
        fields.parse_groups("1000")
    with pytest.raises(ValueError, match="not an integer"):
        fields.parse_groups("a")
