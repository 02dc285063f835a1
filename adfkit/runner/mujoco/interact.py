"""What the MuJoCo world does between steps (the Interaction half of MujocoWorld): ghosts sensing
what is inside them and acting on it (AMBF's rule, or the hole ghosts' viscous friction), ray sensors, the grasp's weld,
collision switches at run time, contacts."""

from __future__ import annotations

import mujoco
import numpy as np

from ..ghost_rules import MANIFOLD_POINTS, SAME_PLACE, ghost_accelerations, ghost_velocity, viscous_impulse_force
from ..plan import ALL_GROUPS
from ..rotations import invert, matrix_to_quat, pose_matrix
from .assemble import WAKE_FORCE, _xyzw
from .collision import EXCLUDE_SPARE
from .objects import MjActuator, MjBody, MjGhost, MjSensor


class Interaction:
    def _sense(self, s: MjSensor) -> None:
        m, d = self.model, self.data
        t = s.parent.world_matrix() @ s.location
        a = s.starts @ t[:3, :3].T + t[:3, 3]
        b = s.ends @ t[:3, :3].T + t[:3, 3]
        s.sensed, s.rays = [], []
        for p, q in zip(a, b):
            x = mujoco.mj_ray(m, d, p, q - p, self._ray_groups, 1, s.parent.id, self._ray_hit)
            sb = None
            if 0.0 <= x <= 1.0 and self._ray_hit[0] >= 0:
                sb = self._body_of_id.get(int(m.geom_bodyid[self._ray_hit[0]]))
                if sb is not None and sb not in s.sensed:
                    s.sensed.append(sb)
            s.rays.append((sb, float(x) if sb is not None else 1.0))

    def place_ghosts(self) -> None:
        """Ghost geoms ride on their parent bodies: nothing to move."""

    def overlapping(self, g: MjGhost) -> list[MjBody]:
        """The dynamic bodies inside ghost ``g`` now (bounding spheres first, then MuJoCo's
        exact geom distance); also kept in ``g.overlapping``."""
        m, d = self.model, self.data
        cg = self._cand_geoms
        found = []
        if len(cg):
            gx = d.geom_xpos
            near = np.zeros(len(cg), dtype=bool)
            for gid in g.geoms:
                dist = np.linalg.norm(gx[cg] - gx[gid], axis=1)
                near |= dist <= m.geom_rbound[cg] + m.geom_rbound[gid]
            seen = set()
            for k in np.nonzero(near)[0]:
                sb = self._cand_geom_body[k]
                if id(sb) in seen or sb is g.parent:
                    continue
                for gid in g.geoms:
                    if mujoco.mj_geomDistance(m, d, int(gid), int(cg[k]), 0.0, None) <= 0.0:
                        found.append(sb)
                        seen.add(id(sb))
                        break
        g.overlapping = found
        self._overlaps_cleared = False
        return found

    def _penetrating(self, ghosts) -> list[list[tuple[MjBody, int]]]:
        """For each ghost, each dynamic body in penetrating contact with it (its parent too: AMBF's
        ghosts sense the body they hang on), with its contact points: for each of its geoms that
        penetrates one of the ghost's (MuJoCo's exact geom distance below 0; bounding spheres
        first), the points MuJoCo's collider makes for the pair (_collider_points), at most
        MANIFOLD_POINTS (a Bullet manifold's: AMBF's ghost acts once per point of it) and at
        least one."""
        m, d = self.model, self.data
        cg = self._cand_geoms
        if not len(cg):
            return [[] for _ in ghosts]
        gx = d.geom_xpos
        pairs = []  # per ghost: (body, ghost geom, body geom) penetrating
        for g in ghosts:
            near = np.zeros(len(cg), dtype=bool)
            for gid in g.geoms:
                near |= np.linalg.norm(gx[cg] - gx[gid], axis=1) <= m.geom_rbound[cg] + m.geom_rbound[gid]
            pairs.append(
                [
                    (self._cand_geom_body[k], int(gid), int(cg[k]))
                    for k in np.nonzero(near)[0]
                    for gid in g.geoms
                    if mujoco.mj_geomDistance(m, d, int(gid), int(cg[k]), 0.0, None) < 0.0
                ]
            )
        made = self._collider_points([p for found in pairs for p in found]) if any(pairs) else {}
        out = []
        for found in pairs:
            points: dict[int, list] = {}
            for sb, a, b in found:
                n = min(max(made.get((min(a, b), max(a, b)), 0), 1), MANIFOLD_POINTS)
                points.setdefault(id(sb), [sb, 0])[1] += n
            out.append([(sb, n) for sb, n in points.values()])
        return out

    def _collider_points(self, pairs) -> dict[tuple[int, int], int]:
        """{(geom, geom): penetrating contacts} that MuJoCo's collision pass makes between the
        ghosts' geoms and every other, with the ghosts let collide for that pass only (mj_collision
        between control steps; the step's own pass, which they do not join, writes the contacts
        the solver and every reader see). A box in a box gives several, as Bullet's box-box
        manifold does. A ghost's geom never meets its own body's (MuJoCo collides no body with
        itself, nor with its parent): those pairs keep the distance query's one point. The last
        answer stands while the geoms of ``pairs`` (body, ghost geom, body geom) stay within
        SAME_PLACE of where they were (a resting body inside a ghost, the phantom's holes, jaws
        held still with round-off's 1e-16 m jitter: no pass)."""
        m, d = self.model, self.data
        geoms = sorted({g for _, a, b in pairs for g in (a, b)})
        where = np.concatenate([d.geom_xpos[geoms].ravel(), d.geom_xmat[geoms].ravel()])
        last = self._collider_key
        if last is not None and last[0] == geoms and np.max(np.abs(last[1] - where)) <= SAME_PLACE:
            return self._collider_made
        key = (geoms, where)
        ids, bodies = self._ghost_geom_ids, self._ghost_bodies
        saved = m.body_conaffinity[bodies].copy()
        m.geom_conaffinity[ids] = ALL_GROUPS  # their contype (build.GHOST_CONTYPE) meets no geom's conaffinity
        m.body_conaffinity[bodies] |= ALL_GROUPS  # the broadphase filters bodies by these first
        try:
            mujoco.mj_collision(m, d)
        finally:
            m.geom_conaffinity[ids] = 0
            m.body_conaffinity[bodies] = saved
        ghost = self._ghost_geom_set
        out: dict[tuple[int, int], int] = {}
        for c in d.contact[: d.ncon]:
            a, b = int(c.geom[0]), int(c.geom[1])
            if c.dist < 0.0 and (a in ghost) != (b in ghost):
                pair = (min(a, b), max(a, b))
                out[pair] = out.get(pair, 0) + 1
        self._collider_key, self._collider_made = key, out
        return out

    def _ambf_ghosts(self) -> None:
        """AMBF's ghost objects (ghost_rules: afGhostObject::update after each physics step), for
        this control step's physics steps: every body in penetrating contact keeps
        AMBF_GHOST_KEEP per contact and step of its velocity across the ghost parent's (a free
        body's is set; a jointed one is given the force at its centre of mass and the torque that
        take it there over the control step, as in the PyBullet runner) and is weightless until
        the next control step."""
        steps = self.opt.control_substeps
        cdt = self.dt * steps
        d, m = self.data, self.model
        held: dict[int, MjBody] = {}
        for g, found in zip(self.ghosts, self._penetrating(self.ghosts)):
            g.overlapping, g.points = [sb for sb, _ in found], found
            if not found:
                continue
            if not held:  # the velocities now: mj_step left those of its last physics step's start
                mujoco.mj_comPos(m, d)
                mujoco.mj_comVel(m, d)
            moving = g.parent is not None and not g.parent.static
            v_par = self._com_velocity(g.parent) if moving else np.zeros(3)
            for sb, points in found:
                held[id(sb)] = sb
                v6 = self._vel6
                mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, sb.id, v6, 0)
                v, w = ghost_velocity(v6[3:], v6[:3], v_par, points * steps)
                if not self.set_body_velocity(sb, v, w):
                    a, alpha = ghost_accelerations(v6[3:], v6[:3], v_par, points * steps, cdt)
                    rot = d.ximat[sb.id].reshape(3, 3)  # the inertial frame's, about the COM
                    d.xfrc_applied[sb.id, :3] += m.body_mass[sb.id] * a
                    d.xfrc_applied[sb.id, 3:] += rot @ (m.body_inertia[sb.id] * (rot.T @ alpha))
        if held:
            self._overlaps_cleared = False
            for sb in held.values():
                g = sb.gravity if sb.gravity is not None else np.asarray(self.gravity, float)
                d.xfrc_applied[sb.id, :3] -= m.body_mass[sb.id] * g
            self._xfrc_dirty = True

    def _viscous(self, g: MjGhost, found) -> None:
        """F = -K·(v_body - v_phantom) on every body inside a hole ghost (held for a control
        step as the exact exp(-K·t/m) decay, as in the PyBullet runner)."""
        k = self.opt.hole_friction
        cdt = self.dt * self.opt.control_substeps
        v_ref = self._com_velocity(g.parent) if g.parent is not None and not g.parent.static else 0.0
        xf = self.data.xfrc_applied
        for sb in found:
            xf[sb.id, :3] += viscous_impulse_force(sb.mass, self._com_velocity(sb) - v_ref, k, cdt)
        self._xfrc_dirty = True

    def _com_velocity(self, sb: MjBody) -> np.ndarray:
        v = self._vel6
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, sb.id, v, 0)
        return v[3:].copy()

    def actuate(self, actuator: MjActuator, target: MjBody) -> None:
        """Weld ``target`` to the actuator's parent at their current relative pose; the links of
        the parent's arm stop colliding with it meanwhile (the closed jaws would push the held
        body out), and only with it, as in the PyBullet runner: they still collide with the tissue."""
        self.release(actuator)
        m, d = self.model, self.data
        e = actuator.eq
        a, b = actuator.parent.id, target.id
        ta = pose_matrix(d.xpos[a], _xyzw(d.xquat[a]))
        tb = pose_matrix(d.xpos[b], _xyzw(d.xquat[b]))
        rel = invert(ta) @ tb
        q = matrix_to_quat(rel[:3, :3])
        m.eq_obj2id[e] = b
        m.eq_data[e, :3] = 0.0  # anchor: body2's origin
        m.eq_data[e, 3:6] = rel[:3, 3]
        m.eq_data[e, 6:10] = (q[3], q[0], q[1], q[2])
        m.eq_data[e, 10] = 1.0
        d.eq_active[e] = 1
        self.wake(target)
        actuator.target = target
        art = actuator.parent.articulation
        links = [r[3] for r in art.records] + [art.root] if art is not None else [actuator.parent]
        actuator.constraint = []  # the pairs this grasp turned off (restored on release)
        for sb in links:
            if sb.has_collision and self._pair_enabled(sb, target):
                self.set_collision(sb, target, False)
                actuator.constraint.append(sb)

    def _pair_enabled(self, a: MjBody, b: MjBody) -> bool:
        lo, hi = sorted((int(a.id), int(b.id)))
        return ((lo << 16) + hi) not in self.model.exclude_signature[: self.model.nexclude]

    def ghost_pose(self, g: MjGhost) -> np.ndarray:
        """World pose (4x4) of a ghost's frame, following its parent."""
        loc = g.pose_in_parent if g.pose_in_parent is not None else np.eye(4)
        return g.parent.world_matrix() @ loc if g.parent is not None else np.array(loc)

    def set_collision(self, a: MjBody, b: MjBody, enabled: bool) -> None:
        """Let two bodies collide or pass through each other, as SimWorld.set_collision: an
        excluded body pair written into one of the spare slots the build reserved."""
        m = self.model
        lo, hi = sorted((int(a.id), int(b.id)))
        sig = (lo << 16) + hi
        sigs = np.array(m.exclude_signature[: m.nexclude])
        if enabled:
            if sig not in self._runtime_excludes:
                return
            self._runtime_excludes.discard(sig)
            sigs[np.flatnonzero(sigs == sig)[0]] = 0
        else:
            if sig in sigs or lo == hi:
                return
            free = np.flatnonzero(sigs == 0)
            if not free.size:
                self._warn(
                    "runner-collision-pairs",
                    f"more than {EXCLUDE_SPARE} body pairs turned off at run time; {a.key} and {b.key} keep colliding",
                    None,
                )
                return
            sigs[free[0]] = sig
            self._runtime_excludes.add(sig)
        m.exclude_signature[: m.nexclude] = np.sort(sigs)

    def wake(self, sb: MjBody) -> None:
        """Wake the sleeping tree of ``sb`` (MuJoCo wakes a tree a force is applied to: a
        1e-12 N force at the COM for one control step does it and nothing else)."""
        if self.sleep and sb.id > 0:
            self.data.xfrc_applied[sb.id, 2] += WAKE_FORCE
            self._xfrc_dirty = True

    def release(self, actuator: MjActuator) -> None:
        if actuator.target is not None:
            self.wake(actuator.target)
            self.data.eq_active[actuator.eq] = 0
            for sb in actuator.constraint or ():
                self.set_collision(sb, actuator.target, True)
        actuator.target, actuator.constraint = None, None

    def contacts_among(self, bodies) -> list:
        """As World.contacts_among, from the step's contact table."""
        b1, b2, f, pos = self._contact_table()
        mine = {sb.id: sb for sb in bodies}
        ids = np.fromiter(mine, dtype=b1.dtype, count=len(mine))
        out = []
        for i in np.flatnonzero(np.isin(b1, ids) | np.isin(b2, ids)):
            for a, b in ((int(b1[i]), int(b2[i])), (int(b2[i]), int(b1[i]))):
                sb = mine.get(a)
                other = self._body_of_id.get(b) if sb is not None else None
                if other is not None and other is not sb:
                    out.append((sb, other, float(f[i]), tuple(float(v) for v in pos[i])))
        return out

    def contacts(self, sb: MjBody) -> list:
        """[(other MjBody, normal force N, world point)] of the contacts ``sb`` has after the last step."""
        b1, b2, f, pos = self._contact_table()
        out = []
        for i in np.flatnonzero((b1 == sb.id) | (b2 == sb.id)):
            other = self._body_of_id.get(int(b2[i] if b1[i] == sb.id else b1[i]))
            if other is None or other is sb:
                continue
            out.append((other, float(f[i]), tuple(float(v) for v in pos[i])))
        return out

    def _contact_table(self) -> tuple:
        """Every contact of the last step as arrays (body 1, body 2, normal force, point), made
        once a step: the task and the observer ask for a dozen bodies' contacts every control
        step, and a loop over MuJoCo's contacts for each cost 1-2 ms. With elliptic cones a
        contact's normal force is its first constraint row's (what mj_contactForce returns);
        an excluded contact has none."""
        m, d = self.model, self.data
        key = (self.steps, d.ncon, d.nefc)
        if self._contacts_key == key:
            return self._contacts
        n = d.ncon
        if n == 0:
            z = np.zeros(0)
            table = (z.astype(int), z.astype(int), z, np.zeros((0, 3)))
        else:
            c = d.contact
            b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
            adr = np.array(c.efc_address)
            if m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC:
                f = np.where(adr >= 0, d.efc_force[np.maximum(adr, 0)], 0.0)
            else:
                f6 = np.zeros(6)
                f = np.zeros(n)
                for i in range(n):
                    mujoco.mj_contactForce(m, d, i, f6)
                    f[i] = f6[0]
            table = (b1, b2, np.abs(f), np.array(c.pos))
        self._contacts, self._contacts_key = table, key
        return table
