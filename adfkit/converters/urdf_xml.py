"""Small URDF XML helpers shared by the URDF and MJCF writers and the volume writers: numbers,
vectors, <origin>, unique names, mesh references, colours."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from ..model.pose import Pose, Quat


def _num(v: float) -> str:
    v = 0.0 if abs(v) < 1e-15 else float(v)
    return repr(v)


def _vec(v) -> str:
    return " ".join(_num(x) for x in v)


def _origin(parent: ET.Element, pose: Pose) -> None:
    if pose.position.norm() < 1e-15 and pose.orientation.angle_to(Quat(0.0, 0.0, 0.0, 1.0)) < 1e-15:
        return
    ET.SubElement(parent, "origin", xyz=_vec(pose.position), rpy=_vec(pose.rpy()))


def _unique(name: str, used: set[str]) -> str:
    out, n = name, 1
    while out in used:
        n += 1
        out = f"{name}_{n}"
    used.add(out)
    return out


def _mesh_ref(mesh: Path, out_dir: Path) -> str:
    return Path(os.path.relpath(mesh.resolve(), out_dir.resolve())).as_posix()


def _material(body) -> tuple[float, float, float, float] | None:
    if body.color_rgba is not None:
        c = body.color_rgba
        return (c.r or 0.0, c.g or 0.0, c.b or 0.0, 1.0 if c.a is None else c.a)
    cc = body.color_components
    if cc is not None and cc.diffuse is not None:
        d = cc.diffuse
        a = cc.transparency if cc.transparency is not None else 1.0  # chai3d: 1 = opaque
        return (d.r or 0.0, d.g or 0.0, d.b or 0.0, a)
    return None


def _mesh_element(link_el: ET.Element, tag: str, pose: Pose, mesh: Path, scale: float, out_dir: Path) -> ET.Element:
    """A <visual> or <collision> holding a mesh at ``pose`` in the link frame."""
    el = ET.SubElement(link_el, tag)
    _origin(el, pose)
    m = ET.SubElement(ET.SubElement(el, "geometry"), "mesh", filename=_mesh_ref(mesh, out_dir))
    if scale != 1.0:
        m.set("scale", _vec((scale,) * 3))
    return el
