"""AMBF's ghost rule (Options.ghosts "ambf") as AMBF times it, in the PyBullet world.

AMBF steps Bullet, then each ghost reads the contact points Bullet's collision pass of that step
made, before the step moved anything (afGhostObject::update reads the dynamics world's manifolds,
which are not refreshed after the integration), and acts on the bodies penetrating it: their
velocities keep 0.9 a point, their gravity is off for the next step. So a body is slowed one
physics step after the step that found it inside: the ghost acts with the points of the physics
step before. A body falling into a ghost at 0.67 m/s went 0.66 mm deeper in AMBF than where the
rule acted on the points of the moment (measured with ``adfkit parity``).

At adfkit's 1 ms control step the rule acts at every control step with the points found at the
one before (links too). At a longer control step (the default 4 ms) a free body near an acting
ghost (in its broadphase box, so that one entering it is caught on the step it enters) has its
control step played one physics step at a time while it moves (faster than SLOW), the rule
acting between the physics steps with the points of the step before: its velocity set, its
gravity taken off for that step alone. A multibody link's velocities cannot be set; links keep
the force over the control step (ambf_ghost), or, on a chain AMBF's solver is played on, the
rule acts inside that step (chain_ghosts)."""

from __future__ import annotations

import ctypes

import numpy as np
import pybullet as pb

from ..ghost_rules import (
    ALONG_FROM,
    AMBF_GHOST_KEEP,
    SLOW,
    ghost_accelerations,
    ghost_velocity,
    kept_under_slow_parent,
)
from . import state_calls

#: state_calls.c adfkit_ghost_link with its in and out buffer types once looked up (None: not yet; False: numpy's)
_link_c: tuple | bool | None = None


def link_rule_in_c() -> tuple | bool:
    """(adfkit_ghost_link, its in and out buffer types), or False where state_calls.c cannot be
    had (ADFKIT_NO_C, no compiler): ambf_ghost's rule on a link then in numpy."""
    global _link_c
    if _link_c is None:
        lib = state_calls._load()
        if lib is None:
            _link_c = False
        else:
            # through PyDLL: called holding the GIL (nothing to wait for in it)
            fn, dp = ctypes.PyDLL(lib.path).adfkit_ghost_link, ctypes.POINTER(ctypes.c_double)
            fn.argtypes, fn.restype = (dp, ctypes.c_double, dp), None
            _link_c = (fn, ctypes.c_double * 24, ctypes.c_double * 6)
    return _link_c


class GhostSteps:
    """The free bodies AMBF's ghosts act on at every physics step (see the module)."""

    def __init__(self, world) -> None:
        self.world = world
        self.free = {key: sb for key, sb in world._dynamic_lookup.items() if key[1] < 0}
        self.ghosts: list = []  # the ghosts whose control step is played a physics step at a time
        self.fine = False  # any ghost is: the world plays this control step a physics step at a time
        self.was: dict = {}  # (uid, link) -> position of the free bodies near a ghost at the last control step

    def decide(self, poses: dict) -> list:
        """The acting ghosts (placed, their pass made) with a free body in their boxes (Bullet's
        broadphase boxes: grown by the contact breaking threshold, 0.02 m by default, so that one
        entering is caught on the step it enters) that moved more than SLOW·control step since the
        last control step or has just come near: this control step is played a physics step at a
        time for them. ``poses``: the bodies' poses read this control step (_manifold_points')."""
        w, cid, free = self.world, self.world.cid, self.free
        near_keys = w._near_keys
        was, now = self.was, {}
        step = SLOW * w.dt * w.opt.control_substeps
        fine = []
        for g in w._acting_ghosts:
            keys = near_keys.get(g.uid) if near_keys else None
            if keys is None:
                keys = pb.getOverlappingObjects(*pb.getAABB(g.uid, -1, cid), cid) or ()
            moving = False
            for key in keys:
                if key not in free:
                    continue
                pq = poses.get(key)
                p = pq[0] if pq is not None else pb.getBasePositionAndOrientation(key[0], cid)[0]
                now[key] = p
                q = was.get(key)
                if q is None or abs(p[0] - q[0]) + abs(p[1] - q[1]) + abs(p[2] - q[2]) > step:
                    moving = True
            if moving:
                fine.append(g)
        self.was = now
        self.ghosts, self.fine = fine, bool(fine)
        return fine

    def between(self) -> None:
        """Between two physics steps of a fine control step: those ghosts placed where their
        parents are, their points found, and the free bodies acted on with those of the step before."""
        w = self.world
        poses: dict = {}
        for g in self.ghosts:
            if g.moves:
                w._place(g)
        manifolds = w._manifold_points(self.ghosts, poses)
        acted: dict[int, object] = {}
        for g in self.ghosts:
            before = g.before
            w._overlap(g, poses, with_parent=True, manifolds=manifolds)
            parent = g.parent
            ps = parent.state() if parent is not None and not parent.static else (None, None, (0.0, 0.0, 0.0), None)
            acted.update((id(sb), sb) for sb in act_on_free(w, g, ps, before))
            g.before = g.points
        for sb in acted.values():
            weightless_for_a_step(w, sb)


def ambf_ghost(world, g, held: dict, a_step: dict | None) -> None:
    """AMBF's ghost ``g`` on the bodies in penetrating contact with it (ghost_rules.ghost_velocity),
    for the physics steps of this control step: their velocities reset (a multibody link's cannot
    be: it is given the force at its centre of mass and the torque that take its velocities there
    over the control step) and their gravity off until the next control step (``held`` gets them).
    At a 1 ms control step it acts with the points found a physics step before, as AMBF does;
    where the control step is played a physics step at a time (``a_step``) its free bodies too,
    for this physics step alone (``a_step`` gets them). A ghost with a parent finds nothing before
    the first physics step (first_points)."""
    steps = world.opt.control_substeps
    cdt = world.dt * steps
    found = first_points(world, g)
    before, g.before = g.before, found
    per_step = a_step is not None or steps == 1
    parent, now = g.parent, world._state_now  # (the states this control step read: PyBulletWorld)
    ps = now(parent) if parent is not None and not parent.static else (None, None, (0.0, 0.0, 0.0), None)
    for sb in act_on_free(world, g, ps, before if per_step else found, 1 if per_step else steps, now):
        (a_step if a_step is not None else held)[id(sb)] = sb
    v_par = ps[2]
    for sb, points in before if steps == 1 else found:
        if points == 0 or sb.link < 0 or world.chain_stepped(sb.articulation):  # (chain_ghosts: in its step)
            continue
        held[id(sb)] = sb
        p, q, v, w = ps if sb is parent else now(sb)
        f, t = link_push(v, w, v_par, points * steps, cdt, sb.mass, sb.inertia, pb.getMatrixFromQuaternion(q))
        sb.force(f, list(p))
        sb.torque(t)


def link_push(v, w, v_par, points: int, cdt: float, mass: float, inertia, rot, c: tuple | bool | None = None):
    """(force, torque) as lists: AMBF's rule on a link with velocities ``v``, ``w`` under a ghost
    whose parent moves at ``v_par`` (ghost_rules.ghost_accelerations), as m·a at its centre of mass
    and rot·(I ∘ rotᵀ·α), ``rot`` the COM frame's (getMatrixFromQuaternion's 9 numbers, rows);
    in C where it can be had (``c``: link_rule_in_c(), looked up when None; False: numpy's)."""
    if c is None:
        c = _link_c if _link_c is not None else link_rule_in_c()
    if c:  # the same sums in C, with numpy's rounding (state_calls.c adfkit_ghost_link)
        fn, ins, outs = c  # buffers of each call's own (worlds may step in threads of their own)
        out = outs()
        fn(ins(*v, *w, *v_par, AMBF_GHOST_KEEP**points, cdt, mass, *inertia, *rot), ALONG_FROM, out)
        return out[0:3], out[3:6]
    a, alpha = ghost_accelerations(v, w, v_par, points, cdt)
    r = np.array(rot).reshape(3, 3)
    return (mass * a).tolist(), (r @ (np.asarray(inertia) * (r.T @ alpha))).tolist()


def chain_ghosts(world, art) -> dict:
    """World.chain_ghosts: the bodies of ``art`` the acting ghosts hold at a 1 ms control step,
    with the points found a physics step before (what the rule acts with in this step)."""
    if world.opt.ghosts != "ambf" or world.opt.control_substeps != 1:
        return {}
    out: dict[int, list] = {}
    for g in world._acting_ghosts:
        acts = [(sb.link + 1, n) for sb, n in g.before if n and sb.uid == art.uid]
        if acts:
            parent = g.parent
            v_par = parent.state()[2] if parent is not None and not parent.static else (0.0, 0.0, 0.0)
            for k, n in acts:
                out.setdefault(k, []).append((n, v_par))
    return out


def first_points(world, g) -> list:
    """The points ghost ``g`` acts with: those found now, but nothing before the first physics
    step for a ghost with a parent. AMBF sets a ghost's pose in Bullet in its update, after each
    physics step (afGhostObject::update): for the first step's collision pass a ghost that hangs
    on a body stands where its location puts it in the world, not on its parent. Measured: a ghost
    on a falling body, made around it and a body resting in it, let both fall two physics steps
    in AMBF before they went weightless (one step here before this; 9.6 mm apart after 1 s)."""
    return g.points if world._ghosts_passed or g.parent is None else []


def act_on_free(world, g, ps, points, steps: int = 1, now=None) -> list:
    """AMBF's rule on the free bodies of ``points`` [(body, contact points)] for ``steps`` physics
    steps (``ps``: the ghost parent's state, or a static one's): their velocities set; returns
    those it acted on (their gravity is to be taken off). ``now``: in a control step's first
    physics step, PyBulletWorld._state_now (the states it read, told of the velocities set here)."""
    cid, parent, v_par = world.cid, g.parent, ps[2]
    acted = []
    for sb, n in points:
        if n == 0 or sb.link >= 0 or (sb.articulation is not None and world.chain_stepped(sb.articulation)):
            continue
        s = ps if sb is parent else now(sb) if now is not None else None
        v, w = s[2:] if s is not None else pb.getBaseVelocity(sb.uid, cid)
        kept = kept_under_slow_parent(v, w, v_par, n * steps)
        if kept is None:
            kept = tuple(x.tolist() for x in ghost_velocity(v, w, v_par, n * steps))
        pb.resetBaseVelocity(sb.uid, kept[0], kept[1], cid)
        if now is not None:  # what getBaseVelocity gives back now
            world._reset_now[(sb.uid, -1)] = (*s[:2], tuple(kept[0]), tuple(kept[1]))
        acted.append(sb)
    return acted


def weightless(world, bodies, poses: dict | None = None) -> None:
    """Each body's weight taken off for this control step (AMBF switches its gravity off).
    ``poses``: as _update_ghosts' (read this control step; the ghosts set velocities, not
    positions), its centre of mass read again where it has none."""
    for sb in bodies:
        g = sb.gravity if sb.gravity is not None else world.gravity
        pq = poses.get((sb.uid, sb.link)) if poses else None
        sb.force([-sb.mass * c for c in g], list(pq[0] if pq is not None else sb.com_position()))


def weightless_for_a_step(world, sb) -> None:
    """A free body's weight taken off for the next physics step alone (not held over the control
    step: held.py does not record it)."""
    g = sb.gravity if sb.gravity is not None else world.gravity
    pos = pb.getBasePositionAndOrientation(sb.uid, world.cid)[0]
    pb.applyExternalForce(sb.uid, -1, [-sb.mass * c for c in g], pos, pb.WORLD_FRAME, world.cid)
