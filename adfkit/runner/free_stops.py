"""AMBF's hinge and slider stops on a free multibody, played through AMBF's own solver step:
which multibodies, when, and the joint velocities that step leaves, whatever the engine.

A joint nothing drives that runs into its limit bounces in AMBF as its btRigidBodies do, not as
a joint does: the hinge's limit row turns the child's spin about its own centre of mass back
(relaxation 1, bias 0.3) while its pivot rows, at the joint's erp, pull its centre back onto the
pivot over the following steps. What the joint keeps of its speed is what is left when the two
have met again (a 0.2 kg, 0.2 m rod hinged at one end, into a stop at 11.2 rad/s: 1.71 rad/s
back, about 0.15 of it, where a row on the joint alone turns it back at 0.3).

So, under AMBF's bodies (Options.bodies "ambf"), a multibody whose joints are all hinges and
sliders, at least one of them limited, with nothing commanding its joints and no position motor
holding it, is handed to the chain step (World.chain_of: runner/chain_step.py, the rows of
runner/chain_rows.py) from the physics step before one of its limited joints would cross its
limit, coming in at REST_SPEED or faster, until SETTLE physics steps after the last such step (a
joint resting on its stop is left to the engine's own limit: the PyBullet runner's limit_rows.py,
MuJoCo's limit with Bullet's rate, mujoco/limits.py): at each physics step every joint is taken to
the velocity AMBF's solver leaves it at (``FreeStops.velocities``), by the engine (the PyBullet
runner's pybullet/limit_chains.py, the MuJoCo engine's mujoco/limit_chains.py). The world then
steps physics steps one by one, as it does for AMBF's springs.

Not for a multibody with a loop the chain step would close (a hinge or point joining two of its
links): the corpus parallel structure, a four-bar swinging down onto a stop, went 7.9 -> 10.7 mm
from AMBF's in PyBullet (0.84 -> 3.1 mm at the end; not explained: driving only its limited
joints at the chain step's velocities, its loop left to PyBullet, gave the same). Nor do AMBF's
ghosts act on its links in the chain step while it plays them (the links' ghost forces are the
control step's, which the step's velocities override)."""

from __future__ import annotations

import numpy as np

from ..model.semantics import JointKind
from .joint_commands import limits_of

#: physics steps a bounce is played on for after its joints last came in fast: the pivot rows
#: close what is apart by the joint's erp (0.1) a step, to 0.5 % in 50
SETTLE = 50
#: a joint moving slower than this (rad/s or m/s) rests on its stop, which the engine's own limit
#: holds as AMBF's row does: only what comes in faster bounces
REST_SPEED = 0.05


class FreeStops:
    """The engine-neutral part: an engine's subclass takes a multibody (``_take``), gives it back
    (``_give_back``) and realises the velocities ``velocities`` answers at each physics step."""

    def __init__(self, world) -> None:
        self.world = world
        self.arts: list[tuple] = []  # (articulation, [(record index, limits)] of its limited joints)
        self.engaged: dict[int, int] = {}  # id(art) -> the physics step it last came in fast at
        self.commanded: set[tuple[int, int]] = set()  # (id(art), record index) under a joint command
        self.step = 0  # physics steps played, for the chain step's own count
        self.free: list[tuple] = []  # the multibodies of ``arts`` nothing drives, as ``watching`` found them
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

    def leave(self, art, index: int) -> None:
        """Joint ``index`` of ``art`` is under a joint command from now on (joint_commands.py):
        its multibody is not free."""
        self.commanded.add((id(art), index))

    def _commanded(self, art) -> set[int]:
        """The joints of ``art`` a command or a holding position motor drives."""
        if art.held:
            return set(range(len(art.records)))
        if not self.commanded:  # no joint commanded yet (asked before every physics step)
            return set()
        return {n for n in range(len(art.records)) if (id(art), n) in self.commanded}

    def watching(self) -> bool:
        """Whether a multibody may be handed to the chain step or is played now (one free or one
        engaged): an engine that steps physics steps together otherwise steps them one by one."""
        self.free = [(art, limited) for art, limited in self.arts if not self._commanded(art)]
        return bool(self.engaged) or bool(self.free)

    def idle(self, steps: int) -> None:
        """``steps`` physics steps played without a look (``watching`` said no)."""
        self.step += steps

    def playing(self, art) -> bool:
        """Whether the chain step plays ``art``'s joints now (the engine's own limit leaves them)."""
        return id(art) in self.engaged

    def velocities(self) -> list[tuple[object, np.ndarray]]:
        """Before each physics step: each free multibody near a stop handed to the chain step,
        those whose bounce is over given back; (articulation, its joints' velocities after this
        step of AMBF's solver, by record index) of each it plays."""
        w, dt = self.world, self.world.dt
        self.step += 1
        out = []
        for art, limited in list(self.arts):
            key = id(art)
            commanded = self._commanded(art)
            if commanded:
                if key in self.engaged:  # the commanded joints' motors are the commands' now
                    self._give_back(art, limited, keep=commanded)
                continue
            q, v = (x.tolist() for x in w.joint_state(art, list(range(len(art.records)))))
            near = False  # (floats: numpy's scalars gave the same sums at five times the cost)
            for n, (lo, hi) in limited:
                ahead = q[n] + 2.0 * v[n] * dt  # where it is a step after the next: the solver sees it past
                # heading out across a limit (a joint coming back in is the limit row's: a hinge
                # started past its limit is kicked in at 0.3·erp·error/dt and coasts, as in AMBF)
                if abs(v[n]) >= REST_SPEED and ((ahead > hi and v[n] > 0.0) or (ahead < lo and v[n] < 0.0)):
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
                self.engaged[key] = self.step
            if near:
                self.engaged[key] = self.step
            if self.step - self.engaged[key] > SETTLE:
                self._give_back(art, limited)
                continue
            if not out:
                self._state_now()
            out.append((art, np.asarray(w.chain_of(art).velocities({}, {}, self.step), dtype=float)))
        return out

    def reset(self) -> None:
        """The world put back to a snapshot: every multibody given back, what the chain step
        carried from step to step dropped (its next step is not this one's successor)."""
        for art, limited in self.arts:
            if id(art) in self.engaged:
                self._give_back(art, limited)
        self.step += 2

    # the engine's part

    def _state_now(self) -> None:
        """Before the first chain step of a physics step: the engine's poses of the state now."""

    def _take(self, art, limited) -> None:
        """``art``'s joints are the chain step's from this physics step."""

    def _give_back(self, art, limited, keep: set[int] | None = None) -> None:
        """``art``'s joints the engine's own again, but those of ``keep`` (driven by commands since)."""
        self.engaged.pop(id(art), None)
