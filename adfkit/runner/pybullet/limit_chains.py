"""AMBF's hinge and slider stops on a free multibody, played through AMBF's own solver step.

A joint nothing drives that runs into its limit bounces in AMBF as its btRigidBodies do, not as
a joint does: the hinge's limit row turns the child's spin about its own centre of mass back
(relaxation 1, bias 0.3) while its pivot rows, at the joint's erp, pull its centre back onto the
pivot over the following steps. What the joint keeps of its speed is what is left when the two
have met again (a 0.2 kg, 0.2 m rod hinged at one end, into a stop at 11.2 rad/s: 1.71 rad/s
back, about 0.15 of it, where the joint's own row, limit_rows.py, turns it back at 0.3).

So, under AMBF's bodies (Options.bodies "ambf"), a multibody whose joints are all hinges and
sliders, at least one of them limited, with nothing commanding its joints and no position motor
holding it, is handed to the chain step (runner/chain_step.py, the rows of runner/chain_rows.py)
from the physics step before one of its limited joints would cross its limit, coming in at
REST_SPEED or faster, until SETTLE physics steps after the last such step (a joint resting on
its stop is left to limit_rows.py): at each physics step every joint's motor is driven at the
velocity AMBF's solver leaves it at (its PyBullet limits opened meanwhile). The world steps physics steps one by one when there is
such a multibody (world.py), as it does for AMBF's springs.

Not for a multibody with a loop the chain step would close (a hinge or point joining two of its
links): the corpus parallel structure, a four-bar swinging down onto a stop, went 7.9 -> 10.7 mm
from AMBF's (0.84 -> 3.1 mm at the end; not explained: driving only its limited joints at the
chain step's velocities, its loop left to PyBullet, gave the same). Nor do AMBF's ghosts act on its links in the chain step while it
plays them (the links' ghost forces are the control step's, which the motors override)."""

from __future__ import annotations

import pybullet as pb

from ...model.semantics import JointKind
from ..joint_commands import LIMIT_FORCE, limits_of

#: physics steps a bounce is played on for after its joints last came in fast: the pivot rows
#: close what is apart by the joint's erp (0.1) a step, to 0.5 % in 50
SETTLE = 50
#: a joint moving slower than this (rad/s or m/s) rests on its stop, which limit_rows.py holds
#: as AMBF's row does: only what comes in faster bounces
REST_SPEED = 0.05
#: how far out a joint's PyBullet limits are opened while the chain step plays it (rad or m)
OPEN = 1e3


class LimitChains:
    def __init__(self, world) -> None:
        self.world = world
        self.arts: list[tuple] = []  # (articulation, [(record index, limits)] of its limited joints)
        self.engaged: dict[int, int] = {}  # id(art) -> the physics step it last came in fast at
        self.step = 0  # physics steps played, for the chain step's own count
        if world.opt.bodies != "ambf" or world.chain_model is None:
            return
        for art in world.articulations:
            if not all(k in (JointKind.REVOLUTE, JointKind.PRISMATIC) for k in art.kinds):
                continue
            limited = []
            for n, rec in enumerate(art.records):
                lim = limits_of(rec[0])
                if lim is not None and lim[0] < lim[1]:
                    limited.append((n, lim))
            if limited:
                self.arts.append((art, limited))

    def __bool__(self) -> bool:
        return bool(self.arts)

    def _commanded(self, art) -> set[int]:
        """The joints of ``art`` a command or a holding position motor drives."""
        if art.held:
            return set(range(len(art.records)))
        commanded = self.world.limit_rows.commanded
        return {n for n in range(len(art.records)) if (art.uid, n) in commanded}

    def _free(self, art) -> bool:
        return not self._commanded(art)

    def playing(self, art) -> bool:
        """Whether the chain step plays ``art``'s joints now (limit_rows.py leaves them alone)."""
        return id(art) in self.engaged

    def before_step(self) -> None:
        """Before each physics step: hand each free multibody near a stop to the chain step, drive
        the joints of those it plays at its velocities, give back those whose bounce is over."""
        w, cid, dt = self.world, self.world.cid, self.world.dt
        self.step += 1
        for art, limited in self.arts:
            key = id(art)
            if not self._free(art):
                if key in self.engaged:  # the commanded joints' motors are the commands' now
                    self._give_back(art, limited, keep=self._commanded(art))
                continue
            idx = list(range(len(art.records)))
            states = pb.getJointStates(art.uid, idx, physicsClientId=cid)
            near = False
            for n, (lo, hi) in limited:
                q, v = states[n][0], states[n][1]
                ahead = q + 2.0 * v * dt  # where it is a step after the next: the solver sees it past
                if abs(v) >= REST_SPEED and not (lo <= q <= hi and lo <= ahead <= hi):
                    near = True
                    break
            if key not in self.engaged:
                if not near:
                    continue
                model = w.chain_of(art)
                if model is None or model.loops:  # a loop the chain step closes: measured worse (above)
                    self.arts = [(a, lim) for a, lim in self.arts if a is not art]
                    continue
                self._take(art, limited)
            if near:
                self.engaged[key] = self.step
            if self.step - self.engaged[key] > SETTLE:
                self._give_back(art, limited)
                continue
            qd = w.chain_of(art).velocities({}, {}, self.step)
            pb.setJointMotorControlArray(
                art.uid,
                idx,
                pb.VELOCITY_CONTROL,
                targetVelocities=[float(x) for x in qd],
                forces=[LIMIT_FORCE] * len(idx),
                physicsClientId=cid,
            )

    def reset(self) -> None:
        """The world put back to a snapshot: every multibody given back, what the chain step
        carried from step to step dropped (its next step is not this one's successor)."""
        for art, limited in self.arts:
            if id(art) in self.engaged:
                self._give_back(art, limited)
        self.step += 2

    def _take(self, art, limited) -> None:
        rows = self.world.limit_rows
        for n in range(len(art.records)):
            rows.release(art, n)
        for n, (lo, hi) in limited:
            pb.changeDynamics(
                art.uid, n, jointLowerLimit=lo - OPEN, jointUpperLimit=hi + OPEN, physicsClientId=self.world.cid
            )
        self.engaged[id(art)] = self.step

    def _give_back(self, art, limited, keep: set[int] | None = None) -> None:
        """The joints' own limits back, and their motors off but those of ``keep`` (driven by
        commands since)."""
        cid = self.world.cid
        for n, (lo, hi) in limited:
            pb.changeDynamics(art.uid, n, jointLowerLimit=lo, jointUpperLimit=hi, physicsClientId=cid)
        idx = [n for n in range(len(art.records)) if keep is None or n not in keep]
        if idx:
            pb.setJointMotorControlArray(
                art.uid, idx, pb.VELOCITY_CONTROL, forces=[0.0] * len(idx), physicsClientId=cid
            )
        self.engaged.pop(id(art), None)
