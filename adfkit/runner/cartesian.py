"""A free body steered to a pose as AMBF's ROS plugin steers one under a pose command
(ObjectCommPlugin's rigidBodyFetchCommand, TYPE_POSITION): through the body's own Cartesian
controller (adf-format.md §7.6), read as AMBF's loader reads it (ADFUtils::getCartesianController
Attribs). Without a `controller` block: P 10, D 1, output a velocity. With one: each of `linear`
and `angular` given its P and D (I is never used), and the output a force and a torque if the
block has `linear`, else a velocity; `controller output type` (read only with a block) overrides
it (`FORCE`/`EFFORT`, else `VELOCITY`/`POSITION`, which AMBF plays as a velocity; an unknown word
is a force). AMBF decides the output of both parts by the position part's type.

A force output is AMBF's: P·e + D·(e − e_last)/dt, the error e of the position and of the
rotation (the body frame's rotation vector, turned into the world), e_last the last step's (0
at the first), applied at the centre of mass each step, the error read from the pose the body had
a physics step before (AMBF reads its motion state). A velocity output keeps P·e alone: on a
velocity output AMBF's D term, with that pose a step behind, rings and grows (docs/ros.md).
Measured with `adfkit parity` (a `pose` command, 2 s): a 1 kg box with `linear: {P: 50, D: 5}`,
`angular: {P: 2, D: 0.2}` 221 mm from AMBF's (steered as a velocity by P 10, where AMBF's sags
mg/P under its force) -> 0.00 mm, 0.00° (PyBullet), 1.38° (MuJoCo)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .rotations import AMBF_CARTESIAN_P, rotation_log

#: AMBF's default Cartesian D (afCartesianControllerAttributes), used on a force output only
AMBF_CARTESIAN_D = 1.0
FORCE_WORDS = ("FORCE", "EFFORT", "force", "effort")
VELOCITY_WORDS = ("VELOCITY", "velocity", "POSITION", "position")


def _gains(pid) -> tuple[float, float]:
    p = pid.P if pid.P is not None else AMBF_CARTESIAN_P
    d = pid.D if pid.D is not None else AMBF_CARTESIAN_D
    return float(p), float(d)


@dataclass
class PoseSteer:
    """One body's Cartesian controller under a pose command."""

    p_lin: float = AMBF_CARTESIAN_P
    d_lin: float = AMBF_CARTESIAN_D
    p_ang: float = AMBF_CARTESIAN_P
    d_ang: float = AMBF_CARTESIAN_D
    force: bool = False
    last: tuple[np.ndarray, np.ndarray] = field(default_factory=lambda: (np.zeros(3), np.zeros(3)))
    prev: np.ndarray | None = None

    @classmethod
    def of(cls, body) -> PoseSteer:
        """The controller AMBF builds from ``body``'s `controller` and `controller output type`."""
        c = getattr(body, "controller", None)
        if c is None:
            return cls()
        out = cls()
        if c.linear is not None:
            out.p_lin, out.d_lin = _gains(c.linear)
            out.force = True
        if c.angular is not None:
            out.p_ang, out.d_ang = _gains(c.angular)
        word = getattr(body, "controller_output_type", None)
        if word is not None:
            out.force = word not in VELOCITY_WORDS
        return out

    def errors(self, cur: np.ndarray, goal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The position error and the rotation error (body frame) of ``cur`` against ``goal``
        (4x4 poses of the body's centre-of-mass frame)."""
        return goal[:3, 3] - cur[:3, 3], rotation_log(cur[:3, :3].T @ goal[:3, :3])

    def step(self, cur: np.ndarray, goal: np.ndarray, dt: float, lagged: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """This step's (linear, angular) output in the world frame: a force and a torque
        (``self.force``) or a velocity and an angular velocity. ``lagged`` (a caller stepping
        once a physics step): the error taken from the pose ``cur`` had at the last call, as AMBF
        takes it (its motion state's pose, a physics step behind; the first call its own)."""
        if lagged:  # AMBF reads the pose from the body's motion state, one physics step behind
            cur, self.prev = (self.prev if self.prev is not None else cur), cur
        e_lin, e_ang = self.errors(cur, goal)
        if self.force:
            lin = self.p_lin * e_lin + self.d_lin * (e_lin - self.last[0]) / dt
            ang = self.p_ang * e_ang + self.d_ang * (e_ang - self.last[1]) / dt
        else:
            lin, ang = self.p_lin * e_lin, self.p_ang * e_ang
        self.last = (e_lin, e_ang)
        return lin, cur[:3, :3] @ ang
