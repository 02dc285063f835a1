"""ADF volumes in MJCF: each volume's iso-surface mesh (volume_mesh.py) as a static <body>
in <worldbody> at the volume's location, with one mesh <geom>, drawn and colliding."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from .losses import Loss
from .urdf_xml import _unique, _vec
from .volume_mesh import volume_meshes


def write_mjcf_volumes(model, world_el: ET.Element, assets, stem: str, used: dict, losses: list[Loss]) -> None:
    """Each volume as a static <body> in <worldbody> with one mesh <geom> (visual and collision)."""
    for vm in volume_meshes(model, assets.out_dir, stem, "MJCF", losses):
        body = ET.SubElement(world_el, "body", name=_unique(vm.name, used["body"]))
        body.set("pos", _vec(vm.pose.position))
        q = vm.pose.orientation
        body.set("quat", _vec((q.w, q.x, q.y, q.z)))
        geom = ET.SubElement(
            body, "geom", name=_unique(vm.name, used["geom"]), type="mesh", mesh=assets.mesh(vm.path, 1.0)
        )
        if vm.rgba is not None:
            geom.set("rgba", _vec(vm.rgba))
        losses.append(
            Loss(
                vm.volume.identifier,
                "concave collision",
                "MuJoCo collides a mesh as its convex hull: the volume's cavities are solid to contacts",
            )
        )


__all__ = ["write_mjcf_volumes"]
