"""What the PyBullet world does between steps (the Interaction half of PyBulletWorld): ghosts
sensing what is inside them and acting on it (AMBF's rule, or viscous friction in holes), ray
sensors, the grasp's constraint actuator, collision switches, contacts."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pybullet as pb

from ..ghost_rules import in_same_place, viscous_impulse_force
from ..rotations import invert
from .bodies import SimBody
from .ghost_pass import KEPT_WITHIN
from .ghost_steps import ambf_ghost, chain_ghosts, weightless, weightless_for_a_step

# m between the three point constraints of a grasp (PyBulletWorld.actuate): the solver leaves each
# pivot a fraction of a millimetre open under load, which turns the held body by gap/span; at 5 mm
# the bundled needle turned 5° in the puller's jaws and its far end moved 1.3 mm (the thread
# dragging through three pairs), at 20 mm (about the needle's size) 1.5° and 0.66 mm
GRASP_SPAN = 0.02
# error reduction of the grasp's constraints: the share of their gap closed per step (Bullet's 0.2 let
# the thread's pull stretch a held needle 2 mm out of the jaws; 0.8 holds it within a fraction of that)
GRASP_ERP = 0.8
# the force the grasp's constraints may push with: past any they meet. AMBF's constraint actuator is a
# btFixedConstraint with no limit; the file's `max impulse` and `tau` are read by AMBF 2.0 and not used
# (measured: the bundled suture replayed with both at 0.001 repeats to the bit, and a 1 kg box hung from
# an actuator with `max impulse: 0.0001` stays held). PyBullet caps a constraint at 500 N unless told
GRASP_MAX_FORCE = 1e9
# collision bits a ghost has during its collision pass (_manifold_points): meeting every body's
GHOST_PASS_BITS = -1


@dataclass(eq=False)
class SimGhost:
    key: str
    ghost: object
    uid: int
    parent: SimBody | None
    pose_in_parent: np.ndarray  # ghost COM frame in the parent's PyBullet frame (or world)
    friction: bool = False
    overlapping: list = field(default_factory=list)
    pq_in_parent: tuple = ()  # pose_in_parent as PyBullet (position, quaternion)
    points: list = field(default_factory=list)  # (body, penetrating contact points) at the last query
    before: list = field(default_factory=list)  # points at the physics step before (ghost_steps.py)
    moves: bool = False  # a dynamic parent: the ghost follows it every step
    placed_at: tuple | None = None  # the parent's (position, quaternion) the ghost was last placed at
    distances: dict = field(default_factory=dict)  # (uid, link) -> (placement, body pose, inside, points): _overlap
    parts: object = None  # its collision parts (shapes.ShapeParts): ghost_pass.py's copy is made of them


@dataclass(eq=False)
class SimActuator:
    key: str
    actuator: object
    parent: SimBody
    location: np.ndarray  # in the parent body frame
    constraint: list | None = None  # the grasp's constraint ids (see PyBulletWorld.actuate)
    target: SimBody | None = None


@dataclass(eq=False)
class SimSensor:
    key: str
    sensor: object
    parent: SimBody
    location: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    sensed: list = field(default_factory=list)
    rays: list = field(default_factory=list)  # per ray: (body hit or None, fraction of the range)
    resist: object = None  # a resistance sensor's ResistanceParams (played under AMBF's bodies)
    states: list = field(default_factory=list)  # and its rays' RayStates (resistance.py)


class Interaction:
    def set_collision(self, a: SimBody, b: SimBody, enabled: bool) -> None:
        """Let two bodies collide or pass through each other (a task's choice, e.g. a needle
        through a tissue whose collision shape is a convex hull over its holes)."""
        pb.setCollisionFilterPair(a.uid, b.uid, a.link, b.link, int(enabled), physicsClientId=self.cid)
        self._pairs_epoch += 1
        pair = frozenset(((a.uid, a.link), (b.uid, b.link)))
        self._pairs_off = getattr(self, "_pairs_off", set())
        (self._pairs_off.discard if enabled else self._pairs_off.add)(pair)

    def ghost_pose(self, g: SimGhost) -> np.ndarray:
        """World pose (4x4) of a ghost, following its parent."""
        return self._frame(g.parent) @ g.pose_in_parent if g.parent is not None else np.array(g.pose_in_parent)

    def _update_ghosts(self, poses: dict | None = None) -> None:
        """The ghosts that act sense every control step (AMBF's rule: every ghost; the paper's
        friction: the hole ghosts); the others only when asked (overlapping()): a moving ghost
        costs a pose reset and a distance query per nearby body, and without AMBF's rule the
        PSMs' finger ghosts are only read when grasping.

        ``poses``: {(uid, link): (position, quaternion)} of the bodies read since the last step
        (control() passes the springs' and the gravity overrides'), used rather than read again.
        A ghost whose parent has not moved since it was placed is not placed again, and a body
        that has not moved since its distance to an unmoved ghost was measured is not measured
        again (the same transforms give the same answer): a resting phantom costs no queries."""
        if self.gui:
            self.place_ghosts()
        poses = dict(poses) if poses else {}  # hole ghosts share parents: read each once
        cid = self.cid
        ambf = self.opt.ghosts == "ambf"
        held: dict[int, SimBody] = {}
        for g in self._acting_ghosts:
            if g.moves:
                parent = g.parent
                key = (parent.uid, parent.link)
                pq = poses.get(key)
                if pq is None:
                    pq = poses[key] = parent.state(velocity=False)[:2]
                if pq != g.placed_at:
                    pos, orn = pb.multiplyTransforms(pq[0], pq[1], *g.pq_in_parent)
                    pb.resetBasePositionAndOrientation(g.uid, pos, orn, cid)
                    g.placed_at = pq
        manifolds = self._manifold_points(self._acting_ghosts, poses) if ambf else None
        fine = self._ghost_steps.decide(poses) if ambf and self._ghost_steps is not None else ()
        a_step: dict[int, SimBody] = {}  # free bodies weightless for the next physics step alone
        for g in self._acting_ghosts:
            found = self._overlap(g, poses, with_parent=ambf, manifolds=manifolds)
            if ambf and (found or g.before):  # the points found now or a step before
                ambf_ghost(self, g, held, a_step if g in fine else None)
            elif found:
                self._viscous(g, found)
        self._ghosts_passed = True  # (ghost_steps.first_points)
        if ambf:
            weightless(self, held.values(), poses)
            for sb in a_step.values():
                weightless_for_a_step(self, sb)

    def chain_ghosts(self, art) -> dict:
        return chain_ghosts(self, art)

    def place_ghosts(self) -> None:
        """Move every ghost with a moving parent to it (before a picture is taken)."""
        for g in self.ghosts:
            self._place(g)

    def _place(self, g: SimGhost) -> None:
        if g.moves:
            p, q, _, _ = g.parent.state(velocity=False)
            pos, orn = pb.multiplyTransforms(p, q, *g.pq_in_parent)
            pb.resetBasePositionAndOrientation(g.uid, pos, orn, physicsClientId=self.cid)
            g.placed_at = (p, q)

    def overlapping(self, g: SimGhost) -> list[SimBody]:
        """The dynamic bodies inside ghost ``g`` now (moved to its parent first); also kept in
        ``g.overlapping``."""
        self._place(g)
        return self._overlap(g)

    def _manifold_points(self, ghosts, poses: dict) -> dict[int, dict[tuple[int, int], int]]:
        """{ghost uid: {(uid, link): its penetrating contact points}} as Bullet's narrowphase makes them for
        the pair in the dynamics world, where AMBF's ghost reads them (its manifolds: a box in a box gives
        four points at once, btBoxBoxDetector). A ghost collides with nothing (it would push what enters
        it), so those near a dynamic body are let collide for one collision pass between steps
        (performCollisionDetection: no step, so no push) and shut again, in a world of the ghosts and
        copies of those bodies alone where they can be copied (ghost_pass.py: the same points), else in
        the dynamics world; a pair GJK answers (hulls) gives one point a pass, where AMBF's persistent
        manifold gathers up to four over its steps. The last answer stands while the same bodies are near
        the same ghosts, within KEPT_WITHIN of where they were, and no collision pair or grasp has changed
        (``poses``: those read this control step). ``_near_keys``: each ghost's box's bodies, for _overlap."""
        cid, dynamic = self.cid, self._dynamic_lookup
        near, which, where, passes = [], [self._pairs_epoch], [], []
        self._near_keys = overlaps = {}  # None after a pass in this world (it updates the boxes)
        for g in ghosts:
            lo, hi = pb.getAABB(g.uid, -1, cid)
            keys = overlaps[g.uid] = [key for key in pb.getOverlappingObjects(lo, hi, cid) or () if key in dynamic]
            if keys:
                near.append(g)
                which.append((g.uid, keys))
                pq = pb.getBasePositionAndOrientation(g.uid, cid)
                passes.append((g, pq, keys))
                where.append(pq)
                for key in keys:
                    if key not in poses:
                        poses[key] = dynamic[key].state(velocity=False)[:2]
                    where.append(poses[key])
        if not near:
            return {}
        place = (which, where)
        last = self._manifold_place
        if last is not None and last[0] == which and in_same_place(last[1], where, KEPT_WITHIN):
            return self._manifold_made
        # the pass in a world of the ghosts and the bodies near them alone (ghost_pass.py), else here
        made = self._ghost_pass.counts(passes, poses)
        if made is not None:
            self._manifold_place, self._manifold_made = place, made
            return made
        self._near_keys = None
        for g in near:
            pb.setCollisionFilterGroupMask(g.uid, -1, GHOST_PASS_BITS, GHOST_PASS_BITS, physicsClientId=cid)
        pb.performCollisionDetection(physicsClientId=cid)
        out: dict[int, dict[tuple[int, int], int]] = {}
        for g in near:
            counts = out.setdefault(g.uid, {})
            for c in pb.getContactPoints(bodyA=g.uid, physicsClientId=cid):
                if c[8] < 0.0:
                    key = (c[2], c[4]) if c[1] == g.uid else (c[1], c[3])
                    counts[key] = counts.get(key, 0) + 1
            pb.setCollisionFilterGroupMask(g.uid, -1, 0, 0, physicsClientId=cid)
        self._manifold_place, self._manifold_made = place, out
        return out

    def _overlap(
        self, g: SimGhost, poses: dict | None = None, with_parent: bool = False, manifolds: dict | None = None
    ) -> list[SimBody]:
        """``overlapping`` with the ghost already where its parent is (its parent left out unless
        ``with_parent``: AMBF's ghosts sense the body they hang on). With ``poses`` (see
        _update_ghosts), each answer is kept with the ghost's and the body's poses and reused
        while both stay exactly where they were (and no collision pair or grasp has changed).
        ``g.points`` gets each body found with its penetrating contact points (distance < 0): from
        ``manifolds`` (_manifold_points) where given, else the closest-point query's (one a pair).
        Given ``manifolds`` (AMBF's rule, which acts on their points alone, as afGhostObject reads
        its manifolds), a body is inside where the ghost's pass made a penetrating point with it and
        nowhere else: no closest-point query (on the corpus suturing set, 3 s, each of its 12,138
        queries had found the body inside)."""
        cid = self.cid
        keys = self._near_keys.get(g.uid) if manifolds is not None and self._near_keys else None  # _manifold_points'
        keys = pb.getOverlappingObjects(*pb.getAABB(g.uid, -1, cid), cid) or () if keys is None else keys
        found, points = [], []
        dynamic, parent, closest = self._dynamic_lookup, g.parent, pb.getClosestPoints
        at = (self._pairs_epoch, g.placed_at)
        known = g.distances
        counts = manifolds.get(g.uid, {}) if manifolds is not None else None
        for key in keys:
            sb = dynamic.get(key)
            if sb is None or (sb is parent and not with_parent) or (counts is not None and not counts.get(key)):
                continue
            if counts is not None:  # a penetrating point of the pass: inside, as AMBF's ghost reads it
                found.append(sb)
                points.append((sb, counts[key]))
                continue
            pose = poses.get(key) if poses else None
            was = known.get(key) if pose is not None else None
            if was is not None and was[0] == at and was[1] == pose:
                inside, deep = was[2], was[3]
            else:
                hits = closest(g.uid, key[0], 0.0, -1, key[1], physicsClientId=cid)
                inside, deep = bool(hits), sum(1 for h in hits if h[8] < 0.0)
                if pose is not None:
                    known[key] = (at, pose, inside, deep)
            if inside:
                found.append(sb)
                points.append((sb, deep))
        g.overlapping = found
        g.points = points
        return found

    def _viscous(self, g: SimGhost, found) -> None:
        """F = -K·(v_body - v_phantom) on every body inside a hole ghost (the paper's needle friction)."""
        k = self.opt.hole_friction
        cdt = self.dt * self.opt.control_substeps
        v_ref = np.array(g.parent.state()[2]) if g.parent is not None and not g.parent.static else np.zeros(3)
        for sb in found:
            f = viscous_impulse_force(sb.mass, np.array(sb.state()[2]) - v_ref, k, cdt)
            sb.force(f.tolist(), list(sb.com_position()))

    def _sense(self, s: SimSensor) -> None:
        t = self._frame(s.parent) @ invert(s.parent.com_in_body) @ s.location
        a = (t[:3, :3] @ s.starts.T).T + t[:3, 3]
        b = (t[:3, :3] @ s.ends.T).T + t[:3, 3]
        hits = pb.rayTestBatch(a.tolist(), b.tolist(), physicsClientId=self.cid)
        lookup = self._lookup
        s.sensed, s.rays = [], []
        for h in hits:
            sb = lookup.get((h[0], h[1]))
            if sb is s.parent:
                sb = None
            if sb is not None and sb not in s.sensed:
                s.sensed.append(sb)
            s.rays.append((sb, float(h[2]) if sb is not None else 1.0))

    def actuate(self, actuator: SimActuator, target: SimBody) -> None:
        """Fix ``target`` to the actuator's parent at their current relative pose.

        Three POINT2POINT constraints at non-collinear points (the actuator location and
        GRASP_SPAN along its x and y axes) rather than one JOINT_FIXED: PyBullet's fixed constraint
        between a multibody link and a maximal body drives the pair to a wrong relative
        orientation (measured: 120° off within 20 ms on the suturing PSM), while point pivots are
        exact, and three of them lock all six degrees of freedom."""
        self.release(actuator)
        pw = self._frame(actuator.parent)
        tw = self._frame(target)
        at_world = pw @ invert(actuator.parent.com_in_body) @ actuator.location
        fa = invert(pw) @ at_world
        fb = invert(tw) @ at_world
        ids = []
        for e in (np.zeros(3), np.array([GRASP_SPAN, 0, 0]), np.array([0, GRASP_SPAN, 0])):
            pa = fa[:3, :3] @ e + fa[:3, 3]
            pbv = fb[:3, :3] @ e + fb[:3, 3]
            c = pb.createConstraint(
                actuator.parent.uid,
                actuator.parent.link,
                target.uid,
                target.link,
                pb.JOINT_POINT2POINT,
                [0, 0, 0],
                pa.tolist(),
                pbv.tolist(),
                physicsClientId=self.cid,
            )
            pb.changeConstraint(c, maxForce=GRASP_MAX_FORCE, erp=GRASP_ERP, physicsClientId=self.cid)
            ids.append(c)
        actuator.constraint, actuator.target = ids, target
        self._pairs_epoch += 1
        uid = actuator.parent.uid
        self._parting = [p for p in self._parting if not (p[0] == uid and p[2] is target)]
        for link in self._links(actuator.parent):  # the closed jaws would push the held body out
            if not self._pair_off(actuator.parent.uid, link, target):
                pb.setCollisionFilterPair(
                    actuator.parent.uid, target.uid, link, target.link, 0, physicsClientId=self.cid
                )

    def _pair_off(self, uid: int, link: int, b: SimBody) -> bool:
        return frozenset(((uid, link), (b.uid, b.link))) in getattr(self, "_pairs_off", ())

    def _links(self, sb: SimBody):
        art = sb.articulation
        return range(-1, len(art.records)) if art is not None else [sb.link]

    def release(self, actuator: SimActuator) -> None:
        if actuator.constraint is not None:
            self._pairs_epoch += 1
            for c in actuator.constraint:
                pb.removeConstraint(c, physicsClientId=self.cid)
            # the closed jaws lie in the body they held (they did not collide with it): each link
            # collides with it again once it has come off it (parting, every control step), not
            # while inside it, where it would throw the body out (the bundled needle: 9 N from
            # the opening jaws for half a second, 3.5 degrees in the other arm's grasp)
            t, uid = actuator.target, actuator.parent.uid
            self._parting += [(uid, link, t) for link in self._links(actuator.parent)]
            self.parting()
        actuator.constraint, actuator.target = None, None

    def parting(self) -> None:
        """Let each link that released a body collide with it again once they no longer overlap."""
        still = []
        for uid, link, t in self._parting:
            if self._pair_off(uid, link, t):  # set_collision's choice stays
                continue
            if pb.getClosestPoints(uid, t.uid, 0.0, link, t.link, physicsClientId=self.cid):
                still.append((uid, link, t))
            else:
                pb.setCollisionFilterPair(uid, t.uid, link, t.link, 1, physicsClientId=self.cid)
                self._pairs_epoch += 1
        self._parting = still

    def contacts_among(self, bodies) -> list:
        """As World.contacts_among, one getContactPoints a multibody (all its links at once)."""
        per_call = float(self.physics_steps_a_call)  # the force in newtons (physics_steps_a_call)
        wanted: dict[int, dict[int, SimBody]] = {}
        for sb in bodies:
            for link in sb.links:
                wanted.setdefault(sb.uid, {})[link] = sb
        out = []
        lookup = self._lookup
        for uid, links in wanted.items():
            one = next(iter(links)) if len(links) == 1 else None
            query = {"bodyA": uid, "physicsClientId": self.cid}
            if one is not None:
                query["linkIndexA"] = one  # a free body, or a single link: only its contacts
            for c in pb.getContactPoints(**query) or ():
                sb = links.get(c[3])
                other = lookup.get((c[2], c[4]))
                if sb is not None and other is not None and other is not sb:
                    out.append((sb, other, float(c[9]) * per_call, c[5]))
        return out

    def contacts(self, sb: SimBody) -> list:
        """[(other SimBody, normal force N, world point)] of the contacts ``sb`` has after the last
        step: PyBullet's reading times the physics steps the step split into (physics_steps_a_call)."""
        per_call = float(self.physics_steps_a_call)
        out = []
        query = {"bodyA": sb.uid, "physicsClientId": self.cid}
        if not sb.piece_links:
            query["linkIndexA"] = sb.link
        for c in pb.getContactPoints(**query) or ():
            if c[3] not in sb.links:
                continue
            other = self._lookup.get((c[2], c[4]))
            if other is not None and other is not sb:
                out.append((other, float(c[9]) * per_call, c[5]))
        return out
