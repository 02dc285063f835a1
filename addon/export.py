"""Export the Blender scene as an ADF model: gather -> validate -> write (nothing on failure)."""

from __future__ import annotations

import dataclasses
import json
import os
import re
import shutil
from dataclasses import dataclass, field
from pathlib import Path

from adfkit.adf import dumps, read_file
from adfkit.adf.writer import atomic_write_text
from adfkit.diagnostics import Diagnostic, Severity, error, warning
from adfkit.geometry.volume_slices import find_slice_files
from adfkit.model import ModelFile

from . import fields, gather, gather_soft, meshes, namespaces, volumes

HASH_FILE = ".adfkit-meshes.json"


@dataclass
class ExportResult:
    path: Path | None
    diagnostics: list[Diagnostic] = field(default_factory=list)
    written: list[Path] = field(default_factory=list)
    skipped: list[Path] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.path is not None


def _model_level(scene) -> tuple[ModelFile, dict]:
    snap = json.loads(scene.adf.snapshot) if scene.adf.snapshot else {}
    if snap.get("keys"):
        doc, _ = read_file("snapshot.yaml", kind="model", text=snap["keys"])
        doc.path = None
    else:
        doc = ModelFile()
    doc.present_lists = set(snap.get("present", []))
    from adfkit.model.objects import Vehicle, Volume

    for key, cls in (("vehicles", Vehicle), ("volumes", Volume)):
        items = []
        for ident, text in snap.get("kept", {}).get(key, []):
            o = fields.from_snapshot(cls, text, f"blender:{ident}")
            o.identifier = ident
            items.append(o)
        setattr(doc, key, items)
    if scene.adf.use_namespace:
        doc.namespace = scene.adf.namespace
    if scene.adf.use_ignore_inter_collision:
        doc.ignore_inter_collision = scene.adf.ignore_inter_collision
    if scene.adf.use_gravity:
        from adfkit.model.pose import Vec3

        doc.gravity = Vec3(*(fields.tidy(g) for g in scene.adf.gravity))
    return doc, snap.get("order", {})


def _mesh_paths(doc: ModelFile, folder: str = "", out_dir: Path | None = None) -> tuple[str, str]:
    """The high- and low-res folders the model names, relative to its file: ``folder``'s
    high_res/ and low_res/ when the scene names a meshes folder (relative to the model file's
    folder, or absolute, or Blender's // for the .blend's folder), else the imported file's
    folders while they stay inside the output folder, else meshes/high_res/ and meshes/low_res/."""
    if folder:
        if folder.startswith("//"):
            import bpy

            folder = bpy.path.abspath(folder)
        base = Path(folder)
        if base.is_absolute() and out_dir is not None:
            base = Path(os.path.relpath(base, out_dir.resolve()))
        rel = "" if base.as_posix() in (".", "") else base.as_posix().rstrip("/") + "/"
        doc.high_resolution_path, doc.low_resolution_path = rel + "high_res/", rel + "low_res/"
        return doc.high_resolution_path, doc.low_resolution_path
    out = []
    for attr, default in (("high_resolution_path", gather.MESH_DIRS[0]), ("low_resolution_path", gather.MESH_DIRS[1])):
        p = getattr(doc, attr)
        if not p or os.path.isabs(p) or ".." in Path(p).parts:
            p = default  # keep every mesh inside the output folder
            setattr(doc, attr, p)
        out.append(p)
    return out[0], out[1]


def _ordered(objs, order: list[str]):
    """The objects in the order the imported file listed them, an identifier listed twice
    (the phantom's BODY BlackGround) again twice, where it stood; new ones after, by identifier."""
    groups: dict[str, list] = {}
    for o in objs:
        groups.setdefault(o.identifier, []).append(o)
    out, done = [], set()
    for ident in order:
        if ident in groups:
            out += groups[ident][:1] if ident in done else groups[ident]
            done.add(ident)
    return out + sorted((o for o in objs if o.identifier not in done), key=lambda o: o.identifier)


def gather_model(scene, objects=None, mesh_format: str | None = None, out_dir: Path | None = None) -> gather.Gathered:
    doc, order = _model_level(scene)
    hi, lo = _mesh_paths(doc, scene.adf.meshes_path, out_dir)
    sp = scene.adf
    fmt = (mesh_format or sp.mesh_format).upper()
    out = gather.Gathered(
        doc,
        options=gather.Options(apply_modifiers=sp.apply_modifiers, low_res_ratio=sp.low_res_ratio, mesh_format=fmt),
    )
    fields.PRECISION["digits"] = sp.precision
    objs = sorted(objects if objects is not None else scene.objects, key=lambda o: o.name)
    bodies, softs, ghosts, joints = [], [], [], []
    other = {k: [] for k in ("sensors", "actuators", "cameras", "lights")}
    for o in objs:
        k = o.adf.kind
        if k == "BODY":
            bodies.append(gather.gather_body(o, out, (hi, lo)))
            for b in bodies[-1:]:
                for attr in ("high_resolution_path", "low_resolution_path"):
                    setattr(b, attr, None)  # per-body folders are folded into the model folders
        elif k == "SOFT_BODY":
            softs.append(gather_soft.gather_soft_body(o, out, (hi, lo)))
            softs[-1].high_resolution_path = softs[-1].low_resolution_path = None
        elif k == "GHOST":
            ghosts.append(gather.gather_ghost(o, out, (hi, lo)))
        elif k == "JOINT":
            j = gather.gather_joint(o, out)
            if j is not None:
                joints.append(j)
        elif k in gather.GATHER:
            key, fn = gather.GATHER[k]
            other[key].append(fn(o, out))
    out.diagnostics += namespaces.findings(objs)
    doc.bodies = _ordered(bodies, order.get("bodies", []))
    doc.soft_bodies = _ordered(softs, order.get("soft bodies", []))
    doc.ghost_objects = _ordered(ghosts, order.get("ghost objects", []))
    doc.joints = _ordered(joints, order.get("joints", []))
    doc.volumes = [*doc.volumes, *volumes.gather_authored(objs)]  # those authored here, where they stand
    for key, items in other.items():
        setattr(doc, key, _ordered(items, order.get(key, [])))
    if not doc.all_objects() and not any(d.severity >= Severity.ERROR for d in out.diagnostics):
        out.diagnostics.append(
            error(
                "export-empty",
                "nothing to export: "
                + ("no selected object is" if objects is not None else "no object is")
                + " an ADF object",
                None,
                "give objects an ADF kind in their ADF panel (body, joint, ...)"
                + (", or export without 'Selected only'" if objects is not None else ""),
            )
        )
    seen: dict[str, str] = {}
    for job in out.jobs:
        rel = job.directory + job.filename
        if seen.get(rel, job.digest) != job.digest:
            out.diagnostics.append(
                error(
                    "mesh-name-clash",
                    f"two different meshes would be written as {rel}",
                    None,
                    "rename one of the objects",
                )
            )
        seen[rel] = job.digest
    return out


def validate(text: str, target: Path, pending: set[Path]) -> list[Diagnostic]:
    """Validator findings for the text about to be written (reader diagnostics if the
    validator is unavailable). Missing-file findings for meshes still to be written are dropped."""
    try:
        from adfkit.validator import validate_file
    except ImportError:  # pragma: no cover - validator not installed
        _, diags = read_file(target, kind="model", text=text)
        return diags
    res = validate_file(target, kind="model", text=text)
    keep = []
    for d in res.diagnostics:
        if d.rule in ("missing-file", "missing-mesh") and any(p.name in d.message for p in pending):
            continue
        if d.rule == "sensor-type" and d.severity >= Severity.ERROR:
            # a type AMBF 2.0 does not know (CONTACT, used by newer AMBF): carried through, not refused
            d = dataclasses.replace(
                d,
                severity=Severity.WARNING,
                message=d.message.split(";")[0] + "; unknown to AMBF 2.0, carried through as written",
            )
        keep.append(d)
    return keep


def merge_findings(ours: list[Diagnostic], theirs: list[Diagnostic]) -> list[Diagnostic]:
    """Gather findings, then the validator's, each (rule, object) said once: the validator's
    wording wins where both report the same thing (a light without shadow quality)."""

    def obj_of(d):
        m = re.search(r"'([^']*)'", d.message)
        name = m.group(1) if m else ""
        return name.split(" ", 1)[-1] if name.split(" ", 1)[0].isupper() else name

    said = {(d.rule, obj_of(d)) for d in theirs}
    return [d for d in ours if (d.rule, obj_of(d)) not in said] + list(theirs)


def check_scene(scene) -> list[Diagnostic]:
    """What export would say, without writing anything (the Check operator)."""
    g = gather_model(scene)
    if any(d.severity >= Severity.ERROR for d in g.diagnostics):
        return g.diagnostics
    found = validate(dumps(g.model), Path("model.yaml"), {Path(j.directory) / j.filename for j in g.jobs})
    source = json.loads(scene.adf.snapshot).get("source_dir") if scene.adf.snapshot else None
    return merge_findings(list(g.diagnostics), volumes.read_where_they_are(found, g.model, source))


def export_scene(
    scene, out_dir: str | Path, name: str = "model", objects=None, mesh_format: str | None = None
) -> ExportResult:
    """Gather, validate, then write the meshes and last the model file. ``mesh_format`` ('OBJ',
    'STL', 'PLY', '3DS'; default: the scene's export option) is the format of the meshes
    written; meshes imported and left unchanged are copied in their own format."""
    out_dir = Path(out_dir)
    target = out_dir / f"{name}.yaml"
    g = gather_model(scene, objects, mesh_format, out_dir)
    result = ExportResult(None, list(g.diagnostics))
    sp = scene.adf  # the meshes the switches skip are named, not written: AMBF reads the ones there
    jobs = [j for j in g.jobs if (sp.save_low_res if j.low else sp.save_high_res)]
    if any(d.severity >= Severity.ERROR for d in result.diagnostics):
        return result
    source = json.loads(scene.adf.snapshot).get("source_dir") if scene.adf.snapshot else None
    copies = rebase_paths(g.model, Path(source), out_dir) if source else []
    copies += rebase_authored(g.model, objects if objects is not None else scene.objects, out_dir)
    text = dumps(g.model)
    pending = {out_dir / j.directory / j.filename for j in jobs}
    # the folder exists while the text is validated (paths through it, such as ../x, resolve);
    # a folder made for a refused export is taken away again
    made = next((p for p in reversed([out_dir, *out_dir.parents]) if not p.exists()), None)
    out_dir.mkdir(parents=True, exist_ok=True)
    copied = []
    for src, dst in copies:  # shader and slice files the new file names (rebase_paths)
        if not dst.exists():
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dst)
            copied.append(dst)
    result.diagnostics = merge_findings(result.diagnostics, validate(text, target, pending))
    if any(d.severity >= Severity.ERROR for d in result.diagnostics):
        for f in copied:
            f.unlink(missing_ok=True)
        if made is not None:
            shutil.rmtree(made, ignore_errors=True)
        return result
    result.written.extend(copied)
    _run_jobs(jobs, out_dir, result, textures=sp.save_textures)
    atomic_write_text(target, text)
    result.path = target
    result.written.append(target)
    return result


def rebase_paths(model: ModelFile, source_dir: Path, out_dir: Path) -> list[tuple[Path, Path]]:
    """Paths to folders of files the add-on does not edit (shaders, volume slices), written
    relative to the imported file, made to resolve from the exported one: relative to the new
    file when the folder stays inside its scene tree (adfkit.inputs), else the files are copied
    into the output folder under the same folder name. Absolute paths stay as they are.
    Returns the (source, destination) copies to make."""
    from adfkit import inputs

    tree = inputs.tree_of(out_dir / "model.yaml")
    copies: list[tuple[Path, Path]] = []

    def rebase(text: str | None, names: list[str]) -> str | None:
        if not text or os.path.isabs(text):
            return text
        folder = (source_dir / text).resolve()
        if tree.contains(folder / (names[0] if names else ".")):
            new = os.path.relpath(folder, out_dir.resolve())
            return new + ("/" if text.endswith("/") and not new.endswith("/") else "")
        local = Path(*[p for p in Path(text).parts if p not in ("..", ".")]) if Path(text).parts else Path(".")
        copies.extend((folder / n, out_dir / local / n) for n in names if (folder / n).is_file())
        return local.as_posix() + ("/" if text.endswith("/") else "")

    def shader_files(sh) -> list[str]:
        return [n for n in (sh.vertex, sh.fragment) if n]

    for obj in model.all_objects():
        for attr in ("shaders", "preprocessing_shaders", "depth_compute_shaders"):
            sh = getattr(obj, attr, None)
            if sh is not None:
                sh.path = rebase(sh.path, shader_files(sh))
        im = getattr(obj, "images", None)
        if im is not None and im.count and im.prefix is not None and im.format:
            base = source_dir / im.path if im.path else source_dir
            found = find_slice_files(base, str(im.prefix), str(im.format), min(int(im.count), 4096)).files
            names = [os.path.relpath(f, base) for f in found]  # the slices AMBF reads: count is the most
            im.path = rebase(im.path, [*names, "labels.yaml"])  # the tissues `adfkit drill` reads, when there
    if getattr(model, "shaders", None) is not None:
        model.shaders.path = rebase(model.shaders.path, shader_files(model.shaders))
    return copies


def rebase_authored(model: ModelFile, objs, out_dir: Path) -> list[tuple[Path, Path]]:
    """The slice folders of the volumes authored in Blender (absolute, addon/volumes.py) written
    as :func:`rebase_paths` writes an imported volume's: relative to the new file when inside
    its tree, else the slices copied beside it. Returns the copies to make."""
    ids = {o[volumes.VOLUME_KEY] for o in objs if volumes.AUTHORED_KEY in o}
    copies: list[tuple[Path, Path]] = []
    for vol in model.volumes:
        im = vol.images
        if vol.identifier in ids and im is not None and im.path and os.path.isabs(im.path):
            folder = Path(im.path)
            im.path = folder.name + "/"
            copies += rebase_paths(ModelFile(volumes=[vol]), folder.parent, out_dir)
    return copies


def _run_jobs(jobs, out_dir: Path, result: ExportResult, textures: bool = True) -> None:
    """Write the meshes (with their textures unless ``textures`` is off), each file only if its
    bytes change, and record every mesh file's content hash (sha-256 of its bytes) in HASH_FILE."""
    hashes_path = out_dir / HASH_FILE
    try:
        known = json.loads(hashes_path.read_text()) if hashes_path.is_file() else {}
    except (OSError, ValueError):
        known = {}
    if not isinstance(known, dict):
        known = {}
    now: dict[str, str] = {}
    for job in jobs:
        dst = out_dir / job.directory / job.filename
        if job.source is not None and job.parts is None:
            files = meshes.source_files(job.source, job.filename)
        else:
            files = meshes.mesh_files(job.parts, job.filename, split=not job.whole)
        if not textures:
            files = _without_textures(files, dst, result)
        done = meshes.write_files(dst.parent, files)
        for path, (digest, written) in done.items():
            now[os.path.relpath(path, out_dir).replace(os.sep, "/")] = digest
            if written:
                result.written.append(path)
        if not done[dst][1]:
            result.skipped.append(dst)
    # entries of files this export did not touch stay while they still describe the file
    for rel, digest in known.items():
        f = out_dir / rel
        if rel not in now and isinstance(digest, str) and f.is_file():
            if meshes.content_hash(f.read_bytes()) == digest:
                now[rel] = digest
    if jobs:
        atomic_write_text(hashes_path, json.dumps(now, indent=1, sort_keys=True))


def _without_textures(files: dict, dst: Path, result: ExportResult) -> dict:
    """The files of a mesh but its images ('Textures' off): an image the MTL names that is not
    in the folder already is a warning, since AMBF will not find it."""
    keep = {}
    for name, content in files.items():
        if name == dst.name or Path(name).suffix.lower() in (".mtl", *meshes.MESH_SUFFIXES_LOWER):
            keep[name] = content
        elif not (dst.parent / name).is_file():
            result.diagnostics.append(
                warning(
                    "texture-not-saved",
                    f"texture {name} of {dst.name} is not written ('Textures' is off) and is not in {dst.parent}",
                    None,
                    "tick 'Textures' in the Export options, or put the image there",
                )
            )
    return keep
