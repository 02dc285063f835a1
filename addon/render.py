"""Headless Workbench thumbnail of the ADF objects in a scene (for READMEs and reviews)."""

from __future__ import annotations

from pathlib import Path

import bpy
from mathutils import Vector


def thumbnail(scene, path: str | Path, size: int = 512) -> Path:
    objs = [o for o in scene.objects if o.type == "MESH" and o.adf.kind in ("BODY", "GHOST") and not o.hide_render]
    if not objs:
        raise ValueError("no ADF body with a mesh to render")
    pts = [o.matrix_world @ Vector(c) for o in objs for c in o.bound_box]
    lo = Vector(tuple(min(p[i] for p in pts) for i in range(3)))
    hi = Vector(tuple(max(p[i] for p in pts) for i in range(3)))
    centre, radius = (lo + hi) / 2, max((hi - lo).length / 2, 1e-3)
    cam = bpy.data.objects.new("adf-thumbnail", bpy.data.cameras.new("adf-thumbnail"))
    scene.collection.objects.link(cam)
    direction = Vector((1.0, -1.2, 0.8)).normalized()
    cam.location = centre + direction * radius * 3.2
    cam.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
    cam.data.clip_start, cam.data.clip_end = radius * 0.01, radius * 20
    try:
        scene.camera = cam
        r = scene.render
        r.engine = "BLENDER_WORKBENCH"
        r.resolution_x = r.resolution_y = size
        r.resolution_percentage = 100
        r.film_transparent = True
        r.image_settings.file_format = "PNG"
        shading = scene.display.shading
        shading.light, shading.color_type = "STUDIO", "MATERIAL"
        r.filepath = str(Path(path).resolve())
        bpy.ops.render.render(write_still=True)
    finally:
        bpy.data.objects.remove(cam, do_unlink=True)
    return Path(path)
