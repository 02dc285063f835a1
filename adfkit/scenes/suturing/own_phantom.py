"""A modeller's phantom in the bundled suturing scene (``adfkit suture --phantom MODEL.yaml``).

The phantom file, as the Blender add-on exports it, holds the tissue bodies and, for each hole
pair k, the hole ghosts Entry k and Exit k (any ghost whose name ends in "entry k" or "exit k",
the add-on's ``ghostEntry1``), each on its hole body (the add-on's hole helpers frame the hole
with four capsules; a hole without them is where its ghost is). It takes the place of the
bundled phantom (its tissue bodies, hole bodies and hole ghosts); the needle, the thread, the
stereo camera's frame and both PSMs stay, and are placed for the phantom's holes:

- **The placement** is the rigid motion, about the vertical, that takes the bundled holes'
  centre to the phantom's holes' centre (all its pairs) and the bundled pairs' direction from
  entry to exit (world x) to the phantom's mean one. The PSMs' bases and the camera's frame go
  with it, so that they stand to the phantom's holes as they stand to the bundled ones; the
  needle and the thread too, moved along the line of holes to lie as far beyond its end as in
  the bundled scene (24 mm past the pair at the end of the line).
- **The order of the pairs**: the suture starts at the pair next to the needle and goes along
  the line, as in the bundled scene, whichever way the phantom numbers its pairs (``pairs``,
  in that order): a phantom numbered from the other end is sutured from its last pair to its
  first, each pair still from its Entry k to its Exit k.
- **The needle's bed.** The needle lies, as in the bundled scene, across a slot (the jaws close
  around the wire in it) of a static tray, ``SutureTray``, the thread on a strip of it; the
  tray's top is where the bundled slab's is, 6 mm below the holes' centre, raised (with the
  needle and the thread) where the phantom's tissue would fill the slot or stand above the wire
  (a slab there: by the tray's depth, 4 mm). Laid flat on a slab instead, the planner found no
  pick-up that kept the jaws off it and took a grasp that drove the wrist into the phantom at
  the first insertion (2.9 kN); lifted without the strip, the falling thread drew the needle
  1.3 mm aside as the scene settled, and the plan made there failed the same way. The tray is
  tissue to the suture like any other body. Beside holes on a slope the bed may be turned a
  quarter turn instead, its thread running out from the line of holes (needle_bed).

Pure model work (numpy and the ADF model): the scene comes back as a Scene for the runner.
"""

from __future__ import annotations

import copy
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...model import Body, Friction, Geometry, ModelFile, Pose, Scene, ShapeEntry, Vec3
from ...model.semantics import collision_primitives
from ...runner.rotations import pose_to_matrix
from ...tasks.holes import HOLE_NAME, hole_name
from . import layout as L
from .frames import pose, rot_z, translation
from .needle_bed import TURN, sloped_bed

#: the bundled phantom's bodies the modeller's phantom replaces (the needle's file keeps the rest)
BUNDLED_TISSUE = re.compile(r"^(Phantom|Entry\d+|Exit\d+)$")
#: m from entry to exit beyond which a pair is not a suture's bite but a file in other units
#: (this needle bites at most 14.5 mm; a phantom written in millimetres has its holes 14000 apart)
UNITS_APART = 0.1
TRAY = "SutureTray"
#: m: the tray's thickness, the depth of its slot: room for the jaws' fingers around the wire
#: (the bundled slab's slot is 8 mm deep; a tray raised 8 mm onto a phantom's slab stood 2 mm
#: above the holes, and the driver's wrist struck it at the first insertion)
TRAY_DEPTH = 0.004
TRAY_MARGIN = 0.003  # m the tray reaches beyond the needle and the thread lying on it
NEEDLE_PARTS = re.compile(r"^(Needle|Thread(_\d+)?)$")


class PhantomError(ValueError):
    """The phantom file cannot go into the scene (no hole pairs, a needle of its own, ...)."""


def _matrix(p: Pose | None) -> np.ndarray:
    return pose_to_matrix(p) if p is not None else np.eye(4)


def _has_capsules(body: Body) -> bool:
    return any((s.shape or "").lower() == "capsule" for s in body.compound_collision_shape or [])


@dataclass
class Holes:
    """The phantom's hole pairs: {k: {"entry": 4x4, "exit": 4x4}} in the world (the hole body's
    frame where it is framed by capsules, else the ghost's), the names, and the ghosts each
    hole was found by ({k: {kind: [ghost names]}}: more than one is a file to fix)."""

    frames: dict[int, dict[str, np.ndarray]] = field(default_factory=dict)
    names: dict[int, dict[str, str]] = field(default_factory=dict)
    ghosts: dict[int, dict[str, list[str]]] = field(default_factory=dict)

    def pairs(self) -> list[int]:
        return sorted(k for k, d in self.frames.items() if "entry" in d and "exit" in d)

    def lone(self) -> dict[int, str]:
        """{k: "entry" or "exit"} of the pairs that have one hole only."""
        return {k: next(iter(d)) for k, d in self.frames.items() if len(d) == 1}


def _ref(text: str | None) -> str:
    """A body's reference as a file spells it (``BODY Entry 1``, ``Entry 1``, with or without a
    namespace) reduced to the body's own name: ``Entry 1``."""
    s = (text or "").rsplit("/", 1)[-1].strip()
    return s[5:].strip() if s.upper().startswith("BODY ") else s


def phantom_holes(model: ModelFile | _Files) -> Holes:
    """The hole ghosts of a phantom file, by pair, with where each hole is."""
    bodies = {_ref(b.identifier): b for b in model.bodies}
    out = Holes()
    for g in model.ghost_objects:
        hole = hole_name(g.name or g.identifier or "")
        if hole is None:
            continue
        kind, k = hole
        parent = bodies.get(_ref(g.parent)) if g.parent else None
        at = _matrix(parent.location) if parent is not None else np.eye(4)
        if parent is not None and _has_capsules(parent):
            frame, name = at, parent.name or parent.identifier
        else:
            frame, name = at @ _matrix(g.location), g.name or g.identifier
        out.frames.setdefault(k, {})[kind] = frame
        out.names.setdefault(k, {})[kind] = name
        out.ghosts.setdefault(k, {}).setdefault(kind, []).append(g.name or g.identifier)
    return out


def check_holes(holes: Holes, model: ModelFile | _Files) -> None:
    """Refuse, saying why, a phantom whose holes cannot be sutured as they stand: none at all
    (or hole bodies without their ghosts), a hole without its pair's other one, two ghosts for
    one hole, a pair so far apart that the file is in other units than metres."""
    if not holes.frames:
        named = sorted(b.name or b.identifier for b in model.bodies if hole_name(b.name or b.identifier or ""))
        raise PhantomError(
            "no hole pair: the phantom has no ghosts named Entry k and Exit k (ghostEntry1, ghostExit1, ...)"
            + (
                f"; it has hole bodies ({', '.join(named[:4])}{', ...' if len(named) > 4 else ''}) but no hole "
                "ghosts: give each a ghost (GHOST ghostEntry1 with parent: BODY Entry1), as the add-on's "
                "Add hole pair does"
                if named
                else ""
            )
        )
    lone = holes.lone()
    if lone:
        said = "; ".join(
            f"pair {k} has only its {kind} hole ({holes.ghosts[k][kind][0]}), no "
            f"{'Exit' if kind == 'entry' else 'Entry'}{k} hole ghost"
            for k, kind in sorted(lone.items())
        )
        whole = holes.pairs()
        raise PhantomError(
            ("no hole pair: the phantom has no whole pair of Entry k and Exit k hole ghosts; " if not whole else "")
            + said
            + (f" (its whole pairs: {', '.join(map(str, whole))}): name both holes of every pair" if whole else "")
        )
    twice = [(k, kind, g) for k, d in sorted(holes.ghosts.items()) for kind, g in sorted(d.items()) if len(g) > 1]
    if twice:
        k, kind, g = twice[0]
        raise PhantomError(f"pair {k}'s {kind} hole has {len(g)} ghosts ({', '.join(g)}): keep one for each hole")
    for k in holes.pairs():
        d = float(np.linalg.norm(holes.frames[k]["exit"][:3, 3] - holes.frames[k]["entry"][:3, 3]))
        if d > UNITS_APART:
            n = holes.names[k]
            raise PhantomError(
                f"{n['entry']} and {n['exit']} are {d:.1f} m apart, where this needle drives a pair at most "
                "14.5 mm apart: "
                + (
                    f"is the file in millimetres ({d:.1f} mm)? ADF lengths are in metres"
                    if d > 5.0
                    else f"bring Exit{k} next to Entry{k}"
                )
            )


def _up() -> np.ndarray:
    return np.array([0.0, 0.0, 1.0])


def _centre_and_heading(frames: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, float]:
    """The centre of the holes (entry, exit pairs) and the heading (rad about the vertical) of
    their mean direction from entry to exit."""
    pts = np.array([f[:3, 3] for pair in frames for f in pair])
    d = sum(x[:3, 3] - e[:3, 3] for e, x in frames)
    d = np.asarray(d, float) - np.dot(d, _up()) * _up()
    if np.linalg.norm(d) < 1e-9:
        raise PhantomError("the phantom's entry and exit holes lie on top of each other: no direction to suture in")
    return pts.mean(axis=0), math.atan2(d[1], d[0])


def bundled_holes() -> list[tuple[np.ndarray, np.ndarray]]:
    return [L.hole_poses(k) for k in range(1, len(L.HOLE_YS) + 1)]


def placement(holes: Holes) -> np.ndarray:
    """The rigid motion (4x4, about the vertical) from the bundled holes to the phantom's."""
    if not holes.pairs():
        raise PhantomError("no hole pair: the phantom has no ghosts named Entry k and Exit k (ghostEntry1, ...)")
    c_b, h_b = _centre_and_heading(bundled_holes())
    c_u, h_u = _centre_and_heading([(holes.frames[k]["entry"], holes.frames[k]["exit"]) for k in holes.pairs()])
    return translation(*c_u) @ rot_z(h_u - h_b) @ translation(*(-c_b))


class _Placed:
    """A body of a model file where the file puts it, as clearance.Tissue reads bodies."""

    def __init__(self, body: Body, model: ModelFile) -> None:
        self.body, self.model = body, model
        self.name = body.name or body.identifier
        self._t = _matrix(body.location)
        self.static = (body.mass or 0.0) == 0.0

    def world_matrix(self) -> np.ndarray:
        return self._t


def tissue_top(models: list[ModelFile], points: np.ndarray, below: float = 0.03, triangles: bool = True) -> np.ndarray:
    """For each world point (N, 3), the height of the phantom's collision surface under it (the
    first it meets looking down from ``below`` above the point); -inf where there is none within
    2 * ``below``. ``triangles``: a concave collision mesh read as the engine collides it
    (clearance.Tissue): as its triangles (AMBF, PyBullet), else as hulls (MuJoCo)."""
    from ...tasks.clearance import Tissue
    from ...tasks.sweep import march

    bodies = [
        _Placed(b, m) for m in models for b in m.bodies if collision_primitives(b) != [] and (b.mass or 0.0) == 0.0
    ]
    shapes = Tissue(bodies, triangles=triangles)
    t = march(shapes, points + below * _up(), -_up(), far=2 * below)
    return np.where(np.isfinite(t), points[:, 2] + below - t, -np.inf)


def _wire(needle_start: np.ndarray) -> np.ndarray:
    """Points along the needle's wire where it lies, in the bundled frame."""
    return np.array([L.arc_point(needle_start, a) for a in np.linspace(L.NEEDLE_TIP_ANGLE, L.NEEDLE_TAIL_ANGLE, 12)])


def _tray_boxes(wire: np.ndarray, thread: np.ndarray) -> tuple[list, list]:
    """The tray's top as rectangles ((x0, y0), (x1, y1)), bundled frame: under the needle, with
    the bundled slab's slot where the jaws close around the wire, and a strip under the thread;
    and the slot's rectangle."""
    lo, hi = wire[:, :2].min(axis=0) - TRAY_MARGIN, wire[:, :2].max(axis=0) + TRAY_MARGIN
    lo[0] = min(lo[0], L.SLOT_X[0] - (L.SLOT_X[1] - L.SLOT_X[0]) / 2)  # the slot closed at both ends, as in the slab
    gy = L.NEEDLE_GRASP_XY[1]
    sx0, sx1 = L.SLOT_X
    sy0, sy1 = gy - L.SLOT_HALF_Y, gy + L.SLOT_HALF_Y
    out = [
        ((lo[0], lo[1]), (hi[0], sy0)),
        ((lo[0], sy1), (hi[0], hi[1])),
        ((lo[0], sy0), (sx0, sy1)),
        ((sx1, sy0), (hi[0], sy1)),
    ]
    if len(thread):
        tlo, thi = thread[:, :2].min(axis=0) - TRAY_MARGIN, thread[:, :2].max(axis=0) + TRAY_MARGIN
        out.append(((tlo[0], tlo[1]), (thi[0], min(thi[1], lo[1]))))
    return [(a, b) for a, b in out if b[0] - a[0] > 1e-6 and b[1] - a[1] > 1e-6], [((sx0, sy0), (sx1, sy1))]


def _tray(rects: list, top: float, t: np.ndarray) -> Body:
    """The static tray (rectangles of the bundled frame, TRAY_DEPTH deep under ``top``), placed by t."""
    parts = [
        ShapeEntry(
            shape="Box",
            geometry=Geometry(x=x1 - x0, y=y1 - y0, z=TRAY_DEPTH),
            offset=Pose(Vec3((x0 + x1) / 2, (y0 + y1) / 2, top - TRAY_DEPTH / 2)),
        )
        for (x0, y0), (x1, y1) in rects
    ]
    return Body(
        identifier=f"BODY {TRAY}",
        name=TRAY,
        mass=0.0,
        location=pose(t),
        compound_collision_shape=parts,
        collision_margin=0.0001,
        friction=Friction(static=0.8, rolling=0.01),
        restitution=0.0,
        passive=False,
    )


@dataclass
class Composed:
    scene: Scene
    placement: np.ndarray  # the bundled frame -> the phantom's
    lift_m: float  # how far the needle's bed was raised onto the phantom's tissue
    pairs: list[int]  # in the order the suture visits them: from the needle's end of the line
    names: dict[int, dict[str, str]]
    bed_turn_deg: float = 0.0  # the needle's bed turned about the vertical beside a sloping phantom (needle_bed)


def _moved(body: Body, t: np.ndarray) -> None:
    body.location = pose(t @ _matrix(body.location))


class _Files:
    """Several model files read as one phantom: their bodies, joints and ghosts together (a
    ghost's parent may stand in another file, as AMBF finds it by name)."""

    def __init__(self, models: list[ModelFile]) -> None:
        self.models = models
        self.bodies = [b for m in models for b in m.bodies]
        self.joints = [j for m in models for j in m.joints]
        self.ghost_objects = [g for m in models for g in m.ghost_objects]


def compose(bundled: Scene, phantom: ModelFile | list[ModelFile], triangles: bool = True) -> Composed:
    """The bundled scene with ``phantom`` (a model file, or the model files of a launch file) in
    place of its phantom, the rest placed for its holes (the module docstring); ``triangles``:
    whether the engine collides a static concave mesh as its triangles (tissue_top)."""
    files = phantom if isinstance(phantom, list) else [phantom]
    whole = _Files(files)
    holes = phantom_holes(whole)
    own = [b.name or b.identifier for b in whole.bodies if NEEDLE_PARTS.match(b.name or "")]
    if own:
        raise PhantomError(
            f"the phantom file has its own {own[0]}: --phantom puts a phantom beside the bundled needle "
            "and thread; export the phantom's bodies alone, or play your whole scene (adfkit suture SCENE)"
        )
    kept = {b.name for m in bundled.models for b in m.bodies if not BUNDLED_TISSUE.match(b.name or "")}
    clash = sorted({b.name for b in whole.bodies if b.name in kept})
    if clash:
        # the bundled scene's cameras hang from its CameraFrame: beside a second one they found no
        # parent and stayed where the bundled scene has them, whatever the placement
        raise PhantomError(
            f"the phantom file has a body named {clash[0]}, as a body of the bundled scene that --phantom keeps "
            f"({'the stereo camera hangs from it' if clash[0] == 'CameraFrame' else 'the arms, the needle or the camera'}): "
            "export the phantom's tissue and hole bodies alone, or rename it"
        )
    check_holes(holes, whole)
    t = placement(holes)
    scene = copy.deepcopy(bundled)
    needle_file = None
    models = []
    for m in scene.models:
        names = {b.name for b in m.bodies}
        if "Needle" in names:
            needle_file = m
            m.bodies = [b for b in m.bodies if not BUNDLED_TISSUE.match(b.name or "")]
        elif m.ghost_objects and all(HOLE_NAME.search(g.name or "") for g in m.ghost_objects) and not m.bodies:
            continue  # the bundled hole ghosts go with the bundled holes
        models.append(m)
    if needle_file is None:
        raise PhantomError("the bundled scene has no needle to put beside the phantom")
    # the needle and the thread lie as far beyond the end of the line of holes as they do in the
    # bundled scene (24 mm past pair 1, along the line): placed from the pairs' centre (60 mm),
    # a short line left them far from its end pair, and the driver's grasp, chosen to reach both,
    # came down onto the needle's bed (the planner found no grasp off it: -0.3 mm; 178 N held)
    along = {
        k: (np.linalg.inv(t) @ ((f["entry"] + f["exit"]) / 2)[:, 3])[1] for k, f in holes.frames.items() if len(f) == 2
    }
    needle_t = t @ translation(0.0, max(along.values()) - max(L.HOLE_YS), 0.0)
    for m in models:
        for b in m.bodies:
            _moved(b, needle_t if m is needle_file and NEEDLE_PARTS.match(b.name or "") else t)
    # the needle's bed (the module docstring)
    wire = _wire(L.needle_start())
    needle_bodies = next(m for m in bundled.models if any(x.name == "Needle" for x in m.bodies)).bodies
    thread = np.array([_matrix(b.location)[:3, 3] for b in needle_bodies if (b.name or "").startswith("Thread")])
    rects, slot = _tray_boxes(wire, thread.reshape(-1, 3))
    bed = L.SLAB[2]
    (sx0, sy0), (sx1, sy1) = slot[0]
    grid = [(x, y, bed - TRAY_DEPTH) for x in np.linspace(sx0, sx1, 9) for y in np.linspace(sy0, sy1, 5)]
    under = np.array(grid + [(p[0], p[1], bed) for p in wire])
    placed = np.c_[under, np.ones(len(under))] @ needle_t.T
    top = tissue_top(files, placed[:, :3], triangles=triangles)
    lift = max(0.0, float(np.max(top - placed[:, 2]))) if np.isfinite(top).any() else 0.0

    # on a slope, a turned lay where it leaves the bed lower (needle_bed)
    def tops(points: np.ndarray, below: float) -> np.ndarray:
        return tissue_top(files, points, below=below, triangles=triangles)

    chosen = sloped_bed(tops, holes.frames, rects, slot, thread.reshape(-1, 3), bed, TRAY_DEPTH, needle_t)
    turn = 0.0
    if chosen is not None:
        shift, lift = chosen
        turn = TURN
        moved = needle_t @ shift @ np.linalg.inv(needle_t)
        needle_t = needle_t @ shift
        for b in needle_file.bodies:
            if NEEDLE_PARTS.match(b.name or ""):
                _moved(b, moved)
    if lift > 0:
        up = translation(0.0, 0.0, lift)
        for b in needle_file.bodies:
            if NEEDLE_PARTS.match(b.name or ""):
                _moved(b, up)
    needle_file.bodies.append(_tray(rects, bed, translation(0.0, 0.0, lift) @ needle_t))
    models.extend(files)
    scene.models = models
    # from the needle's end of the line on (the bundled pair 1 is there): a phantom numbered the
    # other way, sutured 1 to N, started at the far end with the thread drawn back over the pairs
    # it was to go through last (its pair 4 failed, entry-outside-opening by 4.9 mm)
    pairs = sorted(holes.pairs(), key=lambda k: (-along[k], k))
    return Composed(scene, t, lift, pairs, holes.names, turn)


def load_phantom(path: Path, diagnostics: list) -> ModelFile | list[ModelFile]:
    """The phantom model file, read through the input policy (a file named on the command line);
    or, for a launch file, the model files it lists (``multibody configs``), as AMBF loads them:
    a phantom whose tissue, holes and ghosts stand in several files. Its world, colours and input
    devices are the bundled scene's (said, where it names them)."""
    from ...adf import load_scene, read_file
    from ...diagnostics import warning
    from ...model import Launch

    doc, found = read_file(path)
    if not isinstance(doc, Launch):
        doc, found = read_file(path, "model")
        diagnostics.extend(found)
        return doc
    scene = load_scene(path, None, diagnostics)
    kept = [
        k
        for k, v in (
            ("world config", doc.world_config),
            ("color config", doc.color_config),
            ("input devices config", doc.input_devices_config),
            ("plugins", doc.plugins),
        )
        if v
    ]
    if kept:
        diagnostics.append(
            warning(
                "phantom-launch",
                f"--phantom takes the model files of {path.name}; its {', '.join(kept)} not (the bundled scene's stand)",
                doc.where(),
            )
        )
    return scene.models
