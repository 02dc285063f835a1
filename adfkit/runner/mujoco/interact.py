"""What the MuJoCo world does between steps (the Interaction half of MujocoWorld): ghosts sensing
what is inside them and acting on it (the hole ghosts' viscous friction; AMBF's rule in
ghosts.py), ray sensors, the grasp's weld, collision switches at run time, contacts."""

from __future__ import annotations

import mujoco
import numpy as np

from ..ghost_rules import viscous_impulse_force
from ..rotations import invert, matrix_to_quat, pose_matrix
from .assemble import WAKE_FORCE, _xyzw
from .collision import EXCLUDE_SPARE
from .ghosts import AmbfGhosts
from .objects import MjActuator, MjBody, MjGhost, MjSensor

#: an explicit pair's margin while its bodies are kept apart: MuJoCo's bounding test never passes
PAIR_OFF = -1e9


class Interaction(AmbfGhosts):
    def _sense(self, s: MjSensor) -> None:
        m, d = self.model, self.data
        t = s.parent.world_matrix() @ s.location
        a = s.starts @ t[:3, :3].T + t[:3, 3]
        b = s.ends @ t[:3, :3].T + t[:3, 3]
        s.sensed, s.rays = [], []
        for p, q in zip(a, b):
            if not float(np.dot(q - p, q - p)) > 1e-24:  # a sensor of range 0 senses nothing (mj_ray refuses it)
                s.rays.append((None, 1.0))
                continue
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
        if m.npair:  # explicit pairs (the floor's, Bullet's frictions) heed no exclusion: kept out of reach
            b1, b2 = m.geom_bodyid[m.pair_geom1], m.geom_bodyid[m.pair_geom2]
            hit = ((b1 == lo) & (b2 == hi)) | ((b1 == hi) & (b2 == lo))
            m.pair_margin[hit] = self._pair_margins[hit] if enabled else PAIR_OFF

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
