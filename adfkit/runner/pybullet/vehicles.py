"""AMBF's vehicles in PyBullet (runner/vehicles.py has Bullet's raycast vehicle): the wheels'
bodies made static where they stand, the rays cast by PyBullet's own ray test (Bullet's, as
btDefaultVehicleRaycaster casts them: the closest body, ghosts never), the chassis given each
physics step's impulses as a force and a torque over the next physics step. The world then steps
one physics step a call."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..rotations import invert, matrix_to_pq, pose_matrix
from ..vehicles import RaycastVehicle, RayHit, cross3, planned


class PyBulletVehicles:
    def __init__(self, world, models) -> None:
        self.cid = world.cid
        self.vehicles: list[RaycastVehicle] = []
        self._pending: list[tuple] = []
        for key, veh, chassis, bodies, wheels in planned(world, models, lambda m: world._model_bodies.get(id(m), [])):
            for b in bodies:
                if b is None or b.static:
                    continue
                if b.link >= 0:
                    world._warn(
                        "runner-vehicle-wheel",
                        f"{veh.identifier}: wheel body {b.key} is a link of a multibody, which PyBullet cannot make "
                        "static; it stays dynamic",
                        veh,
                    )
                    continue
                pb.changeDynamics(b.uid, -1, mass=0.0, physicsClientId=self.cid)  # AMBF: setMassProps(0, 0)
                pb.resetBaseVelocity(b.uid, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], physicsClientId=self.cid)
                b.mass, b.inertia = 0.0, (0.0, 0.0, 0.0)
            if chassis.static:
                inv_mass, inv_inertia = 0.0, np.zeros(3)
            else:  # AMBF keeps the chassis awake (DISABLE_DEACTIVATION)
                pb.changeDynamics(
                    chassis.uid,
                    chassis.link,
                    activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING,
                    physicsClientId=self.cid,
                )
                inv_mass = 1.0 / chassis.mass
                inv_inertia = [1.0 / i if i > 0 else 0.0 for i in chassis.inertia]
            v = RaycastVehicle(key, chassis, wheels, inv_mass, inv_inertia)
            v.com_in_ref = invert(chassis.ref_in_body) @ chassis.com_in_body  # AMBF's COM in PyBullet's frame
            self.vehicles.append(v)

    def __bool__(self) -> bool:
        return bool(self.vehicles)

    def _cast(self, froms: np.ndarray, tos: np.ndarray) -> list:
        out = []
        for r in pb.rayTestBatch(froms.tolist(), tos.tolist(), physicsClientId=self.cid):
            out.append(None if r[0] < 0 else RayHit(r[2], np.array(r[3]), np.array(r[4])))
        return out

    def update(self, dt: float) -> None:
        """After a physics step: each vehicle's impulses, applied over the next (push)."""
        self._pending = []
        for v in self.vehicles:
            sb = v.chassis
            p, q, lin, ang = sb.state()
            ref = pose_matrix(p, q)  # PyBullet's frame of the chassis
            com = ref @ v.com_in_ref  # AMBF's COM frame
            pos, quat = matrix_to_pq(com)
            lin_com = np.array(lin) + cross3(ang, com[:3, 3] - ref[:3, 3])
            made = v.update(dt, pos, quat, lin_com, ang, self._cast)
            if made is not None:
                self._pending.append((sb.uid, sb.link, made[0].tolist(), pos, made[1].tolist()))

    def push(self) -> None:
        """Before a physics step: the impulses the last one left, as a force and a torque."""
        for uid, link, force, at, torque in self._pending:
            pb.applyExternalForce(uid, link, force, at, pb.WORLD_FRAME, physicsClientId=self.cid)
            pb.applyExternalTorque(uid, link, torque, pb.WORLD_FRAME, physicsClientId=self.cid)
