"""AMBF's ghost rule in the MuJoCo world (Options.ghosts "ambf": adfkit run / parity), the
AmbfGhosts half of Interaction: which bodies penetrate each ghost and at how many contact points
(MuJoCo's geom distance and collider), what the rule does to them each control step, and what is
kept between control steps so that a scene at rest costs little (docs/speed.md)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..ghost_rules import AMBF_GHOST_KEEP, MANIFOLD_POINTS, SAME_PLACE
from ..plan import ALL_GROUPS
from .chain import chain_stepped_ids
from .ghost_rigid import rigid_points
from .ghost_steps import MjGhostSteps, com_velocities
from .objects import MjBody

_SLEEP_BIT = int(getattr(mujoco.mjtEnableBit, "mjENBL_SLEEP", 0))
#: sets of colliding ghost pairs whose pass masks (_collider_masks) are kept at most
COLLIDER_MASKS_KEPT = 64


@dataclass
class _GhostPlan:
    """What AMBF's ghost rule does each control step while the ghosts' answers and the bodies'
    sleep states stay (Interaction._plan_ghosts)."""

    key: bytes  # the bodies' sleep states it was made for
    overlapping: dict  # each ghost's (by id) bodies in it
    ids: np.ndarray  # the bodies acted on, one per (ghost, body), in AMBF's order
    both: np.ndarray  # those bodies, then each one's moving ghost parent (itself where none)
    has_parent: np.ndarray  # (n, 1): a moving ghost parent whose velocity it takes
    keep: np.ndarray  # AMBF_GHOST_KEEP^(points·physics steps)
    free: list  # (index, first dof, body id) of the free bodies: velocities set
    jointed: np.ndarray  # indices of the others: force and torque
    jointed_ids: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    weight_ids: np.ndarray  # held bodies whose weight (or a gravity of their own) is taken off as a force
    weights: np.ndarray  # (n, 3) that weight, m·g


class AmbfGhosts:
    def _penetrating(self, ghosts) -> list[list[tuple[MjBody, int]]]:
        """For each ghost, each dynamic body in penetrating contact with it (its parent too: AMBF's
        ghosts sense the body they hang on), with its contact points: for each of its geoms that
        penetrates one of the ghost's (MuJoCo's exact geom distance below 0; bounding spheres
        first, every ghost geom against every candidate in one array), the points MuJoCo's
        collider makes for the pair (_collider_points), at most MANIFOLD_POINTS (a Bullet
        manifold's: AMBF's ghost acts once per point of it) and at least one.

        A ghost geom and a geom of its own body are one rigid pair, looked at once (_ghost_rows);
        the other pairs' distances are taken again only when one of their bodies moved
        (_pair_distances); the ghosts' answers are made again only for a ghost whose pairs or
        points changed."""
        cg = self._cand_geoms
        if not len(cg) or not ghosts:
            return [[] for _ in ghosts]
        gg, starts = self._ghost_rows()
        gx = self.data.geom_xpos
        diff = gx[gg][:, None, :] - gx[cg][None, :, :]
        near = np.einsum("ijk,ijk->ij", diff, diff) <= self._ghost_reach
        near &= self._ghost_cross
        rows, ks = np.nonzero(near)
        hit, flipped = self._pair_distances(rows, ks)
        if self._ghost_near is None:
            dirty = np.ones(len(gg), dtype=bool)
        else:
            dirty = (near != self._ghost_near).any(axis=1)
            dirty[rows[flipped]] = True
        self._ghost_near = near
        rows, ks = rows[hit], ks[hit]
        # only pairs of two bodies can have the collider's points (MuJoCo collides no body with itself)
        made = self._collider_points(rows, ks)
        if made != self._ghost_made:
            dirty[rows] = True
            self._ghost_made = made
        answers = self._ghost_answers
        remade = np.flatnonzero(np.logical_or.reduceat(dirty, starts))
        self._ghost_changed = len(remade) > 0
        if self._ghost_changed:
            rigid_rows, rigid_ks = self._rigid_hits
            rows, ks = np.concatenate([rigid_rows, rows]), np.concatenate([rigid_ks, ks])
        for i in remade:
            mine = (rows >= starts[i]) & (rows < starts[i] + len(ghosts[i].geoms))
            r, k = rows[mine], ks[mine]
            order = np.lexsort((r, k))  # the candidates in turn, each against the ghost's geoms
            points: dict[int, list] = {}
            boxes = self._geom_is_box
            for a, c, kk in zip(gg[r[order]].tolist(), cg[k[order]].tolist(), k[order].tolist()):
                pair = (min(a, c), max(a, c))
                n = min(max(made.get(pair, 0) or self._rigid_made.get(pair, 0), 1), MANIFOLD_POINTS)
                if not (boxes[a] and boxes[c]):  # Bullet's GJK: one point a pass (ghost_rigid.py)
                    n = 1
                sb = self._cand_geom_body[kk]
                points.setdefault(id(sb), [sb, 0])[1] += n
            answers[i] = [(sb, n) for sb, n in points.values()]
        return answers

    def _pair_distances(self, rows: np.ndarray, ks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(penetrating, changed since it was last taken) for the pairs of two bodies (ghost geom
        ``rows``, candidate geom ``ks``). MuJoCo's distance is taken again only for a pair one
        of whose bodies is not where it was, to the last bit, when the pair's was last taken
        (asleep, static and resting bodies keep theirs): each body's pose is compared with the
        one the last call saw (one array test for all of them), and the call at which it last
        moved is kept."""
        m, d = self.model, self.data
        self._ghost_tick += 1
        tick = self._ghost_tick
        pose = np.hstack((d.xpos, d.xquat))
        self._moved_at[(pose != self._last_pose).any(axis=1)] = tick
        self._last_pose = pose
        moved = self._moved_at
        taken = self._pair_at[rows, ks]
        stale = (taken < moved[self._ghost_geom_body[rows]]) | (taken < moved[self._cand_geom_bodyid[ks]])
        dist = self._pair_dist[rows, ks]
        was = dist < 0.0
        if stale.any():
            r, k = rows[stale], ks[stale]
            ga, gb = self._ghost_row_of[0][r].tolist(), self._cand_geoms[k].tolist()
            dist[stale] = [mujoco.mj_geomDistance(m, d, a, b, 0.0, None) for a, b in zip(ga, gb)]
            self._pair_dist[r, k] = dist[stale]
            self._pair_at[r, k] = tick
        hit = dist < 0.0
        return hit, hit != was

    def _ghost_rows(self) -> tuple[np.ndarray, np.ndarray]:
        """Every ghost's geoms one after the other and where each ghost's begin (made once; a
        ghost has one geom at least); with them what _penetrating keeps: the squared reach of
        each (ghost geom, candidate geom) pair, which pairs are of two bodies, the rigid pairs
        (a ghost geom and a geom of its own body) that penetrate, the bodies of the ghost
        geoms, each pair's last distance and the call it was taken at, each ghost's last
        answer."""
        if self._ghost_row_of is None:
            m, d = self.model, self.data
            cg = self._cand_geoms
            gg = np.array([gid for g in self.ghosts for gid in g.geoms], dtype=int)
            starts = np.cumsum([0] + [len(g.geoms) for g in self.ghosts[:-1]]).astype(int)
            self._ghost_reach = (m.geom_rbound[gg][:, None] + m.geom_rbound[cg][None, :]) ** 2
            self._ghost_geom_body = np.array(m.geom_bodyid[gg], dtype=int)
            self._ghost_cross = self._ghost_geom_body[:, None] != self._cand_geom_bodyid[None, :]
            # a rigid pair's distance never changes: taken once, where the bounding spheres meet
            diff = d.geom_xpos[gg][:, None, :] - d.geom_xpos[cg][None, :, :]
            rigid = (np.einsum("ijk,ijk->ij", diff, diff) <= self._ghost_reach) & ~self._ghost_cross
            pairs = [
                (r, k)
                for r, k in zip(*np.nonzero(rigid))
                if mujoco.mj_geomDistance(m, d, int(gg[r]), int(cg[k]), 0.0, None) < 0.0
            ]
            self._rigid_hits = tuple(np.array([p[i] for p in pairs], dtype=int) for i in (0, 1))
            self._geom_is_box = np.asarray(m.geom_type) == mujoco.mjtGeom.mjGEOM_BOX
            self._rigid_made = rigid_points(m, d, [(int(gg[r]), int(cg[k])) for r, k in pairs])  # ghost_rigid.py
            self._is_ghost_geom = np.zeros(m.ngeom, dtype=bool)
            self._is_ghost_geom[gg] = True
            self._pair_dist = np.full((len(gg), len(cg)), np.nan)
            self._pair_at = np.full((len(gg), len(cg)), -1, dtype=int)
            self._ghost_tick = 0
            self._moved_at = np.zeros(m.nbody, dtype=int)
            self._last_pose = np.full((m.nbody, 7), np.nan)
            # each body's free joint's first dof, -1 for a body without one (set_body_velocity's test)
            self._free_dof = np.full(m.nbody, -1, dtype=int)
            for j in np.flatnonzero(m.jnt_type == mujoco.mjtJoint.mjJNT_FREE):
                self._free_dof[m.jnt_bodyid[j]] = m.jnt_dofadr[j]
            self._ghost_near, self._ghost_made = None, None
            self._ghost_answers: list = [[] for _ in self.ghosts]
            self._collider_pairs: dict = {}
            self._ghost_row_of = (gg, starts)
        return self._ghost_row_of

    def _collider_points(self, rows: np.ndarray, ks: np.ndarray) -> dict[tuple[int, int], int]:
        """{(geom, geom): penetrating contacts} that MuJoCo's collision pass makes between the
        ghost geoms ``rows`` and the candidate geoms ``ks`` (pairs of two bodies), the ghosts let
        collide for that pass only (mj_collision between control steps; the step's own pass,
        which they do not join, writes the contacts the solver and every reader see). A box in a
        box gives several, as Bullet's box-box manifold does. A ghost's geom never meets its
        own body's (MuJoCo collides no body with itself, nor with its parent): those pairs keep
        the distance query's one point. The last answer stands while the pairs' geoms stay
        within SAME_PLACE of where they were (a resting body inside a ghost, the phantom's holes,
        jaws held still with round-off's 1e-16 m jitter: no pass)."""
        if not len(rows):
            return {}
        m, d = self.model, self.data
        key = rows.tobytes() + ks.tobytes()
        masks = self._collider_pairs.get(key)
        if masks is None:
            if len(self._collider_pairs) >= COLLIDER_MASKS_KEPT:
                self._collider_pairs.clear()
            masks = self._collider_pairs[key] = self._collider_masks(rows, ks)
        geoms = masks[0]
        where = np.concatenate((d.geom_xpos[geoms].ravel(), d.geom_xmat[geoms].ravel()))
        last = self._collider_key
        if last is not None and last[0] is geoms and np.max(np.abs(last[1] - where)) <= SAME_PLACE:
            return self._collider_made
        # the pass collides only the geoms of the pairs (_collider_masks); with island sleeping
        # on, MuJoCo collides no pair without an awake body: a body asleep in a ghost on a static
        # one (a cube come to rest in it, weightless) keeps its points
        live = (m.geom_contype, m.geom_conaffinity, m.body_contype, m.body_conaffinity)
        saved = [np.array(x) for x in live]
        for x, y in zip(live, masks[1:]):
            x[:] = y
        flags = m.opt.enableflags
        m.opt.enableflags = flags & ~_SLEEP_BIT
        try:
            mujoco.mj_collision(m, d)
        finally:
            m.opt.enableflags = flags
            for x, y in zip(live, saved):
                x[:] = y
        out: dict[tuple[int, int], int] = {}
        if d.ncon:
            c = d.contact
            ab = np.sort(c.geom, axis=1)
            is_ghost = self._is_ghost_geom[ab]
            keep = (c.dist < 0.0) & (is_ghost[:, 0] != is_ghost[:, 1])
            for a, b in ab[keep].tolist():
                out[(a, b)] = out.get((a, b), 0) + 1
        self._collider_key, self._collider_made = (geoms, where), out
        return out

    def _collider_masks(self, rows: np.ndarray, ks: np.ndarray) -> tuple:
        """(the geoms of the pairs (ghost geom ``rows``, candidate geom ``ks``), and the geoms'
        contype and conaffinity and the bodies' for _collider_points' pass): every other geom's
        and body's bits off (those of a pair's body geom kept; its ghost geom, whose contype
        (build.GHOST_CONTYPE) meets no conaffinity, given every one), as the whole scene's pass
        would collide those pairs (MuJoCo makes a pair's contacts from its two geoms alone)."""
        m = self.model
        ghost_side = np.unique(self._ghost_row_of[0][rows])
        body_side = np.unique(self._cand_geoms[ks])
        geoms = np.union1d(ghost_side, body_side)
        masks = [np.zeros_like(x) for x in (m.geom_contype, m.geom_conaffinity, m.body_contype, m.body_conaffinity)]
        masks[0][body_side] = m.geom_contype[body_side]
        masks[1][ghost_side] = ALL_GROUPS
        masks[2][m.geom_bodyid[body_side]] = m.body_contype[m.geom_bodyid[body_side]]
        masks[3][m.geom_bodyid[ghost_side]] = ALL_GROUPS  # the broadphase filters bodies first
        return (geoms, *masks)

    def _ambf_ghosts(self) -> None:
        """AMBF's ghost objects (ghost_rules: afGhostObject::update after each physics step), for
        this control step's physics steps: every body in penetrating contact keeps
        AMBF_GHOST_KEEP per contact and step of its velocity across the ghost parent's (a free
        body's is set; a jointed one is given the force at its centre of mass and the torque that
        take it there over the control step, as in the PyBullet runner) and is weightless until
        the next control step. What the rule does is planned again only when a ghost's answer or
        a body's sleep state changes (_plan_ghosts)."""
        if not self.ghosts or not len(self._cand_geoms):
            return  # nothing a ghost could hold
        now = answers = self._penetrating(self.ghosts)
        changed, first = self._ghost_changed, not self._ghosts_passed
        self._ghosts_passed = True
        if first:  # nothing before the first step for a ghost with a parent (pybullet/ghost_steps.first_points)
            answers, changed = [[] if g.parent is not None else a for g, a in zip(self.ghosts, answers)], True
        if self.opt.control_substeps == 1:  # AMBF acts with the points its last step's pass found
            before, self._ghost_before = self._ghost_before, (list(answers), changed, first)
            answers, changed, first = before if before is not None else ([[] for _ in self.ghosts], True, True)
        key = self._body_awake.tobytes() if self.sleep else b""
        plan = self._ghost_plan
        if plan is None or changed or key != plan.key:
            plan = self._ghost_plan = self._plan_ghosts(answers, key)
        if first:
            self._ghost_plan = None  # planned on the first step's answers: the next control step plans afresh
        steps = self._ghost_steps
        if steps is None and self.opt.control_substeps > 1:
            steps = self._ghost_steps = MjGhostSteps(self)
        fine = np.zeros(0, dtype=int)  # free bodies the rule acts on a physics step at a time (ghost_steps.py)
        if steps is not None and steps.decide():
            fine = steps.free_of(answers)
            steps.begin(answers, fine)
        elif steps is not None:
            steps.before = list(answers)
        for g, found in zip(self.ghosts, now):  # what each ghost holds now (overlapping() may have written its own)
            g.overlapping = plan.overlapping[id(g)] if now is answers else [sb for sb, _ in found]
            g.points = found
        stepped = chain_stepped_ids(self)  # AMBF's solver on a chain holds its bodies' ghosts (chain_ghosts)
        stepped = np.union1d(stepped, fine) if len(fine) else stepped
        if len(plan.ids):
            self._ghost_velocities(plan, stepped)
        if len(plan.weight_ids):  # the weight taken off as a force: AMBF's gravity off
            kept = ~np.isin(plan.weight_ids, stepped) if len(stepped) else slice(None)
            self.data.xfrc_applied[plan.weight_ids[kept], :3] -= plan.weights[kept]
            self._xfrc_dirty = True

    def _plan_ghosts(self, answers, key: bytes) -> _GhostPlan:
        """What AMBF's ghost rule does while the ghosts' answers and the bodies' sleep states stay
        as they are now: the ghosts' overlapping bodies; the bodies acted on, in the order AMBF's
        updates come, each with the ghost parent whose velocity it takes (a moving one) and its
        share kept; the held bodies weightless. A body asleep in a ghost whose parent does not
        move is at rest (velocity 0, which the rule keeps 0) and left out; one asleep in a moving
        ghost is woken."""
        m = self.model
        awake, AWAKE = self._body_awake, self._AWAKE
        held: dict[int, MjBody] = {}
        acts = []  # (moving ghost parent or None, body, points)
        overlapping = {}
        for g, found in zip(self.ghosts, answers):
            overlapping[id(g)] = [sb for sb, _ in found]
            moving = g.parent is not None and not g.parent.static and awake[g.parent.id] == AWAKE
            for sb, points in found:
                held[id(sb)] = sb
                if moving or awake[sb.id] == AWAKE:
                    acts.append((g.parent if moving else None, sb, points))
                    if self.sleep and awake[sb.id] != AWAKE:
                        self.wake(sb)  # asleep in a moving ghost: it is moved again
        # a tree that may sleep is held weightless by MuJoCo's gravity compensation (a gravity of
        # its own, which the base forces give it, taken off as a force besides); one that never
        # sleeps (driven) by the force -m·g, as before the compensation was used
        sleeps = [sb for sb in held.values() if self._may_sleep(sb)]
        now = {sb.id for sb in sleeps}
        for i in self._weightless_ids - now:
            m.body_gravcomp[i] = 0.0
            sb = self._body_of_id.get(i)
            if sb is not None:
                self.wake(sb)
        for i in now:
            m.body_gravcomp[i] = 1.0
        self._weightless_ids = now
        g_world = np.asarray(self.gravity, float)
        weights = []
        for sb in held.values():
            if sb.id not in now:
                weights.append((sb.id, m.body_mass[sb.id] * (sb.gravity if sb.gravity is not None else g_world)))
            elif sb.gravity is not None:
                weights.append((sb.id, m.body_mass[sb.id] * (sb.gravity - g_world)))
        if held:
            self._overlaps_cleared = False
        ids = np.array([sb.id for _, sb, _ in acts], dtype=int)
        pids = np.array([p.id if p is not None else -1 for p, _, _ in acts], dtype=int)
        dof = self._free_dof[ids]
        jointed = ids[dof < 0]
        return _GhostPlan(
            key=key,
            overlapping=overlapping,
            ids=ids,
            both=np.concatenate([ids, np.where(pids >= 0, pids, ids)]),
            has_parent=(pids >= 0)[:, None],
            # (Python's power, not numpy's, which can differ in the last bit)
            keep=np.array([AMBF_GHOST_KEEP ** (n * self.opt.control_substeps) for _, _, n in acts], dtype=float),
            free=[(i, int(dof[i]), int(ids[i])) for i in np.flatnonzero(dof >= 0)],
            jointed=np.flatnonzero(dof < 0),
            jointed_ids=jointed,
            mass=np.array(m.body_mass[jointed])[:, None],
            inertia=np.array(m.body_inertia[jointed]),
            weight_ids=np.array([i for i, _ in weights], dtype=int),
            weights=np.array([f for _, f in weights], dtype=float).reshape(-1, 3),
        )

    def _may_sleep(self, sb: MjBody) -> bool:
        """Whether MuJoCo may put the tree of ``sb`` to sleep (a driven tree never sleeps)."""
        m = self.model
        never = (int(mujoco.mjtSleepPolicy.mjSLEEP_NEVER), int(mujoco.mjtSleepPolicy.mjSLEEP_AUTO_NEVER))
        return self.sleep and int(m.tree_sleep_policy[m.body_treeid[sb.id]]) not in never

    def _ghost_velocities(self, plan: _GhostPlan, stepped: np.ndarray) -> None:
        """AMBF's ghost rule on the bodies of ``plan``, all from the velocities at this control
        step's start (mj_step left those of its last physics step's start): free bodies'
        velocities set (the last ghost's stands), the others' forces and torques that take them
        there over the control step added to xfrc_applied."""
        m, d = self.model, self.data
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        n = len(plan.ids)
        vel = com_velocities(d, m, plan.both)
        w, v = vel[:n, :3], vel[:n, 3:]
        v_par = np.where(plan.has_parent, vel[n:, 3:], 0.0)
        mag = np.sqrt(np.einsum("ij,ij->i", v_par, v_par))
        fast = mag > 1e-5
        share = np.einsum("ij,ij->i", v, v_par) / np.where(fast, mag * mag, 1.0)
        along = np.where(fast[:, None], v_par * share[:, None], 0.0)
        keep = plan.keep[:, None]
        v2 = keep * (v - along) + v_par
        w2 = keep * w
        for i, a, b in plan.free:  # in order: the last ghost's velocity stands
            if len(stepped) and b in stepped:
                continue
            d.qvel[a : a + 3] = v2[i]
            d.qvel[a + 3 : a + 6] = d.xmat[b].reshape(3, 3).T @ w2[i]  # body frame
        j = plan.jointed
        if len(j):
            cdt = self.dt * self.opt.control_substeps
            a, alpha = (v2[j] - v[j]) / cdt, (w2[j] - w[j]) / cdt
            # the torque in the inertial frame, about the COM: R (I (Rᵀ α)), each product a stacked
            # matmul (numpy's gemv body by body: the PyBullet runner's bits, which einsum's are not)
            rot = d.ximat[plan.jointed_ids].reshape(-1, 3, 3)
            local = np.matmul(rot.transpose(0, 2, 1), alpha[:, :, None])
            wrench = np.empty((len(j), 6))
            wrench[:, :3] = plan.mass * a
            wrench[:, 3:] = np.matmul(rot, plan.inertia[:, :, None] * local)[:, :, 0]
            if len(stepped):
                wrench[np.isin(plan.jointed_ids, stepped)] = 0.0
            np.add.at(d.xfrc_applied, plan.jointed_ids, wrench)  # in order: a body in two ghosts
            self._xfrc_dirty = True
