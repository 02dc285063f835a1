"""Kinematics of the da Vinci PSM with the Large Needle Driver (LND 400006), pure numpy.

The arm is described with modified (Craig) Denavit-Hartenberg parameters, as the dVRK and the
surgical robotics challenge describe it (see docs: shared reference "suturing-scene.md",
section "PSM kinematics"). One link transform is

    T_i^{i-1} = RotX(alpha) · TransX(a) · RotZ(theta) · TransZ(d)

with theta = q + offset for a revolute joint and d = d + offset + q for a prismatic one.
The base frame of the PSM has its origin at the remote centre of motion (RCM).

Frames returned by :func:`PSMKinematics.fk_all`: index 0 is the base, index k (1..6) the
frame of joint k after its motion, index 7 the end effector (the control point, at the wrist
yaw axis for the LND, since L_yaw2ctrlpnt is 0). At q = 0 the end effector has
x_E = y_0, y_E = x_0, z_E = -z_0 and sits L_tool2rcm - L_pitch2yaw = 0.0139 m above the RCM.

Inverse kinematics is the closed form of the reference (steps 1-5): the wrist yaw point and
then the wrist pitch point are found from the end-effector pose, the pitch point gives the
outer yaw, outer pitch and insertion, and the tool roll, wrist pitch and wrist yaw are signed
angles between vectors about given axes, using frames 3, 4, 5 from forward kinematics.

Two choices, documented here because callers depend on them:

* Joint limits. :meth:`PSMKinematics.ik` raises :class:`JointLimitError` (a ``ValueError``)
  naming every violated joint, with the unclipped solution in ``.q``; pass
  ``check_limits=False`` to get the raw solution. :meth:`violations` lists them for any q.
* Near the RCM. The reference's steps assume the palm link points from the yaw point back
  toward the RCM and the wrist pitch point lies beyond the RCM (q3 >= L_tool2rcm =
  0.0229 m). For 0 <= q3 < L_tool2rcm either can fail, so the solver tries the reference
  branch first, then the palm reversed and/or the shaft reaching the pitch point from
  behind (P reversed, q3 = L_tool2rcm - ||P||), and returns the first candidate that
  reproduces the pose within limits. Every configuration within limits is recovered (tested
  on random samples), not only the deep ones.

Every solution is verified with forward kinematics (step 5). Ignoring limits, a generic pose
has a solution; :class:`UnreachablePoseError` is raised for the degenerate ones (the yaw or
pitch point exactly at the RCM) or when no branch reproduces the pose within ``tol``.

Conventions checked against forward kinematics rather than taken from prose: the yaw point is
at -L2 along z_E (the reference writes T_E^0·[I | (0,0,L2)]; the last link's TransZ(d) puts
the end frame +L2 from the yaw axis, as the challenge's code has it); alpha is exactly pi/2
where the dVRK configuration files write 1.5708.
The jaw (optional 7th value) does not move the end-effector frame; it is only range-checked.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PI_2 = np.pi / 2

# LND 400006 lengths (dVRK configuration files psm_400006.json, LARGE_NEEDLE_DRIVER_400006.json)
L_RCC = 0.4389  # base (RCM) to the insertion origin
L_TOOL = 0.416  # tool shaft length
L_PITCH2YAW = 0.009  # wrist pitch axis to wrist yaw axis
L_YAW2CTRLPNT = 0.0  # wrist yaw axis to the control point (end effector) for the LND
L_TOOL2RCM = L_RCC - L_TOOL  # 0.0229 m: pitch point to RCM at q3 = 0

LIMIT_SLACK = 1e-9  # rad or m: IK accepts a solution this far past a limit (rounding)

REVOLUTE = "revolute"
PRISMATIC = "prismatic"


@dataclass(frozen=True)
class DHLink:
    """One modified-DH link: (a, alpha, theta, d, offset, joint type) plus its joint limits."""

    name: str
    alpha: float
    a: float
    d: float
    offset: float
    joint_type: str
    lower: float
    upper: float

    def transform(self, q: float) -> np.ndarray:
        """T_i^{i-1} = RotX(alpha) TransX(a) RotZ(theta) TransZ(d) for joint value q."""
        if self.joint_type == REVOLUTE:
            theta, d = q + self.offset, self.d
        else:
            theta, d = 0.0, self.d + self.offset + q
        ca, sa = np.cos(self.alpha), np.sin(self.alpha)
        ct, st = np.cos(theta), np.sin(theta)
        return np.array(
            [
                [ct, -st, 0.0, self.a],
                [st * ca, ct * ca, -sa, -d * sa],
                [st * sa, ct * sa, ca, d * ca],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )


JAW_LIMITS = (-0.698132, 1.39626)


def lnd_400006_links(l_yaw2ctrlpnt: float = L_YAW2CTRLPNT) -> tuple[DHLink, ...]:
    """The seven links of the PSM with the LND 400006 (six joints plus the end frame)."""
    return (
        DHLink("outer_yaw", PI_2, 0.0, 0.0, PI_2, REVOLUTE, -1.588, 1.588),
        DHLink("outer_pitch", -PI_2, 0.0, 0.0, -PI_2, REVOLUTE, -0.925025, 0.925025),
        DHLink("outer_insertion", PI_2, 0.0, 0.0, -L_RCC, PRISMATIC, 0.0, 0.24),
        DHLink("outer_roll", 0.0, 0.0, L_TOOL, 0.0, REVOLUTE, -3.05433, 3.05433),
        DHLink("outer_wrist_pitch", -PI_2, 0.0, 0.0, -PI_2, REVOLUTE, -1.39626, 1.39626),
        DHLink("outer_wrist_yaw", -PI_2, L_PITCH2YAW, 0.0, -PI_2, REVOLUTE, -1.39626, 1.39626),
        # the end frame is fixed (its "joint" is always 0); limits are irrelevant
        DHLink("end_effector", -PI_2, 0.0, l_yaw2ctrlpnt, PI_2, REVOLUTE, 0.0, 0.0),
    )


class JointLimitError(ValueError):
    """IK found a configuration, but it violates joint limits.

    ``violations``: list of (joint name, value, lower, upper); ``q``: the raw solution."""

    def __init__(self, q: np.ndarray, violations: list[tuple[str, float, float, float]]):
        self.q = q
        self.violations = violations
        text = ", ".join(f"{n} = {v:.6g} outside [{lo:.6g}, {hi:.6g}]" for n, v, lo, hi in violations)
        super().__init__(f"pose is out of the PSM's reach: {text}")


class UnreachablePoseError(ValueError):
    """No configuration of the PSM reproduces the requested pose."""


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b of two 3-vectors: np.cross's products and differences in its order (the same
    bits) without its axis handling, which costs ~15 µs a call (the IK makes three a pose)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def signed_angle(a: np.ndarray, b: np.ndarray, axis: np.ndarray) -> float:
    """Angle in (-pi, pi] that turns a onto b, positive when a x b points along ``axis``.

    atan2 of |a x b| and a.b, which is accurate near 0 and pi (acos is not)."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    cross = cross3(a, b)
    angle = float(np.arctan2(np.linalg.norm(cross), np.dot(a, b)))
    return -angle if np.dot(cross, axis) < 0.0 else angle


class PSMKinematics:
    """Forward and inverse kinematics of one PSM (LND 400006 by default)."""

    def __init__(self, l_yaw2ctrlpnt: float = L_YAW2CTRLPNT):
        self.links = lnd_400006_links(l_yaw2ctrlpnt)
        self.l_rcc = L_RCC
        self.l_tool = L_TOOL
        self.l_pitch2yaw = L_PITCH2YAW
        self.l_yaw2ctrlpnt = float(l_yaw2ctrlpnt)
        self.l_tool2rcm = L_RCC - L_TOOL
        self.joint_names = tuple(link.name for link in self.links[:6]) + ("jaw",)
        #: limits of the six arm joints plus the jaw (7 values each)
        self.lower_limits = np.array([link.lower for link in self.links[:6]] + [JAW_LIMITS[0]])
        self.upper_limits = np.array([link.upper for link in self.links[:6]] + [JAW_LIMITS[1]])

    # ------------------------------------------------------------------ forward
    @staticmethod
    def _joints(q) -> np.ndarray:
        q = np.asarray(q, dtype=float).reshape(-1)
        if q.size not in (6, 7):
            raise ValueError(f"expected 6 joint values (or 7 with the jaw), got {q.size}")
        if not np.all(np.isfinite(q)):
            raise ValueError(f"joint values must be finite, got {q.tolist()}")
        return q

    def fk_all(self, q) -> np.ndarray:
        """Frames of every link in the base frame: array (8, 4, 4); [0] base, [7] end effector."""
        q = self._joints(q)
        frames = np.empty((8, 4, 4))
        frames[0] = np.eye(4)
        for i, link in enumerate(self.links):
            frames[i + 1] = frames[i] @ link.transform(q[i] if i < 6 else 0.0)
        return frames

    def fk(self, q) -> np.ndarray:
        """Pose (4x4) of the end effector in the PSM base frame."""
        return self.fk_all(q)[7]

    def _fk_upto(self, q_first: list[float]) -> np.ndarray:
        T = np.eye(4)
        for link, qi in zip(self.links, q_first):
            T = T @ link.transform(qi)
        return T

    # ------------------------------------------------------------------ limits
    def violations(self, q, slack: float = 0.0) -> list[tuple[str, float, float, float]]:
        """(name, value, lower, upper) for every joint of q (6 or 7 values) more than ``slack``
        outside its limits."""
        q = self._joints(q)
        out = []
        for i, v in enumerate(q):
            lo, hi = self.lower_limits[i], self.upper_limits[i]
            if v < lo - slack or v > hi + slack:
                out.append((self.joint_names[i], float(v), float(lo), float(hi)))
        return out

    def within_limits(self, q) -> bool:
        return not self.violations(q)

    # ------------------------------------------------------------------ inverse
    def ik(self, T, check_limits: bool = True, tol: float = 1e-7) -> np.ndarray:
        """Joint values q1..q6 that put the end effector at pose T (4x4, in the base frame).

        Raises ValueError for a malformed T, :class:`JointLimitError` when the solution breaks
        a joint limit (unless ``check_limits`` is False), :class:`UnreachablePoseError` when no
        configuration reproduces T within ``tol`` (metres and radians)."""
        T = np.asarray(T, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ValueError("pose must be a finite 4x4 homogeneous transform")
        R = T[:3, :3]
        if np.abs(R.T @ R - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0:
            raise ValueError("the rotation part of the pose is not a proper rotation matrix")

        # Step 1: the wrist yaw point. The end frame sits l_yaw2ctrlpnt along its own z from
        # the yaw axis (TransZ(d) of the last link), so the yaw point is at -L2 along z_E.
        p_yaw0 = T[:3, 3] - self.l_yaw2ctrlpnt * R[:, 2]
        p_yaw_local = R.T @ p_yaw0
        # Step 2: the palm link lies in the y-z plane of the end frame, pointing back toward
        # the RCM: its direction is -P_yaw with the x component removed.
        towards = -p_yaw_local * np.array([0.0, 1.0, 1.0])
        n = np.linalg.norm(towards)
        if n < 1e-12:
            raise UnreachablePoseError(
                "the wrist yaw point lies on the end effector's x axis through the RCM; the palm direction is undefined"
            )
        palm_dir = R @ (towards / n)

        # The reference's branch first (palm toward the RCM, pitch point beyond the RCM);
        # near the RCM (q3 < L_tool2rcm) the palm may point away from it and the shaft may
        # reach it from behind, so those branches are tried next.
        candidates = []
        for palm_sign in (1.0, -1.0):
            p_pitch0 = p_yaw0 + palm_sign * self.l_pitch2yaw * palm_dir
            for behind_rcm in (False, True):
                solved = self._solve_from_pitch_point(R, p_yaw0, p_pitch0, behind_rcm)
                if solved is None:
                    continue
                q, end = solved  # the solve's own frames finish the FK: one FK per candidate
                err = pose_error(end, T)
                candidates.append((err, q))
                if err <= tol and not self.violations(q, LIMIT_SLACK):
                    # a solution at a limit may land a rounding error outside it
                    return np.clip(q, self.lower_limits[:6], self.upper_limits[:6])
        if not candidates:
            raise UnreachablePoseError("the wrist pitch point is at the RCM; outer yaw and pitch are undefined")
        reproducing = [c for c in candidates if c[0] <= tol]
        if not reproducing:
            best = min(c[0] for c in candidates)
            raise UnreachablePoseError(
                f"no PSM configuration reproduces the pose (best error {best:.3g}); the "
                "orientation is not one the wrist can take at that position"
            )
        q = reproducing[0][1]
        if check_limits:
            raise JointLimitError(q, self.violations(q, LIMIT_SLACK))
        return q

    def _solve_from_pitch_point(self, R, p_yaw0, p_pitch0, behind_rcm: bool):
        # Step 3: the shaft passes through the RCM (base origin) and the pitch point.
        P = -p_pitch0 if behind_rcm else p_pitch0
        dist = float(np.linalg.norm(P))
        if dist < 1e-12:
            return None
        q1 = float(np.arctan2(P[0], -P[2]))
        q2 = float(-np.arctan2(P[1], np.hypot(P[0], P[2])))
        q3 = self.l_tool2rcm - dist if behind_rcm else dist + self.l_tool2rcm
        # Step 4: roll, wrist pitch and wrist yaw as signed angles.
        palm = p_yaw0 - p_pitch0
        T30 = self._fk_upto([q1, q2, q3])
        q4 = signed_angle(cross3(R[:, 0], palm), T30[:3, 1], -T30[:3, 2])
        T40 = T30 @ self.links[3].transform(q4)
        q5 = signed_angle(palm, T40[:3, 2], -T40[:3, 1])
        T50 = T40 @ self.links[4].transform(q5)
        q6 = signed_angle(R[:, 2], T50[:3, 0], -T50[:3, 1])
        # the end effector at q, multiplied in fk_all's order (so it equals fk(q) exactly)
        end = (T50 @ self.links[5].transform(q6)) @ self.links[6].transform(0.0)
        return np.array([q1, q2, q3, q4, q5, q6]), end


def pose_error(A: np.ndarray, B: np.ndarray) -> float:
    """max(position distance in m, rotation angle between the two in rad)."""
    dp = float(np.linalg.norm(A[:3, 3] - B[:3, 3]))
    Rd = A[:3, :3].T @ B[:3, :3]
    # angle from the skew part and the trace together (accurate at small angles)
    s = 0.5 * np.linalg.norm([Rd[2, 1] - Rd[1, 2], Rd[0, 2] - Rd[2, 0], Rd[1, 0] - Rd[0, 1]])
    c = 0.5 * (np.trace(Rd) - 1.0)
    return max(dp, float(np.arctan2(s, c)))


_DEFAULT = None


def default() -> PSMKinematics:
    global _DEFAULT
    if _DEFAULT is None:
        _DEFAULT = PSMKinematics()
    return _DEFAULT


def fk(q) -> np.ndarray:
    """End-effector pose of the LND 400006 PSM (see :meth:`PSMKinematics.fk`)."""
    return default().fk(q)


def fk_all(q) -> np.ndarray:
    return default().fk_all(q)


def ik(T, check_limits: bool = True) -> np.ndarray:
    """Closed-form IK of the LND 400006 PSM (see :meth:`PSMKinematics.ik`)."""
    return default().ik(T, check_limits=check_limits)
