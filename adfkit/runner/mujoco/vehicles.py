"""AMBF's vehicles in MuJoCo (runner/vehicles.py has Bullet's raycast vehicle): each wheel's
body welded where it stands (its free joint taken out of the spec before it is compiled), the
rays cast by ``mj_ray`` at the collision geoms (not the chassis's own: Bullet's ray does not
meet a shape it starts inside), the chassis given each physics step's impulses as a force and a
torque at its COM over the next physics step. The world then steps one physics step a call."""

from __future__ import annotations

import mujoco
import numpy as np

from ..rotations import matrix_to_quat
from ..vehicles import RaycastVehicle, RayHit, planned
from .after_step import AfterStep


def weld_wheels(world, plan) -> None:
    """Before the spec is compiled: each vehicle's wheel bodies lose their free joints (AMBF makes
    them static where they stand); a wheel body on other joints stays as it is, warned."""
    by_model: dict[int, list] = {}
    for bp in plan.bodies:
        by_model.setdefault(id(bp.model), []).append(bp)
    models = world.scene.all_models()
    for _key, veh, _chassis, bodies, _wheels in planned(world, models, lambda m: by_model.get(id(m), []), warn=False):
        for bp in bodies:
            if bp is None or bp.mjname == "world":
                continue
            body = plan.spec.body(bp.mjname)
            joints = list(body.joints) if body is not None else []
            if len(joints) == 1 and joints[0].type == mujoco.mjtJoint.mjJNT_FREE:
                plan.spec.delete(joints[0])
            elif joints:
                world._warn(
                    "runner-vehicle-wheel",
                    f"{veh.identifier}: wheel body {bp.key} hangs on joints, which MuJoCo cannot make static; "
                    "it stays dynamic",
                    veh,
                )


class MujocoVehicles(AfterStep):
    def __init__(self, world) -> None:
        super().__init__(world)
        m = world.model
        models = world.scene.all_models()
        self.vehicles: list[RaycastVehicle] = []
        for key, _veh, chassis, _bodies, wheels in planned(
            world, models, lambda mf: [b for b in world.bodies if b.model is mf]
        ):
            mass = float(m.body_mass[chassis.id]) if not chassis.static else 0.0
            inertia = m.body_inertia[chassis.id]
            inv_inertia = [1.0 / i if i > 0 else 0.0 for i in inertia]
            self.vehicles.append(RaycastVehicle(key, chassis, wheels, 1.0 / mass if mass > 0 else 0.0, inv_inertia))
        self._hit = np.zeros(1, dtype=np.int32)
        self._normal = np.zeros(3)

    def __bool__(self) -> bool:
        return bool(self.vehicles)

    def _caster(self, exclude: int):
        m, d, w = self.world.model, self.world.data, self.world

        def cast(froms: np.ndarray, tos: np.ndarray) -> list:
            out = []
            for a, b in zip(froms, tos):
                if not float(np.dot(b - a, b - a)) > 1e-24:  # a ray of no length meets nothing (mj_ray refuses it)
                    out.append(None)
                    continue
                x = mujoco.mj_ray(m, d, a, b - a, w._ray_groups, 1, exclude, self._hit, self._normal)
                hit = None
                if 0.0 <= x <= 1.0 and self._hit[0] >= 0:
                    hit = RayHit(float(x), a + (b - a) * x, self._normal.copy())
                out.append(hit)
            return out

        return cast

    def update(self, dt: float) -> None:
        """After a physics step (its poses computed): each vehicle's impulses, for the next."""
        m, d = self.world.model, self.world.data
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        self._pending = []
        vel = np.zeros(6)
        for v in self.vehicles:
            sb = v.chassis
            bid = sb.id
            t = sb.world_matrix() @ sb.com_in_body  # AMBF's COM frame
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, bid, vel, 0)  # at MuJoCo's COM
            ang = vel[:3].copy()
            lin = vel[3:] + np.cross(ang, t[:3, 3] - d.xipos[bid])
            r = d.ximat[bid].reshape(3, 3)
            inv_i = r @ np.diag(v.inv_inertia) @ r.T
            made = v.update(dt, t[:3, 3], matrix_to_quat(t[:3, :3]), lin, ang, self._caster(bid), inv_i)
            if made is not None:
                force, torque = made
                torque = torque + np.cross(t[:3, 3] - d.xipos[bid], force)  # about MuJoCo's COM
                self._pending.append((bid, np.concatenate([force, torque])))
