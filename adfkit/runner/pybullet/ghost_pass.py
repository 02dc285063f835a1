"""The ghosts' collision pass (interact._manifold_points) in a PyBullet world of its own.

AMBF's ghost acts once per penetrating contact point of its manifold with a body, which only
Bullet's narrowphase makes in a collision pass (a box in a box gives four points at once). Run
in the dynamics world (each ghost near a body let collide, performCollisionDetection, shut
again), the pass also went over every other pair of the scene, the thread on the phantom and the
rest, which the next step does again: on the corpus suturing set that was half of the pass. Here
the ghosts and copies of the bodies near them stand in a second PyBullet world, made on the
first pass, where only a ghost and a body can meet (their collision bits). Each pass puts them
where they are in the dynamics world and starts every ghost's pairs afresh, as the world's pass
did (changing a ghost's collision bits drops its pairs): the same shapes, margins and poses give
the same points. The dynamics world's own pass left nothing behind (replaying its counts without
it leaves every body where it was, to the bit): its other pairs' points are the step's to make.

A ghost whose pose and whose near bodies' poses are each within KEPT_WITHIN (10 µm, and 1e-5 in
each quaternion entry) of those of its last pass (the same bodies near it, no collision pair or
grasp changed since) keeps that pass's points and leaves this pass: its pairs meet nothing else
here, so the others' points are those the pass of all of them gives. The PSMs' finger links and
the phantom's hole bodies creep by 10-100 nm a control step (1.8 µm at times: the fingers), so
within 1 nm (SAME_PLACE, the MuJoCo engine's bound) a third of the ghosts' queries kept their points
on the corpus suturing set, within 10 µm 97 %; over its 10 s not one query kept within 1 nm to
0.1 mm had points a pass afresh would have counted otherwise. AMBF's ghost keeps a manifold's
point far longer: Bullet refreshes it until the bodies part by the contact breaking threshold.

A ghost or a body that cannot be copied (a volume's surface pieces, one without collision parts)
leaves the pass to the dynamics world (``counts`` returns None).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..ghost_rules import in_same_place
from ..rotations import invert, matrix_to_pq
from . import broadphase_margin, bullet_globals
from .shapes import create_collision

# the copies' collision bits: a ghost meets bodies, a body meets ghosts, never another body
BODY_BIT, GHOST_BIT = 1, 2
COPY_MASS = 1.0  # kg: a copy must be dynamic (Bullet leaves a pair of static objects alone); never stepped
#: m (and quaternion entries): a ghost and the bodies near it that moved no more than this since its
#: last pass keep that pass's points. AMBF's ghost reads the dynamics world's persistent manifolds,
#: whose points stay until they part by the contact breaking threshold (Bullet's 0.02 m); on the
#: corpus suturing set, 10 s, no ghost kept within 1e-9 to 1e-4 had counts a pass afresh would change
KEPT_WITHIN = 1e-5


class GhostPass:
    def __init__(self, world) -> None:
        self.world = world
        self.cid: int | None = None
        self.ghosts: dict[int, int | None] = {}  # ghost uid in the world -> its copy (None: cannot be)
        self.copies: dict[tuple[int, int], int | None] = {}  # (uid, link) -> its copy (None: cannot be)
        self.owner: dict[int, tuple[int, int]] = {}  # copy uid -> (uid, link) in the world
        # ghost uid in the world -> (collision pairs' epoch, near keys, poses, its counts) of its last pass
        self.last: dict[int, tuple] = {}

    def _connect(self) -> int:
        if self.cid is None:
            self.cid = pb.connect(pb.DIRECT)
            # a world made puts PyBullet's broadphase margin back for the whole process: the dynamics world's again
            broadphase_margin.use(self.world.broadphase_margin)
        return self.cid

    def _shape(self, parts) -> int:
        """The collision shape of ``parts`` in this world; -1 where PyBullet refuses it now (a
        mesh file gone since the world was built)."""
        try:
            return create_collision(parts, self._connect(), compound=self.world.opt.bodies == "ambf")
        except pb.error:
            return -1

    def _copy_ghost(self, g) -> int | None:
        if g.uid not in self.ghosts:
            col = self._shape(g.parts) if g.parts is not None else -1
            uid = None
            if col >= 0:
                uid = pb.createMultiBody(0, col, -1, useMaximalCoordinates=True, physicsClientId=self.cid)
                pb.setCollisionFilterGroupMask(uid, -1, 0, 0, physicsClientId=self.cid)
            self.ghosts[g.uid] = uid
        return self.ghosts[g.uid]

    def _copy_body(self, key: tuple[int, int], sb) -> int | None:
        """The body's copy: its collision parts, in its link's inertial frame as PyBullet puts a
        multibody link's shapes (a free body's and a base's frame is their centre of mass)."""
        if key in self.copies:
            return self.copies[key]
        uid = None
        if sb._parts is not None and (sb._parts.types or sb._parts.plane is not None) and not sb.piece_links:
            col = self._shape(sb._parts)
            if col >= 0:
                inertial = invert(sb.ref_in_body) @ sb.com_in_body if sb.link >= 0 else np.eye(4)
                ipos, iorn = matrix_to_pq(inertial)
                uid = pb.createMultiBody(
                    COPY_MASS,
                    col,
                    -1,
                    baseInertialFramePosition=ipos,
                    baseInertialFrameOrientation=iorn,
                    useMaximalCoordinates=True,
                    physicsClientId=self.cid,
                )
                pb.setCollisionFilterGroupMask(uid, -1, BODY_BIT, GHOST_BIT, physicsClientId=self.cid)
                self.owner[uid] = key
        self.copies[key] = uid
        return uid

    def counts(self, near, poses: dict) -> dict[int, dict[tuple[int, int], int]] | None:
        """{ghost uid: {(uid, link): penetrating contact points}} for ``near``, [(ghost, its pose,
        the keys of the dynamic bodies near it)], ``poses`` holding each key's (position,
        quaternion) of its centre of mass; None where a body near a ghost cannot be copied."""
        dynamic, epoch = self.world._dynamic_lookup, self.world._pairs_epoch
        placed: dict[int, tuple] = {}
        out: dict[int, dict[tuple[int, int], int]] = {}
        todo, where = [], {}
        for g, pq, keys in near:
            if self._copy_ghost(g) is None:
                return None
            for key in keys:
                if key not in placed and self._copy_body(key, dynamic[key]) is None:
                    return None
                placed[key] = poses[key]
            at = [pq] + [poses[key] for key in keys]
            last = self.last.get(g.uid)
            if last is not None and last[0] == epoch and last[1] == keys and in_same_place(last[2], at, KEPT_WITHIN):
                out[g.uid] = last[3]
            else:
                todo.append((g, pq, keys))
                where[g.uid] = at
        if not todo:
            return out
        cid = self._connect()
        reset = pb.resetBasePositionAndOrientation
        for key in {key for _g, _pq, keys in todo for key in keys}:
            p, q = placed[key]
            reset(self.copies[key], p, q, cid)
        on = []
        for g, (p, q), keys in todo:
            uid = self.ghosts[g.uid]
            reset(uid, p, q, cid)
            pb.setCollisionFilterGroupMask(uid, -1, GHOST_BIT, BODY_BIT, physicsClientId=cid)
            on.append((g, uid, keys))
        bullet_globals.use(self.world.contact_threshold, cid)  # the dynamics world's (one per process)
        pb.performCollisionDetection(physicsClientId=cid)
        for g, uid, keys in on:
            counts = out[g.uid] = {}
            self.last[g.uid] = (epoch, keys, where[g.uid], counts)
            wanted = set(keys)  # a copy left where an earlier pass put it is no body near this ghost now
            for c in pb.getContactPoints(bodyA=uid, physicsClientId=cid):
                if c[8] < 0.0:
                    key = self.owner.get(c[2] if c[1] == uid else c[1])
                    if key in wanted:
                        counts[key] = counts.get(key, 0) + 1
            pb.setCollisionFilterGroupMask(uid, -1, 0, 0, physicsClientId=cid)  # its pairs dropped
        return out

    def close(self) -> None:
        if self.cid is not None and pb.isConnected(self.cid):
            pb.disconnect(self.cid)
        self.cid = None
