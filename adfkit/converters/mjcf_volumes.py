"""ADF volumes in MJCF: each volume as a static <body> in <worldbody> at the volume's location:
its iso-surface (volume_mesh.py: one STL, or pieces of at most 200,000 triangles) as mesh geoms
that are drawn and do not collide, and the convex parts the MuJoCo engine collides by (the
hull's vertices per block of 8³ voxels the surface crosses, inline in <asset>) as mesh geoms
that collide and are not drawn (group 3)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from ..geometry.surface_parts import PART_BLOCK
from .losses import Loss
from .urdf_xml import _unique, _vec
from .volume_mesh import volume_meshes


def write_mjcf_volumes(model, world_el: ET.Element, assets, stem: str, used: dict, losses: list[Loss]) -> None:
    """Each volume as a static <body> in <worldbody>: visual mesh geoms and collision parts."""
    for vm in volume_meshes(model, assets.out_dir, stem, "MJCF", losses, with_parts=True):
        body = ET.SubElement(world_el, "body", name=_unique(vm.name, used["body"]))
        body.set("pos", _vec(vm.pose.position))
        q = vm.pose.orientation
        body.set("quat", _vec((q.w, q.x, q.y, q.z)))
        for k, path in enumerate(vm.paths):
            geom = ET.SubElement(
                body,
                "geom",
                name=_unique(vm.name if len(vm.paths) == 1 else f"{vm.name}_{k}", used["geom"]),
                type="mesh",
                mesh=assets.mesh(path, 1.0),
                contype="0",
                conaffinity="0",
                group="1",
            )
            if vm.rgba is not None:
                geom.set("rgba", _vec(vm.rgba))
        for k, points in enumerate(vm.parts):
            mesh = _unique(f"{vm.name}_part{k}", assets.used)
            ET.SubElement(assets.el, "mesh", name=mesh, vertex=" ".join(f"{x:.7g}" for x in points.ravel()))
            ET.SubElement(body, "geom", name=_unique(mesh, used["geom"]), type="mesh", mesh=mesh, group="3")
        losses.append(
            Loss(
                vm.volume.identifier,
                "concave collision",
                f"MuJoCo collides a mesh as its convex hull: the volume collides by {len(vm.parts)} convex parts "
                f"of at most {PART_BLOCK}³ voxels, so a cavity smaller than a part is solid to contacts",
            )
        )


__all__ = ["write_mjcf_volumes"]
