"""The scene resolved once, the same way for every engine: the ADF rules that decide what is
built (which world gravity, which body a ghost, sensor, actuator or camera hangs on, which
sensors and actuators are played, which ghosts are holes with viscous friction, what an engine
does not play and why). The back ends (pybullet/, mujoco/) only translate what this module
decides into their engine; the geometry and joint rules live in ``model.semantics`` and
``springs.py``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnostics import warning
from ..model.semantics import (
    ACTUATOR_TYPES,
    DEFAULT_GRAVITY,
    DEFAULT_SENSOR_RANGE,
    SENSOR_TYPES,
    JointKind,
    collision_primitives,
    holds_no_joint,
    joint_kind,
    pose_or_identity,
)
from .names import merge_namespace
from .rotations import pose_to_matrix

#: joints of the six-dof family: springs and limits per axis (springs.py)
SPRING_KINDS = (
    JointKind.SIX_DOF,
    JointKind.SIX_DOF_SPRING,
    JointKind.CONE_TWIST,
    JointKind.LINEAR_SPRING,
    JointKind.TORSION_SPRING,
)

#: every collision-group bit: what a body without collision groups (and the runner's floor,
#: which stands in for a world's) collides as, in both engines
ALL_GROUPS = (1 << 31) - 1

#: sections of a model each engine does not play (each is warned about and listed in the report)
NOT_PLAYED: dict[str, tuple] = {"pybullet": (), "mujoco": ()}


def world_gravity(scene, opt) -> np.ndarray:
    """The options' gravity, else the world file's, else AMBF's default."""
    w = scene.world
    g = opt.gravity or (tuple(w.gravity) if w is not None and w.gravity is not None else DEFAULT_GRAVITY)
    return np.array(g, dtype=float)


def not_played(world, models, engine: str) -> None:
    """Warn about and list (``world.not_played``) every object of a section ``engine`` skips."""
    other = "pybullet" if engine == "mujoco" else None
    for m in models:
        for kind, attr in NOT_PLAYED[engine]:
            for o in getattr(m, attr):
                why = f"{kind}s are not played by the {'MuJoCo engine' if engine == 'mujoco' else 'PyBullet runner'}"
                world._warn(
                    f"runner-{kind.replace(' ', '-')}",
                    f"{o.identifier}: {why}; skipped",
                    o,
                    f"play it with --engine {other}" if other else "play this object in AMBF itself",
                )
                world.not_played.append({"object": o.identifier, "what": kind, "why": why})


def mesh_refusal(model, path) -> str | None:
    """Why the input policy (adfkit.inputs) keeps an engine from reading this mesh, or None:
    missing, not a regular file, over the size cap, outside the model's tree."""
    from .. import inputs
    from ..diagnostics import AdfError

    try:
        inputs.check_file(path, "mesh", tree=getattr(model, "tree", None), what="mesh file")
    except AdfError as exc:
        d = exc.diagnostics[0]
        return f"{inputs.shown(path)} not found" if d.rule == "file-not-found" else d.message
    return None


def uncreated(model, obj):
    """The located warning (a Diagnostic) when AMBF does not create ``obj`` (a body or ghost),
    else None: its visual `mesh` (without a visual primitive) cannot be loaded, or its collision
    comes from a mesh file (no primitive collision shape) that is missing, refused by the input
    policy or has no triangles."""
    from .. import inputs
    from ..adf.paths import collision_mesh_path
    from ..geometry.meshcheck import mesh_problem

    if (why := _visual_refused(model, obj)) is not None:
        return why
    path = collision_mesh_path(model, obj) if collision_primitives(obj) is None else None
    if path is None:
        return None
    if (refused := mesh_refusal(model, path)) is not None:
        return mesh_skipped(obj, refused)
    if (problem := mesh_problem(path)) is not None:
        # no triangles at all (the validator's mesh-unreadable): PyBullet crashes on some. An
        # OBJ face naming no vertex: AMBF 2.0 makes the body of what it reads (measured: it
        # collides with nothing and falls freely); the engines here could not read it at all
        as_ambf = (
            "as AMBF does"
            if path.suffix.lower() != ".obj" or "no faces" in problem or "no vertices" in problem
            else ("(AMBF 2.0 makes it of what it reads of the mesh, which collides with nothing)")
        )
        return warning(
            "runner-bad-mesh",
            f"{obj.identifier}: collision mesh {inputs.shown(path.name)}: {problem}; the body is skipped {as_ambf}",
            mesh_key(obj),
            "re-export the mesh as a triangle mesh (STL or OBJ)",
        )
    return None


def _visual_refused(model, obj):
    """AMBF makes an object's visual first and leaves the object out when its visual `mesh` (no
    `shape` or `compound shape`) does not load, whatever its collision shape is. Measured in
    AMBF 2.0: a missing file, an STL without triangles or that is no STL is left out; an OBJ
    without faces, even an empty one, loads (chai3d's OBJ reader takes it)."""
    from .. import inputs
    from ..adf.paths import visual_mesh_path
    from ..geometry.meshcheck import mesh_problem

    if getattr(obj, "shape", None) or getattr(obj, "compound_shape", None):
        return None
    path = visual_mesh_path(model, obj)
    if path is None:
        return None
    where = obj.where("mesh") or obj.source
    if (refused := mesh_refusal(model, path)) is not None:
        rule, why = "runner-missing-mesh", refused
    elif path.suffix.lower() != ".obj" and (problem := mesh_problem(path)) is not None:
        rule, why = "runner-bad-mesh", f"{inputs.shown(path.name)}: {problem}"
    else:
        return None
    return warning(
        rule,
        f"{obj.identifier}: visual mesh {why}; the body is skipped as AMBF does (it makes the visual first)",
        where,
        "fix `mesh` or the high resolution path" if rule == "runner-missing-mesh" else "re-export the mesh",
    )


def mesh_skipped(obj, refused: str):
    """The located ``runner-missing-mesh`` warning for a body skipped because its collision mesh
    cannot be read (``refused``: why, as mesh_refusal or an engine's own reader says it)."""

    return warning(
        "runner-missing-mesh",
        f"{obj.identifier}: collision mesh {refused}; the body is skipped as AMBF does",
        mesh_key(obj),
        "fix `collision mesh`/`mesh` or the resolution paths",
    )


def mesh_key(obj):
    """Where a body's collision mesh is named: `collision mesh`, else `mesh`."""
    return obj.where("collision mesh" if obj.collision_mesh is not None else "mesh") or obj.source


def uncreated_bodies(world, model) -> frozenset[str]:
    """The bodies of ``model`` AMBF does not create (``uncreated``), each warned about and listed
    in ``world.skipped``, the joints that name them warned about too: an engine that writes the
    whole model at once (the MuJoCo engine) leaves these out first; the PyBullet runner asks
    ``uncreated`` as it builds each body's shapes (pybullet/shapes.py)."""
    from ..model.tree import joint_ends

    out = set()
    for b in model.bodies:
        if (why := uncreated(model, b)) is not None:
            world.diagnostics.append(why)
            out.add(b.identifier)
    ns = model.namespace or ""
    world.skipped += [merge_namespace(ns, b.namespace) + b.identifier for b in model.bodies if b.identifier in out]
    for j in model.joints:
        if joint_ends(model, j) & out:
            world._warn("runner-joint-body", f"{j.identifier}: parent or child body not found; skipped", j)
    return frozenset(out)


def holds_nothing(body, joint) -> bool:
    """``joint`` (a hinge, slider, fixed or p2p joint) hangs from ``body``, a static body (mass 0)
    with no collision shape of any kind and no `inertia`: AMBF prints "COLLISION TYPE NOT
    UNDERSTOOD" and the joint holds nothing. Measured in AMBF 2.0: a 0.5 kg bar hinged to such a
    post falls freely, unturned (19.09 m in 2 s; both engines held it swinging, 19.06 m apart),
    as on a fixed or p2p joint (4.84 m in 1 s); given `inertia` (or a `collision shape`) the
    post holds it, as adfkit does; `mesh: ''` is no collision shape. A dynamic body without a
    collision shape keeps its joints (a link hinged between two others within 0.2 mm). AMBF
    still turns such a child by the joint's controller, which adfkit leaves out, and a spring
    there still pulls its child to its equilibrium (its limits and locked axes gone), so springs
    are made as before (docs/parity.md)."""
    if joint_kind(joint.type) not in (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.FIXED, JointKind.P2P):
        return False
    return holds_no_joint(body)


def warn_unheld(world, joint, parent_key: str) -> None:
    """Says, on ``world``, that ``joint`` is not made: its parent ``holds_nothing``."""
    world._warn(
        "runner-joint-static",
        f"{joint.identifier}: its parent {parent_key} is static with no collision shape and no inertia; AMBF keeps "
        "the joint and it holds nothing (the child moves free); nothing made",
        joint,
        "give the parent a `collision shape` or an `inertia` (it stays static) for the joint to hold, as in AMBF",
    )


def unheld_joints(model, world) -> frozenset[str]:
    """Identifiers of ``model``'s joints whose parent (in the model) ``holds_nothing``, each warned
    about in ``world``: AMBF keeps them, and they move nothing (World.inert_joints); an engine
    that writes the whole model at once (the MuJoCo engine) leaves them out."""
    from ..model.tree import find_body

    out = set()
    for j in model.joints:
        p = find_body(model, j.parent, j)
        if p is not None and holds_nothing(p, j) and p is not find_body(model, j.child, j):
            warn_unheld(world, j, p.identifier)
            out.add(j.identifier)
    return frozenset(out)


def resolve_parent(world, ref: str | None, ns: str, obj, body_type=None, known=None):
    """The body ``ref`` names for ``obj`` (a ghost, sensor, actuator), found as written or in the
    model's namespace among ``known`` (a Registry; default: every body of the world); None with a
    located ``runner-parent`` warning when no unique body matches."""
    reg = known if known is not None else world.registry
    key, hit = reg.find(ref)
    if key is None and ref:
        key, hit = reg.find(ns + ref)
    if key is None or (body_type is not None and not isinstance(hit, body_type)):
        world._warn(
            "runner-parent",
            f"{obj.identifier}: parent {ref!r} not found" + (f" (matches: {', '.join(hit)})" if hit else ""),
            obj,
        )
        return None
    return hit


def is_hole(ghost, opt) -> bool:
    """A ghost whose name says it is an entry or exit hole applies viscous friction."""
    name = (ghost.name or ghost.identifier).lower()
    return any(w in name for w in opt.hole_ghost_words)


def joint_ends(registry, local, ns: str, joint) -> list:
    """A joint's [parent, child] bodies (None where not found) by AMBF's lookup (adf-format.md
    §12.2): the joint's own model (``local``), exact then substring, then that model with the
    joint's namespace prepended, then the world (``registry``) with it, then the world."""
    jns = merge_namespace(ns, joint.namespace)
    ends = []
    for ref in (joint.parent, joint.child):
        key, hit = local.find(ref)
        if key is None:
            key, hit = local.find(jns + (ref or ""))
        if key is None:
            key, hit = registry.find(jns + (ref or ""))
        if key is None:
            key, hit = registry.find(ref)
        ends.append(hit if key is not None else None)
    return ends


def key_of(ns: str, obj) -> str:
    return merge_namespace(ns, obj.namespace) + obj.identifier


@dataclass
class SensorRays:
    key: str
    sensor: object
    parent: object  # the engine's body
    location: np.ndarray  # 4x4 in the parent's ADF body frame
    starts: np.ndarray  # (n, 3) ray starts in the sensor frame
    ends: np.ndarray

    @property
    def resistance(self) -> bool:
        return SENSOR_TYPES.get(self.sensor.type) == "resistance"


@dataclass
class Grasper:
    key: str
    actuator: object
    parent: object
    location: np.ndarray  # 4x4 in the parent's ADF body frame


def played_sensors(world, m, body_type=None, known=None, resistance: bool = False) -> list[SensorRays]:
    """The model's proximity and resistance sensors with rays, parents resolved among ``known``,
    the bodies of the models loaded so far (``loaded_so_far``); the others warned about (a
    resistance sensor's forces: resistance.py), resistance sensors only where ``resistance``
    (under AMBF's bodies)."""
    ns = m.namespace or ""
    out = []
    for s in m.sensors:
        rays = None
        if SENSOR_TYPES.get(s.type) == "proximity" or (resistance and SENSOR_TYPES.get(s.type) == "resistance"):
            rays = array_rays(s) if s.array else parametric_rays(s) if s.parametric else None
        if rays is None:
            world._warn(
                "runner-sensor",
                f"{s.identifier}: only proximity sensors (and, under AMBF's bodies, resistance sensors) "
                "with an `array` or a `parametric` fan of rays are played; skipped",
                s,
            )
            continue
        parent = resolve_parent(world, s.parent, ns, s, body_type, known)
        if parent is None:
            continue
        loc = pose_to_matrix(pose_or_identity(s.location))
        out.append(SensorRays(key_of(ns, s), s, parent, loc, *rays))
    return out


def array_rays(s) -> tuple[np.ndarray, np.ndarray]:
    """Starts and ends, in the sensor frame, of an `array` of rays (§11.1)."""
    rng = s.range if s.range is not None else DEFAULT_SENSOR_RANGE
    starts = np.array([r.offset or (0, 0, 0) for r in s.array], dtype=float)
    dirs = np.array([r.direction or (1, 0, 0) for r in s.array], dtype=float)
    return starts, starts + dirs * rng


def parametric_rays(s) -> tuple[np.ndarray, np.ndarray] | None:
    """Starts and ends of a `parametric` fan as AMBF's loader makes them
    (ADFLoader_1_0::loadRayTracerSensorAttribs): resolution² rays around +X, ray (i, j) turned by
    Rz(h_i)·Ry(v_j), h and v spanning the horizontal and vertical angles, starting `start offset`
    along it; AMBF puts them through the sensor's `location` already and places the sensor at its
    location again, so the rays are returned in the location's frame (the location twice, as
    AMBF has it). None where AMBF refuses the fan (a key missing, resolution below 2)."""
    p = s.parametric
    keys = (p.resolution, p.horizontal_angle, p.vertical_angle, p.start_offset)
    if any(k is None for k in keys) or p.resolution < 2:
        return None
    n, hs, vs, off = int(p.resolution), float(p.horizontal_angle), float(p.vertical_angle), float(p.start_offset)
    rng = s.range if s.range is not None else DEFAULT_SENSOR_RANGE
    loc = pose_to_matrix(pose_or_identity(s.location))
    h = -hs / 2 + np.arange(n) * hs / (n - 1)
    v = -vs / 2 + np.arange(n) * vs / (n - 1)
    hh, vv = np.meshgrid(h, v, indexing="ij")  # ray index n·i + j: h_i, v_j
    turned = np.stack([np.cos(hh) * np.cos(vv), np.sin(hh) * np.cos(vv), -np.sin(vv)], axis=-1).reshape(-1, 3)
    starts = turned * off @ loc[:3, :3].T + loc[:3, 3]
    dirs = turned @ loc[:3, :3].T
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return starts, starts + dirs * rng


def played_actuators(world, m, body_type=None, known=None) -> list[Grasper]:
    """The model's constraint actuators, parents resolved among ``known`` (as sensors); other
    types warned about."""
    ns = m.namespace or ""
    out = []
    for a in m.actuators:
        if ACTUATOR_TYPES.get(a.type) != "constraint":
            world._warn("runner-actuator", f"{a.identifier}: actuator type {a.type!r} not supported; skipped", a)
            continue
        parent = resolve_parent(world, a.parent, ns, a, body_type, known)
        if parent is None:
            continue
        # no `max impulse` nor `tau`: AMBF 2.0 reads them and does not use them (its grasp is a
        # btFixedConstraint without a limit; measured, runner/pybullet/interact.py GRASP_MAX_FORCE)
        out.append(Grasper(key_of(ns, a), a, parent, pose_to_matrix(pose_or_identity(a.location))))
    return out


def loaded_so_far(known, bodies) -> object:
    """``known`` (a Registry, created when None) with ``bodies`` (engine bodies with a ``key``)
    added: AMBF makes a model's sensors and actuators only on a parent already loaded, its own or
    an earlier model's (measured: a later model's body is not found; a ghost's parent is, the
    runner finds it among every body)."""
    from .names import Registry

    known = known if known is not None else Registry()
    for b in bodies:
        known.items[b.key] = b
    return known


def rgba(obj) -> list[float] | None:
    """Colour of §7.3: `color rgba`, then `color components` (diffuse + transparency), else None."""
    if obj.use_material is False:
        return None
    c = obj.color_rgba
    if c is not None and None not in (c.r, c.g, c.b, c.a):
        return [c.r, c.g, c.b, c.a]
    cc = obj.color_components
    if cc is not None:
        d = cc.diffuse
        col = [d.r or 0.0, d.g or 0.0, d.b or 0.0] if d is not None else [0.7, 0.7, 0.7]
        return col + [cc.transparency if cc.transparency is not None else 1.0]
    return None
