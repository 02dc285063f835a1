"""Loader parity: what AMBF makes of a file against what adfkit makes of it. For a file AMBF
loads: the bodies, soft bodies, ghosts, joints, sensors and actuators each side created, each
joint's type, bodies, motor, limits and controller, each body's mass and where it starts. For a
file AMBF refuses: whether `adfkit validate` refuses it too (an error)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..diagnostics import AdfError, Severity
from . import ambf
from .compare import _only, angle_deg, match
from .traces import ambf_name, made_by, made_by_ambf, rigid_bodies

#: what AMBF prints when its loader refuses a file
REFUSED = ("Failed to Load", "COULDN'T DETERMINE THE CORRECT ADF LOADER")


@dataclass
class LoaderResult:
    path: Path
    kind: str  # launch, world, model, input_devices, colors (adfkit's reading of it)
    ambf: str  # "loads", "refuses", "not loaded" (a file no launch loads by itself)
    validate_errors: list[str]  # the error rules `adfkit validate` gives
    ambf_note: str = ""
    ambf_counts: dict[str, int] = field(default_factory=dict)
    adfkit_counts: dict[str, int] = field(default_factory=dict)
    only_in_ambf: list[dict] = field(default_factory=list)
    only_in_adfkit: list[dict] = field(default_factory=list)
    differences: list[str] = field(default_factory=list)  # joints' facts, bodies' masses
    # where the links of multibodies start, apart: on their joints in adfkit, where the file puts
    # them in AMBF (docs/parity.md), so a figure, not a disagreement (free bodies must agree)
    start_gap_m: float = 0.0
    start_gap_deg: float = 0.0
    # a launch file's models AMBF refuses, with the error rules `adfkit validate` gives each
    refused_models: dict[str, list[str]] = field(default_factory=dict)

    @property
    def agree(self) -> bool:
        if self.ambf == "not loaded":
            return True
        if self.ambf == "refuses":
            return bool(self.validate_errors)
        return not (self.validate_errors or self.only_in_ambf or self.only_in_adfkit or self.differences)

    def as_json(self) -> dict:
        return {
            "path": str(self.path),
            "kind": self.kind,
            "ambf": self.ambf,
            "ambf_note": self.ambf_note,
            "validate_errors": self.validate_errors,
            "ambf_counts": self.ambf_counts,
            "adfkit_counts": self.adfkit_counts,
            "only_in_ambf": self.only_in_ambf,
            "only_in_adfkit": self.only_in_adfkit,
            "differences": self.differences,
            "start_gap_m": self.start_gap_m,
            "start_gap_deg": self.start_gap_deg,
            "refused_models": self.refused_models,
            "agree": self.agree,
        }


def _counts(made: dict[str, list[str]]) -> dict[str, int]:
    return {k: len(v) for k, v in made.items()}


def _stage(path: Path, doc):
    from ..model import Launch, ModelFile, World

    if isinstance(doc, Launch):
        return ambf.Stage(path, list(range(len(doc.multibody_configs or []))))
    if isinstance(doc, World):
        return ambf.write_stage(path, [], None)
    if isinstance(doc, ModelFile):
        return ambf.write_stage(None, [path], None)
    return None


def _joint_facts(world, joint, parent, child) -> dict:
    from ..model.semantics import DEFAULT_JOINT_MAX_MOTOR_IMPULSE, JointKind, joint_kind
    from ..runner.joint_commands import controller_of, limits_of, motor_enabled
    from .traces import joint_key

    kind = joint_kind(joint.type)
    (p, i, d), out = controller_of(joint)
    one_axis = kind not in (JointKind.CONE_TWIST, JointKind.SIX_DOF, JointKind.SIX_DOF_SPRING)
    return {
        "qname": ambf_name(joint_key(world, joint), joint),
        "type": kind.value if kind is not None else "invalid",
        "parent": ambf_name(parent.key, parent.body),
        "child": ambf_name(child.key, child.body),
        "motor": motor_enabled(joint),
        "limits": list(limits_of(joint)) if one_axis and limits_of(joint) else None,
        "max_motor_impulse": joint.max_motor_impulse
        if joint.max_motor_impulse is not None
        else DEFAULT_JOINT_MAX_MOTOR_IMPULSE,
        "controller": {"P": p, "I": i, "D": d, "output": out},
    }


def _differences(world, created: dict) -> list[str]:
    """Each joint's facts and each body's mass, where both sides made it, when they differ."""
    out = []
    theirs: dict[str, list[dict]] = {}
    for j in created["joints"]:  # several of one name: in the order each side made them
        theirs.setdefault(j["qname"], []).append(j)
    for j, parent, child in world.joints_made:
        mine = _joint_facts(world, j, parent, child)
        if not theirs.get(mine["qname"]):
            continue
        other = theirs[mine["qname"]].pop(0)
        for key in ("type", "parent", "child", "motor", "limits", "max_motor_impulse", "controller"):
            a, b = other.get(key), mine[key]
            same = (np.allclose(a, b) if key == "limits" and a is not None and b is not None else a == b) or (
                key == "controller" and a is not None and _same_controller(a, b)
            )
            if not same:
                out.append(f"joint {mine['qname']}: {key} AMBF {a!r}, adfkit {b!r}")
    masses = {b["qname"]: b["mass"] for b in created["bodies"]}
    inertias: dict[str, list] = {}  # several bodies of one name: in the order each side made them
    for b in created["bodies"]:
        inertias.setdefault(b["qname"], []).append(b.get("inertia"))
    for sb in rigid_bodies(world):
        n = ambf_name(sb.key, sb.body)
        if n in masses and not np.isclose(masses[n], sb.mass):
            out.append(f"body {n}: mass AMBF {masses[n]!r}, adfkit {sb.mass!r}")
        theirs = inertias[n].pop(0) if inertias.get(n) else None
        # a body without `mass`: AMBF reads no `inertia` and estimates it from a shape that may be
        # empty, into memory it never set (the LND PSMs' tool_id: 0, 3.3e180, 0)
        if theirs is None or sb.static or sb.mass <= 0 or sb.body.mass is None:
            continue
        if not _same_inertia(theirs, sb.inertia):
            out.append(f"body {n}: inertia AMBF {tuple(theirs)!r}, adfkit {tuple(sb.inertia)!r}")
    return out


def _same_inertia(a, b) -> bool:
    """AMBF's and adfkit's principal moments within 1 % (the corpus PSM's and MTM's mesh links
    estimated from their meshes' bounds come within 0.5 %; a moment of 0, which AMBF's Bullet
    never turns about, is adfkit's FROZEN_INERTIA)."""
    from ..runner.ambf_bodies import FROZEN_INERTIA

    a = np.asarray(a, float)
    b = np.where(np.asarray(b, float) >= FROZEN_INERTIA, 0.0, np.asarray(b, float))
    return bool(np.allclose(a, b, rtol=1e-2, atol=1e-12))


def _same_controller(a: dict, b: dict) -> bool:
    return a["output"] == b["output"] and all(np.isclose(a[k], b[k]) for k in "PID")


def check_file(path: Path, build: ambf.AmbfBuild) -> LoaderResult:
    """One file through AMBF's loader and through adfkit's (its validator and its runner)."""
    from ..adf import load_scene
    from ..model import Launch, ModelFile, World
    from ..runner import Options, open_world
    from ..validator.engine import validate_file

    path = Path(path).resolve()
    res = validate_file(path)
    errors = sorted({d.rule for d in res.diagnostics if d.severity >= Severity.ERROR})
    kind = res.kind or "unknown"
    doc = res.doc
    if doc is None and not errors:
        errors = ["unreadable"]
    if doc is not None and not isinstance(doc, (Launch, World, ModelFile)):
        return LoaderResult(path, kind, "not loaded", errors, "AMBF's launcher loads it only with input devices")
    if doc is None:
        # adfkit cannot read it: stage it as a model, as a launch file would name it
        stage = ambf.write_stage(None, [path], None)
    else:
        stage = _stage(path, doc)
    try:
        rec = ambf.run(build, stage, 0.0, 0.0)
    except AdfError as exc:
        note = _refusal(exc.args[0] if exc.args else "")
        return LoaderResult(path, kind, "refuses", errors, note or "ambf_simulator stopped before the scene loaded")
    note = _refusal(rec.log)
    if note and isinstance(doc, (ModelFile, type(None))):
        return LoaderResult(path, kind, "refuses", errors, note)
    out = LoaderResult(path, kind, "loads", errors, note)
    ambf_made = made_by_ambf(rec.created)
    out.ambf_counts = _counts(ambf_made)
    indices = None
    if isinstance(doc, Launch):
        indices = _models_ambf_loads(doc, rec.log, out)
    try:
        scene = load_scene(path, indices)
        world = open_world(scene, Options(visuals=False, ground=False, bodies="ambf"))
    except AdfError as exc:
        out.differences.append(f"adfkit's runner refuses it: {exc.diagnostics[0].message}")
        return out
    try:
        mine = made_by(world)
        out.adfkit_counts = _counts(mine)
        out.only_in_ambf = _only(ambf_made, mine)
        out.only_in_adfkit = _only(mine, ambf_made)
        out.differences = _differences(world, rec.created)
        free_m, free_deg, out.start_gap_m, out.start_gap_deg = _start_gap(world, mine, rec)
        if free_m > 1e-6 or free_deg > 1e-3:
            out.differences.append(f"free bodies start {free_m * 1e3:.4f} mm, {free_deg:.4f}° apart")
    finally:
        world.close()
    return out


def _models_ambf_loads(launch, log: str, out: LoaderResult) -> list[int]:
    """The indices of the launch file's models AMBF did not refuse. AMBF leaves out a model it
    refuses and loads the others; `adfkit run` plays such a model all the same (with validate's
    errors printed): the comparison leaves it out when `adfkit validate` finds the errors that
    make AMBF refuse it, and counts it as a difference when validate finds none."""
    from ..adf.paths import relative_to_file
    from ..validator.engine import validate_file

    refused = {
        Path(line.split("Failed to Load ", 1)[1].strip()) for line in log.splitlines() if "Failed to Load " in line
    }
    keep = []
    for i, cfg in enumerate(launch.multibody_configs or []):
        p = relative_to_file(launch.path, cfg)
        if not any(p == r or p.resolve() == r.resolve() for r in refused):
            keep.append(i)
            continue
        if not p.exists():
            continue  # a missing model: the runner leaves it out too (missing-model-file)
        rules = sorted({d.rule for d in validate_file(p).diagnostics if d.severity >= Severity.ERROR})
        if rules:
            out.refused_models[str(p)] = rules
        else:
            out.differences.append(f"AMBF refuses model {p}, adfkit validate finds no error in it")
    return keep


def _start_gap(world, mine: dict, rec: ambf.AmbfRecord) -> tuple[float, float, float, float]:
    """How far apart the two sides start their bodies: (position, angle) over the bodies that
    start where the file puts them on both sides (free bodies, multibody bases), then over the
    links of multibodies (which start on their joints in adfkit)."""
    from ..runner.rotations import matrix_to_pq

    if not rec.samples or not mine["body"]:
        return 0.0, 0.0, 0.0, 0.0
    bodies = rigid_bodies(world)
    theirs = np.array(rec.samples[0]["bodies"], dtype=float).reshape(-1, 7)
    ours = np.array([[*p, *q] for p, q in (matrix_to_pq(sb.world_matrix()) for sb in bodies)])
    names = made_by_ambf(rec.created)["body"]
    out = [0.0, 0.0, 0.0, 0.0]
    for i, j in match(names, mine["body"], theirs[:, :3], ours[:, :3]):
        k = 2 if getattr(bodies[j], "link", -1) >= 0 else 0
        out[k] = max(out[k], float(np.linalg.norm(theirs[i, :3] - ours[j, :3])))
        out[k + 1] = max(out[k + 1], float(angle_deg(theirs[i, 3:], ours[j, 3:])))
    return out[0], out[1], out[2], out[3]


def _refusal(log: str) -> str:
    for line in log.splitlines():
        if any(r in line for r in REFUSED):
            return line.strip()
    return ""
