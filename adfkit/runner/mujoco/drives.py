"""AMBF's joint motors in MuJoCo: each driven revolute/prismatic joint held at its target by a
joint equality (q = target, re-targeted every control step), and the motor's force limit
(max motor impulse per physics step) watched, since MuJoCo's equalities have none.

Bullet plays AMBF's joint motors as constraint rows, solved together with the contacts and
the grasp, so a needle held in the jaws loads them as a rigid part of the arm. A MuJoCo
position actuator is an explicit spring whose stiffness must stay below (2/dt)²·M_ii of the
joint alone: sized for the PSM's light wrist links (M_ii 2e-5 kg·m²), it let the held 0.5 kg
needle turn the wrist by 0.3 rad and ring with the grasp weld at 8-35 Hz (docs/mujoco.md); a
stiffer one went unstable within 0.1 s of the grasp. An equality is solved implicitly with
the weld and the contacts, whatever the load."""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import DEFAULT_JOINT_MAX_MOTOR_IMPULSE

#: a drive's time constant in physics steps: 2, the stiffest MuJoCo keeps stable (as the weld's).
#: Its impedance is MuJoCo's default, as the contacts' (contacts.py): under a steady load it yields
#: by (1-d)/d (a 2e-6 kg·m² wrist holding a 0.07 N·m needle: 7.4 mrad). At 0.999 (0.15 mrad) the
#: drive overrode the contacts it met: a jaw opening onto a hole's boundary pressed on it with
#: 1900 N for one step and 385 N held, against 50 N and 5 N at the default
DRIVE_TIMECONST_STEPS = 2


def drive_limit(joint) -> float:
    """A joint motor's max impulse per physics step (AMBF's `max motor impulse`); 0: no motor."""
    imp = joint.max_motor_impulse
    return float(imp if imp is not None else DEFAULT_JOINT_MAX_MOTOR_IMPULSE)


def add_drive(spec, joint_name: str, body_name: str, dt: float) -> None:
    """The joint's motor as an active joint equality named ``drive:<joint>``; the body's tree
    never sleeps (it is driven, as an actuated tree never does)."""
    spec.add_equality(
        type=mujoco.mjtEq.mjEQ_JOINT,
        name=f"drive:{joint_name}",
        name1=joint_name,
        objtype=mujoco.mjtObj.mjOBJ_JOINT,
        active=True,
        solref=[DRIVE_TIMECONST_STEPS * dt, 1.0],
    )
    root = body = spec.body(body_name)
    while body.name != "world":  # the tree's movable root: the top-most body with a joint
        if len(body.joints):
            root = body
        body = body.parent
    root.sleep = mujoco.mjtSleepPolicy.mjSLEEP_NEVER


class DriveLimits:
    """The drives' force limits (max motor impulse / dt), watched after every step: a drive that
    needed more than its limit is named once in a ``runner-motor-limit`` warning, with the force
    it needed then: in Bullet its motor would have given way there, here the equality held.

    Each step costs one slice, one product and one comparison: the rows' limits are looked up
    again only when MuJoCo's equality rows change (a grasp's weld made or let go), and which
    drive is over its limit only when one is."""

    def __init__(self, world, drives: list[tuple]) -> None:
        """``drives``: (equality id, joint name, max impulse per step)."""
        m = world.model
        self.world = world
        self.limit = np.full(m.neq, np.inf)
        self.names = {}
        for eq, name, imp in drives:
            self.limit[eq] = imp / world.dt
            self.names[eq] = name
        self.warned: set[int] = set()
        self._rows = b""  # the equality rows' ids the row limits are for
        self._row_limit = np.zeros(0)

    def check(self) -> None:
        d = self.world.data
        ne = d.ne  # MuJoCo puts the equality rows first
        if not ne:
            return
        ids = d.efc_id[:ne]
        key = ids.tobytes()
        if key != self._rows:
            self._rows, self._row_limit = key, self.limit[ids]
        f = d.efc_force[:ne]
        over = np.abs(f) > self._row_limit
        if np.count_nonzero(over):  # (faster than .any() on a few elements)
            self._warn(ids, np.abs(f), over)

    def _warn(self, ids: np.ndarray, f: np.ndarray, over: np.ndarray) -> None:
        for eq in set(ids[over].tolist()) - self.warned:
            self.warned.add(eq)
            need = float(f[ids == eq].max())
            self.world._warn(
                "runner-motor-limit",
                f"{self.names[eq]}: its drive needed {need:.4g} (N·m or N), more than the "
                f"motor's {self.limit[eq]:.4g} (max motor impulse / step); MuJoCo's equality held it, "
                "where Bullet's motor would have given way",
                None,
            )
