"""Contacts in the MuJoCo world as the ADF scene's engine (Bullet) makes them: rigid, and with
the two bodies' frictions combined so that a frictionless body is frictionless to everything
(and, where AMBF's bodies are asked for, as Bullet combines them).

- **Stiffness.** MuJoCo's contacts are soft by default: a time constant of 0.02 s, 20 physics
  steps here. Bullet's are rigid. The runner gives every geom a time constant of
  CONTACT_TIMECONST_STEPS steps, the stiffest MuJoCo keeps stable. At 0.02 s the suture's thread
  (a 0.19 mm capsule) pulled over a hole's 0.6 mm boundary capsule with 2.4 N sank 0.77 mm into
  it and slipped through, out of the hole it had gone through; now 2.4 N sinks a 0.19 mm sphere
  0.036 mm into such a capsule. The price: a fast impact rebounds (a 0.5 kg box dropped 0.2 m
  onto the ground rises 8.5 mm again, where Bullet's does not; a damping ratio of 2 would stop
  that but soften the contact fourfold, as a time constant of 4 steps, at which the thread still
  slipped out of Exit1 at pair 1, seed 0).
- **Friction.** Bullet multiplies the two bodies' frictions; MuJoCo takes the larger, unless the
  geoms' priorities differ, when it takes the higher-priority geom's. It cannot multiply, so
  every geom gets a priority by its friction, the lowest highest: a pair takes the lower of
  the two, exactly Bullet's product where either is 0 or 1 and within a factor of the other
  otherwise (the suture's thread on the phantom: 0.5 against Bullet's 0.5 × 0.8 = 0.4). The
  suturing scene's hole boundaries are frictionless; with the larger (the thread's 0.5) the
  thread, drawn through two holes, held the pull with 50-80 N where Bullet's needs 2-3 N.
  The floor a model played alone gets, where AMBF's bodies are asked for (``Options.bodies``
  "ambf": ``adfkit run``, ``adfkit parity``), meets each body by an explicit pair of its own
  whose friction is Bullet's product, GROUND_FRICTION times the body's (the floor AMBF and the
  PyBullet runner are given: friction 0.5). With the lower of the two, the corpus springy PSM's
  tool shaft, landing on the floor, held the arm's pitch at 7° on 0.5 where Bullet's 0.25 lets
  it slide and the arm fall 47° as AMBF's does. A scene with soft bodies keeps MuJoCo's rule on
  the floor (their nodes collide with it by its contact bits, which the pairs turn off).
  There every other two bodies meet with Bullet's combination too (bullet_pairs): the product
  of the frictions and r1·f2 + r2·f1 of the rolling frictions. Each class of geoms (one friction,
  one rolling friction) gets a priority and a friction that gives most of its pairs with the
  classes below it Bullet's combination (a default body on a floor of 0.8: 0.4 and 0.013), and
  a pair MuJoCo's rule then gets wrong is an explicit pair. With the lower of the two, the parity
  ramp's balls met it with 0.5 for AMBF's 0.25 and rolled. The corpus suturing set needs 2
  explicit pairs (6,250 with a pair for every two geoms that may touch, its MuJoCo 1.8x the CPU
  time; 823 with each class given its combination with itself, 1.18x; now 1.04-1.08x, the same
  poses to the bit in all three).
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import DEFAULT_FRICTION_ROLLING, DEFAULT_FRICTION_STATIC

#: contacts' time constant in physics steps: 2, the stiffest MuJoCo keeps stable
CONTACT_TIMECONST_STEPS = 2
#: the friction of the floor a model played alone gets: PyBullet's default, which the PyBullet
#: runner's floor and the one AMBF is given by ``adfkit parity`` have (parity/ambf.py)
GROUND_FRICTION = 0.5


def set_contacts(model, dt: float, ranked: bool = False) -> None:
    """Every geom's contact time constant and its friction priority (see the module docstring);
    ``ranked``: the priorities bullet_pairs gave kept."""
    model.geom_solref[:, 0] = CONTACT_TIMECONST_STEPS * dt
    model.pair_solref[:, 0] = CONTACT_TIMECONST_STEPS * dt
    if ranked:
        return
    mu = np.round(model.geom_friction[:, 0], 9)
    levels = np.unique(mu)  # ascending
    model.geom_priority[:] = len(levels) - 1 - np.searchsorted(levels, mu)


def ground_pairs(spec, ground, model, all_groups: int) -> None:
    """The floor ``ground`` (a plane in ``spec``, not yet in the compiled ``model``) meeting each
    geom of a moving body that collides with every group by an explicit pair whose friction is
    GROUND_FRICTION times the geom's (Bullet's product), the floor itself colliding with nothing
    else. A geom without a name is given one (a pair names its geoms)."""
    ground.friction = [GROUND_FRICTION, ground.friction[1], 0.0]
    ground.contype = ground.conaffinity = 0
    for n, g in enumerate(spec.geoms):
        if g is ground or g.type == mujoco.mjtGeom.mjGEOM_PLANE or not ((g.contype | g.conaffinity) & all_groups):
            continue
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, g.parent.name)
        if body <= 0 or model.body_weldid[body] == 0:
            continue  # static: nothing for the floor to push
        if not g.name:
            g.name = f"adfkit:geom{n}"
        mu, roll = GROUND_FRICTION * g.friction[0], GROUND_FRICTION * g.friction[2]
        spec.add_pair(geomname1=ground.name, geomname2=g.name, condim=6, friction=[mu, mu, 0.0, roll, roll])


def ambf_surface(geom, friction) -> None:
    """A body's geom as AMBF's btRigidBody: the file's friction, else AMBF's (static 0.5, rolling
    0.01), no spinning friction, and its rolling friction played (condim 6)."""
    static = friction.static if friction is not None and friction.static is not None else DEFAULT_FRICTION_STATIC
    rolling = friction.rolling if friction is not None and friction.rolling is not None else DEFAULT_FRICTION_ROLLING
    geom.friction = [static, 0.0, rolling]
    geom.condim = 6


#: Bullet clamps a combined friction to ±10 (btManifoldResult::calculateCombinedFriction)
BULLET_MAX_FRICTION = 10.0


def touching_pairs(model, skip) -> list[tuple[int, int]]:
    """The geom pairs (i < j) MuJoCo's own pass may collide in ``model``: their bits meet, they
    are on bodies that move apart (not one weld, and not a weld and its parent's unless the
    parent filter is off), and their bodies are not an excluded pair; ``skip`` (a geom mask) left
    out."""
    m = model
    ok = ~np.asarray(skip, dtype=bool) & ((m.geom_contype != 0) | (m.geom_conaffinity != 0))
    ids = np.flatnonzero(ok)
    if ids.size < 2:
        return []
    ct, ca = m.geom_contype[ids].astype(np.int64), m.geom_conaffinity[ids].astype(np.int64)
    body = m.geom_bodyid[ids]
    weld = m.body_weldid[body]
    weld_parent = m.body_weldid[m.body_parentid[weld]]
    meet = ((ct[:, None] & ca[None, :]) != 0) | ((ca[:, None] & ct[None, :]) != 0)
    meet &= weld[:, None] != weld[None, :]
    if not m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_FILTERPARENT:
        nonzero = (weld[:, None] != 0) & (weld[None, :] != 0)
        meet &= ~(nonzero & ((weld[:, None] == weld_parent[None, :]) | (weld_parent[:, None] == weld[None, :])))
    meet = np.triu(meet, 1)
    rows, cols = np.nonzero(meet)
    if m.nexclude:
        lo, hi = np.minimum(body[rows], body[cols]), np.maximum(body[rows], body[cols])
        keep = ~np.isin((lo.astype(np.int64) << 16) + hi, m.exclude_signature[: m.nexclude])
        rows, cols = rows[keep], cols[keep]
    return list(zip(ids[rows].tolist(), ids[cols].tolist(), strict=True))


def _bullet(a: tuple, b: tuple) -> tuple:
    """Bullet's combination of two (friction, rolling friction): btManifoldResult's."""
    return (
        round(min(a[0] * b[0], BULLET_MAX_FRICTION), 9),
        round(min(a[1] * b[0] + b[1] * a[0], BULLET_MAX_FRICTION), 9),
    )


def _ranked(counts: dict) -> list[tuple]:
    """Geom classes (friction, rolling) from the top priority down, each with the friction MuJoCo
    gives it: a class above the rest decides its pairs with them (and, at one priority, with its
    own), so each is given the combination most of those pairs have in Bullet, and the class that
    leaves the fewest of them to explicit pairs goes first (ties: the one deciding most)."""
    rest = sorted({k for pair in counts for k in pair})
    out = []
    while rest:
        best = None
        for g in rest:
            votes: dict[tuple, int] = {}
            for (a, b), n in counts.items():
                if (a == g and b in rest) or (b == g and a in rest):
                    v = _bullet(a, b)
                    votes[v] = votes.get(v, 0) + n
            v, n = max(votes.items(), key=lambda kv: (kv[1], kv[0])) if votes else (_bullet(g, g), 0)
            rank = (sum(votes.values()) - n, -n)
            if best is None or rank < best[0]:
                best = (rank, g, v)
        assert best is not None
        out.append((best[1], best[2]))
        rest.remove(best[1])
    return out


def bullet_pairs(spec, model, skip) -> list:
    """Bullet's combined frictions (btManifoldResult: the product of the two bodies' frictions,
    rolling r1·f2 + r2·f1, each clamped to 10) on every geom pair MuJoCo's own pass may collide
    (touching_pairs). MuJoCo cannot multiply: where two geoms' priorities differ it takes the
    higher one's friction, else the larger of each. So each class of geoms (one friction, one
    rolling friction) gets a priority of its own and a friction (_ranked) that gives most of its
    pairs Bullet's combination; each pair MuJoCo's rule then gets wrong is made an explicit pair
    with Bullet's, MuJoCo's mixing of the rest kept (the larger margin, gap and condim). Returns
    the (spec geom, friction, priority) to set once nothing reads the files' frictions from
    ``spec`` any more (ground_pairs); a geom in an explicit pair without a name is given one."""
    pairs = touching_pairs(model, skip)
    if not pairs:
        return []
    f, mg, gp, cd = model.geom_friction, model.geom_margin, model.geom_gap, model.geom_condim
    cls = {n: (round(float(f[n, 0]), 9), round(float(f[n, 2]), 9)) for pair in pairs for n in pair}
    counts: dict[tuple, int] = {}
    for i, j in pairs:
        key = tuple(sorted((cls[i], cls[j])))
        counts[key] = counts.get(key, 0) + 1
    ranked = _ranked(counts)
    top = len(ranked)
    prio = {c: top - k for k, (c, _v) in enumerate(ranked)}
    given = dict(ranked)
    geoms = {g.id: g for g in spec.geoms}  # by the compiled model's ids
    for i, j in pairs:
        a, b = cls[i], cls[j]
        got = given[a] if prio[a] >= prio[b] else given[b]  # one class, one friction: either
        want = _bullet(a, b)
        if got == want:
            continue
        for n in (i, j):
            if not geoms[n].name:
                geoms[n].name = f"adfkit:geom{n}"
        spec.add_pair(
            geomname1=geoms[i].name,
            geomname2=geoms[j].name,
            condim=int(max(cd[i], cd[j])),
            friction=[want[0], want[0], 0.0, want[1], want[1]],
            margin=float(max(mg[i], mg[j])),
            gap=float(max(gp[i], gp[j])),
        )
    return [(geoms[n], [given[c][0], float(f[n, 1]), given[c][1]], prio[c]) for n, c in sorted(cls.items())]
