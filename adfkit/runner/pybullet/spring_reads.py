"""How SpringSet (spring_forces.py) reads its bodies' states and hands PyBullet their torques and forces:
the free bodies' base states and their pushes in one C call each where state_calls.py can build it
(the same requests of the same server: the same numbers), else PyBullet's Python calls; the links of
a multibody with one getLinkStates each."""

from __future__ import annotations

from collections import deque
from itertools import chain, repeat

import numpy as np
import pybullet as pb

from ..rotations import quat_to_matrix
from . import spring_c
from .state_calls import for_client as state_calls_for


class SpringReads:
    """SpringSet's reads and pushes (a mixin: it uses the set's bodies, cid, dynamic and pushed)."""

    @property
    def pq(self) -> dict[tuple, tuple]:
        """{(uid, -1): (position, quaternion)} of each free body as last read (states()); made when
        asked (the ghosts ask once a control step, the springs read at every physics step)."""
        self._rows_to_tuples()
        return dict(zip(self._base_keys, self._poses)) if self._poses else {}

    def last_state(self, key: tuple[int, int]) -> tuple | None:
        """(position, quaternion, linear velocity, angular velocity) of free body ``key`` (uid, -1) as
        states() last read it, as SimBody.state() gives them; None for a body it does not read."""
        i = self._base_index.get(key)
        if i is None:
            return None
        self._rows_to_tuples()
        return None if not self._poses else self._poses[i] + self._vels[i]

    def _rows_to_tuples(self) -> None:
        """The C read's rows as the Python calls give them (tuples of the same floats), made when
        asked: the ghosts ask once a control step, the springs read at every physics step."""
        if self._bases_read is None:
            return
        rows = self._bases_read.tolist()
        self._bases_read = None
        self._poses = [(tuple(r[0:3]), tuple(r[3:7])) for r in rows]
        self._vels = [(tuple(r[7:10]), tuple(r[10:13])) for r in rows]

    def _read_plan(self):
        """How to read every body's COM state with the fewest PyBullet calls: free bodies and
        multibody bases one by one (PyBullet has no batch call for them), the links of each
        multibody with one getLinkStates. Built on first use (bodies have their uids then)."""
        bases, links = [], {}
        for i, b in enumerate(self.bodies):
            if b.link < 0:
                bases.append((i, b.uid))
            else:
                links.setdefault(b.uid, []).append((i, b.link))
        order = [i for i, _ in bases] + [i for group in links.values() for i, _ in group]
        self._bases = [uid for _, uid in bases]
        self._base_keys = [(uid, -1) for uid in self._bases]
        self._base_index = {key: i for i, key in enumerate(self._base_keys)}
        self._links = [(uid, [k for _, k in group]) for uid, group in links.items()]
        self._order = np.argsort(np.array(order, dtype=int))  # read order -> body order
        self._in_order = bool(np.array_equal(self._order, np.arange(len(order))))
        # the dynamic bodies' uids and links (each gets a torque), and the pushed ones' (a force too)
        dyn, pushed = [self.bodies[i] for i in self.dynamic], self.dynamic[self.pushed[self.dynamic]]
        self._twisted = ([b.uid for b in dyn], [b.link for b in dyn])
        self._pushed = (pushed, [self.bodies[i].uid for i in pushed], [self.bodies[i].link for i in pushed])
        calls = state_calls_for(self.cid) if self._bases else None
        if calls is not None:
            self._read_c = calls.reader(self._bases)
            self._apply_c = calls.applier(*self._twisted, *self._pushed[1:])
            if spring_c.playable(self):
                self._c_springs = spring_c.CSprings(calls.lib, calls.client, self)

    def _c_read(self):
        """The free bodies' states read in C (spring_c.py's path), kept for ``pq`` and last_state."""
        a = self._bases_read = self._read_c()
        return a

    def states(self):
        """(positions, rotation matrices, linear and angular velocities) of every body's COM;
        the free bodies' (position, quaternion) stay for ``pq`` until the next read."""
        if self._order is None:
            self._read_plan()
        cid = self.cid
        get_links = pb.getLinkStates
        if self._read_c is not None:  # the same requests in one C call (state_calls.py)
            a = self._bases_read = self._read_c()
            rows = []
        else:
            bases = self._bases
            get_pose, get_vel = pb.getBasePositionAndOrientation, pb.getBaseVelocity
            poses = [get_pose(uid, cid) for uid in bases]
            vels = [get_vel(uid, cid) for uid in bases]
            rows = [p + q + v + w for (p, q), (v, w) in zip(poses, vels)]
            self._poses, self._vels = poses, vels
            a = None
        for uid, ks in self._links:  # computeLinkVelocity, computeForwardKinematics
            rows += [s[0] + s[1] + s[6] + s[7] for s in get_links(uid, ks, 1, 1, cid)]
        if rows:
            b = np.fromiter(chain.from_iterable(rows), float, 13 * len(rows)).reshape(-1, 13)
            a = b if a is None else np.concatenate((a, b))
        if not self._in_order:
            a = a[self._order]
        return (a[:, 0:3], quat_to_matrix(a[:, 3:7]), a[:, 7:10], a[:, 10:13])

    def _push(self, torque, force, pos) -> None:
        """Each dynamic body's ``torque`` (world frame), then, ``force`` not None, each pushed body's force
        at its centre of mass ``pos``."""
        # each body's torque, then each pushed body's force at its centre of mass (whose moment
        # PyBullet adds to the torque after it, as one body's calls in turn did), looped in C
        if self._read_c is not None:  # the same commands in one C call (state_calls.py)
            at = self._pushed[0]
            if force is None:
                self._apply_c(torque[self.dynamic], None, None)
            else:
                self._apply_c(torque[self.dynamic], force[at], pos[at])
            return
        cid, frame = self.cid, pb.WORLD_FRAME
        uids, links = self._twisted
        deque(map(pb.applyExternalTorque, uids, links, torque[self.dynamic].tolist(), repeat(frame), repeat(cid)), 0)
        if force is not None:
            at, uids, links = self._pushed
            forces, coms = force[at].tolist(), pos[at].tolist()
            deque(map(pb.applyExternalForce, uids, links, forces, coms, repeat(frame), repeat(cid)), 0)
