"""ADF volumes in Blender: each volume's iso-surface (adfkit.geometry.volume, marching cubes at
its `iso-surface value`) as a mesh object to see it, at the volume's location, in its colour.

The object is a picture only (ADF kind NONE, never exported): the volume itself, its slices
kept by reference, is carried through export as written (build.py's snapshot, with the slice
folder rebased when the file moves), so an import followed by an export changes nothing.
A volume whose slices cannot be read gets no object and a warning.

A volume can also be authored from a folder of slice images (:func:`author_volume`, the Add
volume operator): the object then carries the volume (``AUTHORED_KEY``, its ADF text with the
folder's absolute path), may be moved, and is exported where it stands, its slice folder written
relative to the exported file (the slices copied beside it when the folder lies outside its
tree)."""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, FloatProperty, FloatVectorProperty, StringProperty
from mathutils import Quaternion, Vector

from adfkit.diagnostics import AdfError, Diagnostic, warning
from adfkit.model import Pose

#: the custom property naming the volume an iso-surface object shows
VOLUME_KEY = "adf_volume"
#: the custom property holding an authored volume's ADF text (absolute slice folder, no location)
AUTHORED_KEY = "adf_volume_authored"


def _matrix(p: Pose):
    q = p.orientation
    m = Quaternion((q.w, q.x, q.y, q.z)).to_matrix().to_4x4()
    m.translation = Vector(p.position)
    return m


def import_volumes(doc, scene, diags: list[Diagnostic], body_named=None) -> list:
    """One mesh object per readable volume of ``doc``; returns them. A volume whose `parent`
    names a body (``body_named``: reference -> the body's object, or None) is placed in that
    body's frame and parented to it, as AMBF places it (the skull-base project's volume under
    ``BODY volume_Anatomical_Origin``)."""
    from adfkit.geometry.volume import DEFAULT_ISO, iso_surface, load_volume

    made = []
    for vol in doc.volumes:
        if not vol.defined:
            continue
        level = vol.iso_surface_value if vol.iso_surface_value is not None else DEFAULT_ISO
        try:
            verts, faces = iso_surface(load_volume(doc, vol), level)
        except AdfError as exc:
            for d in exc.diagnostics:
                diags.append(warning(d.rule, f"{d.message}; the volume is kept but not shown", d.location, d.hint))
            continue
        obj = _surface_object(scene, vol, verts, faces)
        parent = body_named(vol.parent) if body_named is not None and vol.parent else None
        local = _matrix(vol.location or Pose())
        obj.parent = parent
        obj.matrix_world = parent.matrix_world.normalized() @ local if parent is not None else local
        obj.hide_select = True  # a picture of the slices: editing it would change nothing
        made.append(obj)
    return made


def _surface_object(scene, vol, verts, faces):
    name = vol.name or vol.identifier.removeprefix("VOLUME ")
    mesh = bpy.data.meshes.new(f"{name} iso-surface")
    mesh.from_pydata(verts.tolist(), [], faces.tolist())
    mesh.update()
    obj = bpy.data.objects.new(f"{name} (volume)", mesh)
    scene.collection.objects.link(obj)
    obj[VOLUME_KEY] = vol.identifier
    c = vol.color_rgba
    if c is not None and None not in (c.r, c.g, c.b):
        obj.color = (c.r, c.g, c.b, 1.0 if c.a is None else c.a)
    return obj


def volume_identifiers(scene) -> set[str]:
    """The volumes the scene already has: imported (kept as written) and authored."""
    import json

    snap = json.loads(scene.adf.snapshot) if scene.adf.snapshot else {}
    taken = {ident for ident, _ in snap.get("kept", {}).get("volumes", [])}
    return taken | {o[VOLUME_KEY] for o in scene.objects if VOLUME_KEY in o}


def _refuse(rule: str, message: str, hint: str) -> AdfError:
    from adfkit.diagnostics import SourceLocation, error

    return AdfError(error(rule, message, SourceLocation("<add volume>"), hint))


def author_volume(
    scene, folder, name: str, dimensions, iso: float, colour=None, prefix: str | None = None, location=(0, 0, 0)
) -> tuple[object, list[Diagnostic]]:
    """A new ADF volume from the slice stack in ``folder`` (geometry.volume_folder finds it),
    shown as its iso-surface at ``location``; returns (the object, warnings). A folder without
    one clean stack, a bad size, level or name is an AdfError saying what to change."""
    from pathlib import Path

    from adfkit.geometry.volume import iso_surface, load_volume
    from adfkit.geometry.volume_folder import find_slices
    from adfkit.model import ModelFile, Vec3
    from adfkit.model.common import RGBA
    from adfkit.model.objects import Volume, VolumeImages

    from . import fields

    name = (name or "").strip()
    if not name:
        raise _refuse("volume-name", "the volume has no name", "give it a name, e.g. Bone")
    ident = f"VOLUME {name}"
    if ident in volume_identifiers(scene):
        raise _refuse("volume-name-taken", f"the scene already has a volume named '{name}'", "give it another name")
    dims = [float(d) for d in dimensions]
    if len(dims) != 3 or not all(d > 0 for d in dims):
        raise _refuse("volume-dimensions", f"dimensions {dims} must be three positive sizes", "give x, y, z in metres")
    if not 0.0 < float(iso) < 1.0:
        raise _refuse(
            "volume-iso", f"iso-surface value {iso:g} is outside 0..1", "a fraction of the slices' full scale, e.g. 0.5"
        )
    stack = find_slices(Path(folder).expanduser().resolve(), prefix or None)
    vol = Volume(
        identifier=ident,
        name=name,
        dimensions=Vec3(*(fields.tidy(d) for d in dims)),
        iso_surface_value=fields.tidy(float(iso)),
        images=VolumeImages(
            path=stack.folder.as_posix() + "/", prefix=stack.prefix, format=stack.format, count=stack.count
        ),
    )
    if colour is not None:
        rgba = (list(colour) + [1.0])[:4]
        vol.color_rgba = RGBA(**{k: fields.tidy(float(c)) for k, c in zip("rgba", rgba)})
    data = load_volume(ModelFile(), vol)  # every slice read as the runner and the validator will
    verts, faces = iso_surface(data, vol.iso_surface_value)
    warnings = []
    if not len(faces):
        warnings.append(
            warning(
                "volume-empty-surface",
                f"volume '{name}': no voxel reaches the iso-surface value {iso:g}; nothing to show",
                None,
                "lower the iso-surface value",
            )
        )
    obj = _surface_object(scene, vol, verts, faces)
    obj[AUTHORED_KEY] = fields.snapshot_text(vol)
    obj.location = tuple(location)
    return obj, warnings


def gather_authored(objs) -> list:
    """The authored volumes among ``objs``, each where its object stands (images: the absolute
    folder; export.rebase_authored writes it relative to the exported file)."""
    from adfkit.model.objects import Volume

    from . import fields, gather

    out = []
    for o in objs:
        if AUTHORED_KEY not in o:
            continue
        vol = fields.from_snapshot(Volume, o[AUTHORED_KEY], f"blender:{o.name}")
        vol.identifier = o[VOLUME_KEY]
        vol.location = gather.world_pose(o)
        out.append(vol)
    return out


def read_where_they_are(found: list[Diagnostic], model, source_dir) -> list[Diagnostic]:
    """The Check operator's findings with every volume's slices read from where they are: the
    validator read them against a file not yet written (the current folder), so an authored
    volume (absolute folder) and an imported one (relative to ``source_dir``, its file's
    folder) are read again from their own folders."""
    import copy
    import os

    from adfkit.model import ModelFile
    from adfkit.validator.volume_rules import check

    placed = []
    for vol in model.volumes:
        vol = copy.deepcopy(vol)
        im = vol.images
        if im is not None and im.path and not os.path.isabs(im.path) and source_dir:
            im.path = os.path.join(source_dir, im.path)
        placed.append(vol)
    return [d for d in found if not d.rule.startswith("volume-")] + check(ModelFile(volumes=placed))


class ADF_OT_add_volume(bpy.types.Operator):
    bl_idname = "adf.add_volume"
    bl_label = "Add volume from slices"
    bl_description = (
        "An ADF volume from a folder of slice images (prefix + index + extension, from 0), "
        "shown as its iso-surface; exported under volumes"
    )
    bl_options = {"REGISTER", "UNDO"}
    directory: StringProperty(subtype="DIR_PATH")
    volume_name: StringProperty(name="Name", default="Volume")
    prefix: StringProperty(name="Prefix", description="the slices' common prefix (empty: the folder's one stack)")
    dimensions: FloatVectorProperty(
        name="Dimensions", description="the size of the voxel box, m", size=3, default=(0.1, 0.1, 0.1), min=0.0
    )
    iso_value: FloatProperty(
        name="Iso-surface value", description="a fraction of the slices' full scale", default=0.5, min=0.0, max=1.0
    )
    use_colour: BoolProperty(name="Colour", default=False)
    colour: FloatVectorProperty(name="Colour", subtype="COLOR", size=4, default=(0.93, 0.89, 0.78, 1.0), min=0, max=1)

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        try:
            obj, warnings = author_volume(
                context.scene,
                self.directory,
                self.volume_name,
                tuple(self.dimensions),
                self.iso_value,
                tuple(self.colour) if self.use_colour else None,
                self.prefix or None,
                tuple(context.scene.cursor.location),
            )
        except AdfError as exc:
            self.report({"ERROR"}, "; ".join(d.message + (f" — {d.hint}" if d.hint else "") for d in exc.diagnostics))
            return {"CANCELLED"}
        for w in warnings:
            self.report({"WARNING"}, w.message + (f" — {w.hint}" if w.hint else ""))
        self.report({"INFO"}, f"Added {obj.name}")
        return {"FINISHED"}


__all__ = ["ADF_OT_add_volume", "AUTHORED_KEY", "VOLUME_KEY", "author_volume", "gather_authored", "import_volumes"]
