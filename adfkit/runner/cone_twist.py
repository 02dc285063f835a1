"""A `cone twist` joint's limits as AMBF's Bullet plays them, for every engine.

AMBF makes a cone twist a btConeTwistConstraint on the joint frames (the frames every joint has:
z along the file's axis) and calls ``setLimit(z, y, x)`` of the file's `joint limits`: swing
span 1 (about frame z) the `z` limit, swing span 2 (about frame y) the `y` limit and the twist
span (about frame x) the `x` limit, softness 1, bias 0.3, relaxation 1 (Bullet's defaults).
Bullet 2.88's calcAngleInfo2 splits the rotation of frame A relative to frame B (in B) into a
cone, the shortest arc that takes x onto where the rotation takes it, and a twist about x after
it. The swing is limited by an ellipse, not per axis: a swing about an axis at angle φ from frame
z is held at 1/√(cos²φ/z² + sin²φ/y²) (computeConeLimitInfo); past it, one row along the
ellipse's normal (adjustSwingAxisToUseEllipseNormal) asks the joint to turn back at
0.3·(swing − limit)/dt and only pushes. The twist past its span gets a row of its own about x.
Limiting each Euler angle instead, a rod falling diagonally into a cone of 0.3 and 0.8 rad went
where Bullet does not let it (80 mm from AMBF's over 2 s).

Bullet keeps the Euler form only where a swing span is under 0.05 rad (a hinge or fixed cone,
getInfo2NonVirtual's other branch): those joints keep the runner's per-axis limits (``elliptic``).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular

#: btConeTwistConstraint's bias factor, which AMBF's setLimit leaves at Bullet's default
CONE_TWIST_BIAS = 0.3
#: CONETWIST_DEF_FIX_THRESH: a swing span under this makes Bullet's cone a hinge or a weld
FIX_THRESH = 0.05
_EPS = 1.1920929e-07  # SIMD_EPSILON (single precision, as AMBF's Bullet is built)


def spans(limits) -> np.ndarray:
    """(swing span 1, swing span 2, twist span) of a cone twist's `joint limits` (x, y, z; AMBF's
    0.7 where one is absent): AMBF's setLimit(z, y, x)."""
    get = (lambda k: getattr(limits, k, None)) if limits is not None else (lambda k: None)
    x, y, z = (0.7 if get(k) is None else float(get(k)) for k in "xyz")
    return np.array([z, y, x])


def elliptic(span: np.ndarray) -> bool:
    """Whether Bullet plays the swing of a cone twist of these spans as an elliptic cone."""
    return bool(span[0] >= FIX_THRESH and span[1] >= FIX_THRESH)


def swing_limit(axis: np.ndarray, span: np.ndarray) -> np.ndarray:
    """(n,): the swing limit for a swing about ``axis`` (n, 3), in frame B (computeConeLimitInfo)."""
    xe, ye = axis[:, 1], -axis[:, 2]
    s1, s2 = span[:, 0], span[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        slope2 = ye * ye / (xe * xe)
        out = np.sqrt((1.0 + slope2) / (1.0 / (s2 * s2) + slope2 / (s1 * s1)))
    return np.where(np.abs(xe) > _EPS, out, s1)


def ellipse_normal(axis: np.ndarray, span: np.ndarray) -> np.ndarray:
    """``axis`` (n, 3) turned onto the ellipse's normal (adjustSwingAxisToUseEllipseNormal)."""
    y, z = -axis[:, 2], axis[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        grad = y / z * span[:, 1] / span[:, 0]
        ny = np.where(y > 0, np.abs(grad * z), -np.abs(grad * z))
        out = np.stack([axis[:, 0], z, -ny], axis=1)
        out /= np.linalg.norm(out, axis=1, keepdims=True)
    return np.where((np.abs(z) > _EPS)[:, None], out, axis)


def cone_rows(r_a: np.ndarray, r_b: np.ndarray, span: np.ndarray):
    """Bullet's swing and twist rows of cone twists: ``r_a``, ``r_b`` (n, 3, 3) the joint frames A
    (in the parent) and B (in the child) in the world, ``span`` (n, 3) as spans() gives them.
    Returns (axes (n, 2, 3), errors (n, 2)): row 0 the swing, row 1 the twist; each axis the world
    direction the child is to turn relative to the parent, each error the angle past the limit
    (0: no row). Bullet's row asks the relative rate along the axis for CONE_TWIST_BIAS·error/dt
    and only pushes (impulse ≥ 0)."""
    n = len(r_a)
    r_ab = r_b.transpose(0, 2, 1) @ r_a  # qAB = qB⁻¹·qA
    v = r_ab[:, :, 0]  # where qAB takes x (vConeNoTwist)
    v = v / np.linalg.norm(v, axis=1, keepdims=True)
    swing = np.arccos(np.clip(v[:, 0], -1.0, 1.0))
    arc = np.stack([np.zeros(n), -v[:, 2], v[:, 1]], axis=1)  # x × v: the cone's axis
    norm = np.linalg.norm(arc, axis=1, keepdims=True)
    swinging = norm[:, 0] > 1e-12
    s_axis = np.where(swinging[:, None], arc / np.where(norm > 0, norm, 1.0), np.array([0.0, 0.0, 1.0]))
    # the cone as a matrix (Rodrigues about s_axis by swing), the twist what is left of qAB
    k = _skew(s_axis)
    sw, cw = np.sin(swing)[:, None, None], np.cos(swing)[:, None, None]
    r_cone = np.eye(3) + sw * k + (1.0 - cw) * (k @ k)
    r_twist = r_cone.transpose(0, 2, 1) @ r_ab
    twist = np.arctan2(r_twist[:, 2, 1], r_twist[:, 1, 1])
    limit = swing_limit(s_axis, span)
    swing_err = np.where(swinging & (swing > limit), swing - limit, 0.0)
    twist_err = np.where(np.abs(twist) > span[:, 2], np.abs(twist) - span[:, 2], 0.0)
    s_row = ellipse_normal(s_axis, span)
    t_row = np.where((twist >= 0)[:, None], np.array([1.0, 0.0, 0.0]), np.array([-1.0, 0.0, 0.0]))
    axes = np.stack([(r_b @ s_row[:, :, None])[..., 0], (r_b @ t_row[:, :, None])[..., 0]], axis=1)
    return axes, np.stack([swing_err, twist_err], axis=1)


def _skew(a: np.ndarray) -> np.ndarray:
    out = np.zeros((len(a), 3, 3))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = a[:, 2], -a[:, 1], a[:, 0]
    return out


def row_impulses(w: np.ndarray, rate: np.ndarray, target: np.ndarray, active: np.ndarray, sweeps: int = 8):
    """(n, 2) impulses ≥ 0 of the rows: ``w`` (n, 2, 2) their inverse mass (J·M⁻¹·Jᵀ), ``rate``
    (n, 2) the rate along each row now (without them), ``target`` (n, 2) the rate each asks for,
    ``active`` (n, 2) the rows there. Projected Gauss-Seidel, as Bullet's solver treats rows that
    only push (the two rows of one joint share its bodies)."""
    lam = np.zeros_like(rate)
    diag = np.where(active, np.maximum(w[:, [0, 1], [0, 1]], 1e-300), 1.0)
    for _ in range(sweeps):
        for i in (0, 1):
            now = rate[:, i] + (w[:, i, :] * lam).sum(1)
            new = np.maximum(lam[:, i] + (target[:, i] - now) / diag[:, i], 0.0)
            lam[:, i] = np.where(active[:, i], new, 0.0)
    return lam


def sequential_impulses(bodies, gap, axes, err, dt: float, erp: float = 0.2, iterations: int = 10, moved=None):
    """(n, 2) impulses of the swing and twist rows as Bullet's solver leaves them: the joint's
    three pivot rows (at ``erp``) and its two angular rows solved one after another, ``iterations``
    sweeps (btSequentialImpulseConstraintSolver's default 10, no warm start for joint rows), each
    body moving with its own mass and inertia about its centre of mass. ``bodies``: for the parent
    and the child, (1/m (n,), I⁻¹ in the world (n, 3, 3), velocity (n, 3) with the step's gravity
    in, angular velocity (n, 3), arm from the centre of mass to the pivot (n, 3)); ``gap`` (n, 3)
    the child's pivot less the parent's; ``axes``, ``err`` as cone_rows gives them. ``moved``: a
    list that gets the two bodies' velocities and angular velocities after the solve."""
    n = len(gap)
    (ma, ia, va, wa, ra), (mb, ib, vb, wb, rb) = bodies
    va, wa, vb, wb = va.copy(), wa.copy(), vb.copy(), wb.copy()
    rows = []  # (linear of A, angular of A, angular of B, target, lower bound); B's linear is -A's
    for j in range(3):
        e = np.zeros((n, 3))
        e[:, j] = 1.0
        rows.append((e, np.cross(ra, e), -np.cross(rb, e), erp / dt * gap[:, j], -np.inf))
    zero = np.zeros((n, 3))
    for r in (0, 1):
        rows.append((zero, -axes[:, r], axes[:, r], CONE_TWIST_BIAS / dt * err[:, r], 0.0))
    inv = [
        (ma + mb) * (lin * lin).sum(1)
        + (ang_a * (ia @ ang_a[:, :, None])[..., 0]).sum(1)
        + (ang_b * (ib @ ang_b[:, :, None])[..., 0]).sum(1)
        for lin, ang_a, ang_b, _t, _lo in rows
    ]
    live = [np.ones(n, bool)] * 3 + [err[:, 0] > 0.0, err[:, 1] > 0.0]
    lam = np.zeros((len(rows), n))
    for _ in range(iterations):
        for k, (lin, ang_a, ang_b, target, low) in enumerate(rows):
            rate = (lin * (va - vb)).sum(1) + (ang_a * wa).sum(1) + (ang_b * wb).sum(1)
            new = np.maximum(lam[k] + (target - rate) / np.maximum(inv[k], 1e-300), low)
            new = np.where(live[k], new, 0.0)
            d = (new - lam[k])[:, None]
            lam[k] = new
            va += ma[:, None] * lin * d
            vb -= mb[:, None] * lin * d
            wa += (ia @ (ang_a * d)[:, :, None])[..., 0]
            wb += (ib @ (ang_b * d)[:, :, None])[..., 0]
    if moved is not None:
        moved += [va, wa, vb, wb]
    return lam[3:].T


def chain_impulses(bodies, joints, axes, err, dt: float, erp: float = 0.2, iterations: int = 10):
    """sequential_impulses for joints that share bodies (a chain of cone twists): every joint's
    three pivot rows and its rows past a limit, joint after joint in their order, ``iterations``
    sweeps. ``bodies``: (1/m (B,), I⁻¹ in the world (B, 3, 3), velocity with the step's gravity in
    (B, 3), angular velocity (B, 3)); ``joints``: (parent index (n,), child index (n,), arm from
    the parent's centre of mass to its pivot (n, 3), the child's (n, 3), the child's pivot less
    the parent's (n, 3)). Returns the (n, 2) impulses of the swing and twist rows.

    A sweep of Bullet's solver is projected Gauss-Seidel on the rows' J·M⁻¹·Jᵀ: triangular solves,
    one more after each row that only pushes and would pull (held at 0). Row by row in Python, a
    12-element rope stepped 50x slower than with the Euler angles' limits.)"""
    inv_m, inv_i, v, w = bodies
    ia, ib, arm_a, arm_b, gap = joints
    n, nb = len(ia), len(inv_m)
    # the rows, joint after joint: its three pivot rows (x, y, z), then its swing and twist rows
    # that act; on body A the linear part and an angular one, on body B minus the linear part
    jj, rr = np.nonzero(err > 0.0)
    owner = np.concatenate([np.repeat(np.arange(n), 3), jj])
    slot = np.concatenate([np.tile(np.arange(3), n), 3 + rr])
    order = np.lexsort((slot, owner))
    owner, slot = owner[order], slot[order]
    pivot = slot < 3
    k = np.where(pivot, slot, 0)
    r = np.where(pivot, 0, slot - 3)
    lin = np.where(pivot[:, None], np.eye(3)[k], 0.0)
    # a × e_k is column k of a's cross-product matrix
    ang_a = np.where(pivot[:, None], _skew(arm_a[owner])[np.arange(len(k)), :, k], -axes[owner, r])
    ang_b = np.where(pivot[:, None], -_skew(arm_b[owner])[np.arange(len(k)), :, k], axes[owner, r])
    target = np.where(pivot, erp / dt * gap[owner, k], CONE_TWIST_BIAS / dt * err[owner, r])
    low_a = np.where(pivot, -np.inf, 0.0)
    rows, o = len(owner), owner
    j_lin, j_ang = np.zeros((rows, nb, 3)), np.zeros((rows, nb, 3))
    at = np.arange(rows)
    j_lin[at, ia[o]] += lin
    j_lin[at, ib[o]] -= lin
    j_ang[at, ia[o]] += ang_a
    j_ang[at, ib[o]] += ang_b
    moved_ang = np.einsum("bij,rbj->rbi", inv_i, j_ang)
    delassus = np.einsum("rbi,sbi->rs", j_lin * inv_m[None, :, None], j_lin) + np.einsum(
        "rbi,sbi->rs", moved_ang, j_ang
    )
    rhs = target - np.einsum("rbi,bi->r", j_lin, v) - np.einsum("rbi,bi->r", j_ang, w)
    diag = np.maximum(np.diag(delassus), 1e-300)
    lower = np.tril(delassus, -1) + np.diag(diag)
    upper = np.triu(delassus, 1)
    lam = np.zeros(rows)
    for _ in range(iterations):
        start = 0  # the rows before it have their impulses of this sweep
        while start < rows:
            b = rhs[start:] - delassus[start:, :start] @ lam[:start] - upper[start:, start:] @ lam[start:]
            free = solve_triangular(lower[start:, start:], b, lower=True, check_finite=False)
            pulls = np.flatnonzero(free < low_a[start:])
            if not pulls.size:
                lam[start:] = free
                break
            q = start + int(pulls[0])  # a row that only pushes would pull: held at 0, the rest after it
            lam[start:q] = free[: q - start]
            lam[q] = low_a[q]
            start = q + 1
    out = np.zeros((n, 2))
    out[owner[~pivot], r[~pivot]] = lam[~pivot]
    return out
