"""ADF volumes in URDF: each volume's iso-surface (volume_mesh.py: one STL, or pieces of at most
200,000 triangles) as a link, visual and collision, fixed at the volume's location to a link
whose frame is the world frame. Each collision says ``concave="yes"`` (PyBullet's URDF reader
then collides a static link with the triangles themselves; other readers ignore it and use
each piece's convex hull)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..model.pose import Pose
from .losses import Loss
from .urdf_xml import _mesh_element, _origin, _unique, _vec
from .volume_mesh import volume_meshes


def write_urdf_volumes(model, robot: ET.Element, parent: str, out_dir: Path, stem: str, used: set, losses) -> None:
    """Each volume as a link with its mesh pieces as visual and collision, fixed to ``parent``
    (a link whose frame is the world frame) at the volume's location."""
    for vm in volume_meshes(model, out_dir, stem, "URDF", losses):
        link = _unique(vm.name, used)
        el = ET.SubElement(robot, "link", name=link)
        inertial = ET.SubElement(el, "inertial")  # static: fixed to the world frame
        ET.SubElement(inertial, "mass", value="0.0")
        ET.SubElement(inertial, "inertia", ixx="0.0", ixy="0.0", ixz="0.0", iyy="0.0", iyz="0.0", izz="0.0")
        for k, path in enumerate(vm.paths):
            vis = _mesh_element(el, "visual", Pose(), path, 1.0, out_dir)
            if vm.rgba is not None:
                mat = ET.SubElement(vis, "material", name=f"{link}_material" + (f"_{k}" if k else ""))
                ET.SubElement(mat, "color", rgba=_vec(vm.rgba))
        for path in vm.paths:
            _mesh_element(el, "collision", Pose(), path, 1.0, out_dir).set("concave", "yes")
        losses.append(
            Loss(
                vm.volume.identifier,
                "concave collision",
                'URDF has no concave mesh collision: written with concave="yes", which PyBullet honours for '
                "this static link; other readers collide each piece as its convex hull",
            )
        )
        joint = ET.SubElement(robot, "joint", name=_unique(f"{parent}_to_{link}", used), type="fixed")
        _origin(joint, vm.pose)
        ET.SubElement(joint, "parent", link=parent)
        ET.SubElement(joint, "child", link=link)


__all__ = ["write_urdf_volumes"]
