"""Cameras and lights between ADF (adf-format.md §9, §10) and MJCF.

An ADF camera is a location, a point it looks at and an up vector in its parent body's frame,
with a vertical field of view in radians; an MJCF camera is a frame in its body (looking
along −Z, +Y up, fovy in degrees). Both use fy = (H/2)/tan(fovy/2), so a camera maps exactly.
An ADF light is a spot light whose `direction` is its +X axis; MJCF's `light` has `dir`,
`cutoff` (degrees, the same half-angle), `exponent` and `attenuation`. What one side has and
the other cannot hold is a loss (MuJoCo's tracking modes, colours, stereo rendering, ...).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from ..model.objects import Attenuation, Camera, ClippingPlane, Light, Resolution
from ..model.pose import Pose, Quat, Vec3
from ..model.semantics import camera_pose
from ..model.spec import adf_fields
from ..model.tree import find_body
from .losses import Loss
from .urdf import _num, _unique, _vec

# MuJoCo's compiled-model enums and defaults (stable across 3.x–4.x)
_FIXED = 0
_SPOT = 0
_LIGHT_TYPES = {1: "directional", 2: "point", 3: "image"}
_DEFAULT_COLOURS = {"diffuse": (0.7, 0.7, 0.7), "ambient": (0.0, 0.0, 0.0), "specular": (0.3, 0.3, 0.3)}
_DEFAULT_IPD = 0.068
# ADF defaults (§9, §10)
ADF_FOV = 0.7
ADF_SPOT_EXPONENT = 0.7
ADF_CUTOFF = 0.7
SHADOW_QUALITY = 3  # what a MuJoCo light that casts shadows becomes (0 none … 5 very high)

_CAMERA_KEYS = {
    "name",
    "parent",
    "location",
    "look at",
    "up",
    "field view angle",
    "orthographic view width",
    "publish image resolution",
    "stereo",
}
_LIGHT_KEYS = {
    "name",
    "parent",
    "location",
    "direction",
    "spot exponent",
    "cutoff angle",
    "shadow quality",
    "attenuation",
}


def _v(a) -> Vec3:
    return Vec3(*(float(x) for x in a))


# ---- MJCF → ADF ------------------------------------------------------------------------------


def _g7(x: float) -> float:
    return float(f"{float(x):.7g}")  # MuJoCo keeps these in float32


def read_cameras(m, d, names: dict[int, str], world_pose: dict[int, Pose], losses: list[Loss]) -> list[Camera]:
    """The compiled model's cameras as ADF cameras on their bodies, where they are at qpos0
    (``d``: mj_kinematics and mj_camlight done; ``world_pose[b]``: ADF body frame in the world)."""
    out = []
    near, far = _g7(m.vis.map.znear * m.stat.extent), _g7(m.vis.map.zfar * m.stat.extent)
    for c in range(m.ncam):
        name = m.camera(c).name or f"camera{c}"
        who = f"CAMERA {name}"
        b = int(m.cam_bodyid[c])
        to_body = world_pose[b].inverse() if b > 0 else Pose()
        rot = [[float(v) for v in d.cam_xmat[c][3 * r : 3 * r + 3]] for r in range(3)]
        pose = to_body * Pose(_v(d.cam_xpos[c]), Quat.from_matrix(rot))
        forward = pose.orientation.rotate(Vec3(0.0, 0.0, -1.0))
        cam = Camera(
            identifier=who,
            name=name,
            location=pose.position,
            look_at=pose.position + forward,
            up=pose.orientation.rotate(Vec3(0.0, 1.0, 0.0)),
            clipping_plane=ClippingPlane(near=near, far=far),
        )
        if b > 0:
            cam.parent = f"BODY {names[b]}"
        w, h = (int(x) for x in m.cam_resolution[c])
        if (w, h) != (1, 1):
            cam.publish_image_resolution = Resolution(width=float(w), height=float(h))
        fovy = float(m.cam_fovy[c])
        if int(m.cam_projection[c]) == 1:
            # MuJoCo's orthographic fovy is the view's height in metres; ADF takes its width
            cam.orthographic_view_width = fovy * (w / h if (w, h) != (1, 1) else 1.0)
            if (w, h) == (1, 1):
                losses.append(
                    Loss(
                        who,
                        "orthographic",
                        "no resolution to turn the view's height into the width ADF takes: written for a square image",
                    )
                )
        else:
            cam.field_view_angle = math.radians(fovy)
        if int(m.cam_mode[c]) != _FIXED:
            losses.append(
                Loss(
                    who,
                    "camera mode",
                    "ADF cameras are fixed to their parent: a tracking MuJoCo "
                    "camera is written where it is and looks at qpos0",
                )
            )
        if abs(float(m.cam_ipd[c]) - _DEFAULT_IPD) > 1e-12:
            losses.append(Loss(who, "ipd", "ADF gives an eye separation only with stereo on"))
        if any(float(x) for x in m.cam_sensorsize[c]):
            losses.append(Loss(who, "sensor size", "ADF takes a vertical field of view: written from fovy"))
        out.append(cam)
    return out


def read_lights(m, d, names: dict[int, str], world_pose: dict[int, Pose], losses: list[Loss]) -> list[Light]:
    """The compiled model's lights as ADF spot lights on their bodies, as they are at qpos0."""
    out = []
    for i in range(m.nlight):
        name = m.light(i).name or f"light{i}"
        who = f"LIGHT {name}"
        b = int(m.light_bodyid[i])
        to_body = world_pose[b].inverse() if b > 0 else Pose()
        att = [float(x) for x in m.light_attenuation[i]]
        light = Light(
            identifier=who,
            name=name,
            location=to_body.transform(_v(d.light_xpos[i])),
            direction=to_body.orientation.rotate(_v(d.light_xdir[i])),
            spot_exponent=float(m.light_exponent[i]),
            cutoff_angle=math.radians(float(m.light_cutoff[i])),
            shadow_quality=SHADOW_QUALITY if bool(m.light_castshadow[i]) else 0,
            attenuation=Attenuation(constant=att[0], linear=att[1], quadratic=att[2]),
        )
        if b > 0:
            light.parent = f"BODY {names[b]}"
        kind = int(m.light_type[i])
        if kind != _SPOT:
            losses.append(
                Loss(
                    who,
                    "light type",
                    f"ADF lights are spot lights: a {_LIGHT_TYPES.get(kind, kind)} "
                    "light is written as a spot at its position",
                )
            )
        if int(m.light_mode[i]) != _FIXED:
            losses.append(Loss(who, "light mode", "ADF lights are fixed to their parent"))
        for attr, default in _DEFAULT_COLOURS.items():
            if any(abs(float(x) - d) > 1e-6 for x, d in zip(getattr(m, f"light_{attr}")[i], default)):  # float32
                losses.append(Loss(who, f"{attr} colour", "ADF lights have no colour"))
        if not bool(m.light_active[i]):
            losses.append(Loss(who, "active", "an ADF light is always on"))
        out.append(light)
    return out


# ---- ADF → MJCF ------------------------------------------------------------------------------


def write_cameras_lights(
    model, tree, elements: dict[int, ET.Element], world: ET.Element, used: dict, losses: list[Loss], lights: bool = True
) -> None:
    """Each ADF camera and light of ``model`` into the MJCF body of its parent (``elements``:
    link id → body element), or into ``world`` without a parent."""
    used.setdefault("camera", set())
    used.setdefault("light", set())
    for cam in model.cameras:
        placed = _parent_frame(model, tree, cam, elements, world, losses, "camera")
        if placed is not None:
            _write_camera(cam, *placed, used, losses)
    for light in model.lights if lights else []:
        placed = _parent_frame(model, tree, light, elements, world, losses, "light")
        if placed is not None:
            _write_light(light, *placed, used, losses)


def _parent_frame(model, tree, obj, elements, world, losses, label, depth: int = 0):
    """(MJCF element, parent frame → that element's frame) for an object's `parent`: a body,
    or a camera of this file (AMBF follows a camera as a parent: the drilling projects' stereo
    pair under main_camera), through that camera's own parent."""
    if not obj.parent:
        return world, Pose()
    body = find_body(model, obj.parent)
    cam = next((c for c in model.cameras if obj.parent in (c.identifier, c.name) and c is not obj), None)
    if body is None and cam is not None and depth < 16:
        placed = _parent_frame(model, tree, cam, elements, world, losses, label, depth + 1)
        frame = camera_pose(cam)
        if placed is None or frame is None:
            return None
        return placed[0], placed[1] * frame
    link = tree.links.get(body.identifier) if body is not None else None
    if link is None or id(link) not in elements:
        losses.append(
            Loss(obj.identifier, label, f"parent {obj.parent!r} is not a body or camera of this file: not written")
        )
        return None
    el = elements[id(link)]
    return el, (Pose() if el is world else link.frame_in_body.inverse())


def _write_camera(cam: Camera, el: ET.Element, to_frame: Pose, used, losses) -> None:
    who = cam.identifier
    loc = cam.location or Vec3()
    at = cam.look_at or Vec3()
    up = cam.up or Vec3(0.0, 0.0, 1.0)
    f = at - loc
    if f.norm() < 1e-12 or up.cross(f).norm() < 1e-12 * max(f.norm(), 1.0):
        losses.append(
            Loss(
                who,
                "camera",
                "look at equals location or up is parallel to the view: AMBF leaves such "
                "a view unset, and so does MJCF: not written",
            )
        )
        return
    z = f.scaled(-1.0 / f.norm())
    x = up.cross(z).normalized()
    y = z.cross(x)
    rot = to_frame.orientation
    c = ET.SubElement(
        el,
        "camera",
        name=_unique(cam.name or who.removeprefix("CAMERA "), used["camera"]),
        mode="fixed",
        pos=_vec(to_frame.transform(loc)),
        xyaxes=_vec((*rot.rotate(x), *rot.rotate(y))),
    )
    res = cam.publish_image_resolution
    w = h = None
    if res is not None and res.width and res.height:
        w, h = float(res.width), float(res.height)
        c.set("resolution", f"{int(round(w))} {int(round(h))}")
    if cam.orthographic_view_width is not None:
        c.set("projection", "orthographic")
        c.set("fovy", _num(cam.orthographic_view_width * (h / w if w else 1.0)))
        if not w:
            losses.append(
                Loss(
                    who,
                    "orthographic view width",
                    "no resolution to turn the width into the height MuJoCo takes: written for a square image",
                )
            )
    else:
        c.set("fovy", _num(math.degrees(cam.field_view_angle if cam.field_view_angle is not None else ADF_FOV)))
    if cam.stereo is not None:
        if cam.stereo.eye_separation is not None:
            c.set("ipd", _num(cam.stereo.eye_separation))
        losses.append(
            Loss(
                who,
                "stereo",
                "MuJoCo renders stereo as a viewer setting: the eye separation is "
                "written as ipd, mode and focal length are not",
            )
        )
    if cam.clipping_plane is not None:
        losses.append(
            Loss(
                who,
                "clipping plane",
                "MuJoCo's near and far clipping are global (visual/map znear, "
                "zfar as fractions of the model's extent): not written",
            )
        )
    _other_keys(cam, _CAMERA_KEYS | {"clipping plane"}, who, losses, "camera")


def _write_light(light: Light, el: ET.Element, to_frame: Pose, used, losses) -> None:
    who = light.identifier
    d = light.direction if light.direction is not None and light.direction.norm() > 0 else Vec3(1.0, 0.0, 0.0)
    lt = ET.SubElement(
        el,
        "light",
        name=_unique(light.name or who.removeprefix("LIGHT "), used["light"]),
        mode="fixed",
        pos=_vec(to_frame.transform(light.location or Vec3())),
        dir=_vec(to_frame.orientation.rotate(d.normalized())),
        cutoff=_num(math.degrees(light.cutoff_angle if light.cutoff_angle is not None else ADF_CUTOFF)),
        exponent=_num(light.spot_exponent if light.spot_exponent is not None else ADF_SPOT_EXPONENT),
        castshadow="true" if (light.shadow_quality or 0) > 0 else "false",
    )
    a = light.attenuation
    if a is not None:
        lt.set(
            "attenuation", _vec((a.constant if a.constant is not None else 1.0, a.linear or 0.0, a.quadratic or 0.0))
        )
    _other_keys(light, _LIGHT_KEYS, who, losses, "light")


def _other_keys(obj, handled: set[str], who: str, losses: list[Loss], label: str) -> None:
    for f in adf_fields(obj):
        k = f.metadata["adf_key"]
        if k not in handled and getattr(obj, f.name) not in (None, [], {}):
            losses.append(Loss(who, k, f"MJCF has no {label} attribute for it"))
