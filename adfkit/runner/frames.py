"""Parents as AMBF follows them, for the objects the runner places relative to one (cameras,
lights, volumes): an object's pose is its parent's times its own ``location``
(``afBaseObject::updateGlobalPose``), and a parent may be a body or a camera, which may have a
parent of its own (the drilling projects' ``stereoL``, ``stereoR`` and ``light1`` hang from
``main_camera``). AMBF finds a parent by its qualified name, else by a unique part of one
(``resolveObjectsMissingParents``); one it cannot find leaves the object where its own
location puts it, in the world.

A camera's own frame is the one ``afCamera::setView`` makes from location, look at and up:
x from the point looked at towards the eye, z along up made orthogonal, y = z × x.
"""

from __future__ import annotations

import numpy as np

from ..model.semantics import camera_pose
from .names import merge_namespace
from .rotations import pose_to_matrix

MAX_DEPTH = 16  # parents deeper than this (or in a loop) are not followed


def camera_frame(cam) -> np.ndarray:
    """4×4 of an ADF camera in its parent's frame, as AMBF's setView makes it
    (model.semantics.camera_pose; an unset view: the camera's location, unturned)."""
    pose = camera_pose(cam)
    if pose is None:
        t = np.eye(4)
        t[:3, 3] = np.array(cam.location or (0.0, 0.0, 0.0), float)
        return t
    return pose_to_matrix(pose)


def scene_cameras(scene) -> list[tuple[str, str, object]]:
    """(qualified key, namespace, camera) of every camera of the world and the model files."""
    out = []
    w = scene.world
    for ns, cams in [(w.namespace or "", w.cameras)] if w is not None else []:
        out += [(merge_namespace(ns, c.namespace) + c.identifier, ns, c) for c in cams]
    for m in scene.all_models():
        ns = m.namespace or ""
        out += [(merge_namespace(ns, c.namespace) + c.identifier, ns, c) for c in m.cameras]
    return out


def match(keyed: list[tuple], ref: str, ns: str):
    """The entry of ``keyed`` ((qualified key, ..., object) tuples) that ``ref`` names as AMBF
    finds a parent: the qualified key as written or in the namespace ``ns``, else the object's
    identifier or name, else a unique part of a key; None when none or several match."""
    for want in (ref, ns + ref):
        exact = [c for c in keyed if c[0] == want]
        if exact:
            return exact[0]
    named = [c for c in keyed if ref in (c[-1].identifier, c[-1].name)]
    if len(named) == 1:
        return named[0]
    part = [c for c in keyed if ref in c[0]]
    return part[0] if len(part) == 1 else None


def resolve_frame(world, ref: str | None, ns: str, obj, body_type=None):
    """(root body or None, 4×4 of the parent's frame in the root body's ADF frame, or in the
    world when the root is None) for ``obj``'s parent ``ref``, through parent cameras. A parent
    that is not found is a ``runner-parent`` warning, and the object stays in the world frame
    (``None, identity``), as AMBF leaves it."""
    t = np.eye(4)
    seen: list[str] = []
    while ref:
        key, hit = world.registry.find(ref)
        if key is None:
            key, hit = world.registry.find(ns + ref)
        if key is not None and hit is not None and (body_type is None or isinstance(hit, body_type)):
            return hit, t
        cam = match(scene_cameras(world.scene), ref, ns)
        if cam is None or cam[0] in seen or len(seen) >= MAX_DEPTH:
            why = "a loop of parents" if cam is not None else "not found"
            world._warn(
                "runner-parent",
                f"{obj.identifier}: parent {ref!r} {why}; placed where its own location puts it in the world",
                obj,
                "name a body or a camera of the scene",
            )
            return None, t
        key, ns, c = cam
        seen.append(key)
        t = camera_frame(c) @ t
        ref = c.parent
    return None, t


__all__ = ["camera_frame", "match", "resolve_frame", "scene_cameras"]
