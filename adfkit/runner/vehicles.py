"""AMBF's vehicles (adf-format.md §11.3): Bullet 2.88's ``btRaycastVehicle``, as AMBF 2.0 builds
it (``afVehicle::createFromAttribs``) and Bullet steps it, engine-neutral.

AMBF makes every wheel's body static (mass and inertia 0, left where its file puts it: the wheel
the vehicle draws is the motion state alone) and adds a raycast wheel per entry of ``wheels``,
whether or not its body or mesh was found: its hard point is the wheel's ``offset`` and its
``down direction`` taken from the chassis body frame into its COM frame; its ``axel direction``
is used as written. The chassis is held up by a spring-damper along each wheel's ray, and
sideways by a friction impulse, both applied to the chassis alone after each physics step
(``btDiscreteDynamicsWorld::updateActions``, after the bodies moved). The coordinate system is
AMBF's (right y, up z, forward x). Nothing commands the wheels here (no engine force, brake or
steering), so a wheel rolls freely: Bullet's rolling impulse without a brake is 0.

The engine hands ``RaycastVehicle.update`` the chassis's COM state and a ray caster; it returns
the impulse's force and torque about the COM spread over the next physics step (an impulse
after a step and a force over the next give the chassis the same velocity at the next step's
end, damping and gravity included)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .rotations import quat_to_matrix

#: btVehicleTuning's defaults: what a wheel keeps of them (AMBF sets the rest from its file)
MAX_SUSPENSION_TRAVEL_CM = 500.0
MAX_SUSPENSION_FORCE = 6000.0
#: what btWheelInfo starts with where the file says nothing (AMBF then reads an unset double)
DEFAULT_FRICTION_SLIP = 10.5
DEFAULT_ROLL_INFLUENCE = 0.1
#: resolveSingleBilateral's contact damping (btContactConstraint.cpp)
SIDE_DAMPING = 0.2
UP = 2  # afVehicle: m_vehicle->setCoordinateSystem(1, 2, 0), the chassis frame's up axis z


@dataclass
class RaycastWheel:
    connection: np.ndarray  # hard point in the chassis COM frame
    direction: np.ndarray  # down, in the chassis COM frame
    axle: np.ndarray  # as the file gives it (AMBF does not turn it into the COM frame)
    rest_length: float
    radius: float
    stiffness: float
    relaxation: float  # the file's suspension `damping`
    compression: float  # the file's suspension `compression`
    friction_slip: float = DEFAULT_FRICTION_SLIP
    roll_influence: float = DEFAULT_ROLL_INFLUENCE
    # state kept from one update to the next (btWheelInfo)
    suspension_length: float = 0.0
    in_contact: bool = False


@dataclass
class RayHit:
    fraction: float
    point: np.ndarray
    normal: np.ndarray


def cross3(a, b) -> np.ndarray:
    """a x b of two 3-vectors (np.cross costs ~30 µs a call on them; this runs at each physics step)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))


def _norm(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


class RaycastVehicle:
    """One vehicle: its chassis's inverse mass and inverse principal inertia (COM frame) and its
    raycast wheels."""

    def __init__(self, key: str, chassis, wheels: list[RaycastWheel], inv_mass: float, inv_inertia) -> None:
        self.key, self.chassis, self.wheels = key, chassis, wheels
        self.inv_mass = float(inv_mass)
        self.inv_inertia = np.asarray(inv_inertia, dtype=float)
        for w in wheels:
            w.suspension_length = w.rest_length

    def update(self, dt: float, pos, quat, v, w, cast, inv_i=None) -> tuple[np.ndarray, np.ndarray] | None:
        """btRaycastVehicle::updateVehicle after a physics step of ``dt``: the chassis COM at
        ``pos`` turned by ``quat`` (x, y, z, w) moving at ``v``, ``w``; ``cast(froms, tos)`` gives a
        RayHit or None per ray (the closest body with contact response); ``inv_i``, the chassis's
        inverse inertia in the world (default: the principal one turned by ``quat``). Returns the force and the
        torque about the COM that give the chassis the step's impulses over the next physics step,
        or None when the chassis cannot take impulses (static)."""
        if self.inv_mass == 0.0 or not self.wheels:
            return None
        com = np.asarray(pos, dtype=float)
        rot = quat_to_matrix(quat)
        inv_i = rot @ np.diag(self.inv_inertia) @ rot.T if inv_i is None else inv_i
        lin, ang = np.array(v, dtype=float), np.array(w, dtype=float)
        total_j, total_t = np.zeros(3), np.zeros(3)

        def apply(j: np.ndarray, rel: np.ndarray) -> None:
            nonlocal lin, ang, total_j, total_t
            lin = lin + j * self.inv_mass
            t = cross3(rel, j)
            ang = ang + inv_i @ t
            total_j, total_t = total_j + j, total_t + t

        def point_velocity(rel: np.ndarray) -> np.ndarray:
            return lin + cross3(ang, rel)

        hard = [com + rot @ wh.connection for wh in self.wheels]
        down = [rot @ wh.direction for wh in self.wheels]
        axle = [rot @ wh.axle for wh in self.wheels]
        lengths = [wh.rest_length + wh.radius for wh in self.wheels]
        hits = cast(np.array(hard), np.array([h + d * n for h, d, n in zip(hard, down, lengths)]))
        contact, normal, rel_vel, clipped = [], [], [], []
        for wh, h, d, n, hit in zip(self.wheels, hard, down, lengths, hits):
            wh.in_contact = hit is not None
            if hit is None:  # the wheel hangs at its rest length
                wh.suspension_length = wh.rest_length
                contact.append(h + d * n)
                normal.append(-d)
                rel_vel.append(0.0)
                clipped.append(1.0)
                continue
            travel = wh.rest_length, MAX_SUSPENSION_TRAVEL_CM * 0.01
            wh.suspension_length = min(max(hit.fraction * n - wh.radius, travel[0] - travel[1]), travel[0] + travel[1])
            nrm = _norm(np.asarray(hit.normal, dtype=float))
            contact.append(np.asarray(hit.point, dtype=float))
            normal.append(nrm)
            denominator = float(nrm @ d)
            if denominator >= -0.1:
                rel_vel.append(0.0)
                clipped.append(10.0)
            else:
                inv = -1.0 / denominator
                rel_vel.append(float(nrm @ point_velocity(contact[-1] - com)) * inv)
                clipped.append(inv)
        # updateSuspension, then each wheel's suspension impulse
        suspension = []
        for wh, rv, c in zip(self.wheels, rel_vel, clipped):
            if not wh.in_contact:
                suspension.append(0.0)
                continue
            force = wh.stiffness * (wh.rest_length - wh.suspension_length) * c
            force -= (wh.compression if rv < 0.0 else wh.relaxation) * rv
            suspension.append(max(force / self.inv_mass, 0.0))
        for s, n, p in zip(suspension, normal, contact):
            apply(n * min(s, MAX_SUSPENSION_FORCE) * dt, p - com)
        self._friction(com, rot, inv_i, contact, normal, axle, suspension, dt, apply, point_velocity)
        return total_j / dt, total_t / dt

    def _friction(self, com, rot, inv_i, contact, normal, axle, suspension, dt, apply, point_velocity) -> None:
        """btRaycastVehicle::updateFriction: each grounded wheel's sideways impulse (Bullet's
        resolveSingleBilateral against a fixed body), scaled down where it exceeds the wheel's
        grip. Its rolling impulse is bounded by the brake, and nothing commands a brake, an
        engine force or a steering angle here: it is 0, and the axle the file's."""
        up = rot[:, UP]
        pushes = []  # every wheel's impulse from the velocities before any of them (as Bullet's)
        for wh, a, n, p, s in zip(self.wheels, axle, normal, contact, suspension):
            if not wh.in_contact:
                continue
            a = _norm(a - n * float(a @ n))
            rel = p - com
            side = -SIDE_DAMPING * float(a @ point_velocity(rel)) / _denominator(self.inv_mass, inv_i, rel, a)
            grip = s * dt * wh.friction_slip
            side = max(min(side, grip), -grip)  # the skid
            if side != 0.0:
                pushes.append(
                    (a * side, rel - up * (float(up @ rel) * (1.0 - wh.roll_influence)))
                )  # ROLLING_INFLUENCE_FIX
        for impulse, rel in pushes:
            apply(impulse, rel)


def _denominator(inv_mass: float, inv_i: np.ndarray, rel: np.ndarray, direction: np.ndarray) -> float:
    """btRigidBody::computeImpulseDenominator (the fixed ground adds nothing)."""
    c = cross3(rel, direction)
    return inv_mass + float(direction @ cross3(inv_i @ c, rel))


def planned(world, models, bodies_of, warn: bool = True) -> list[tuple]:
    """Each vehicle AMBF makes, as ``(key, vehicle, chassis, wheel bodies, RaycastWheels)``: its
    chassis and its wheels' bodies found by AMBF's lookup among the bodies of the models loaded
    before its own (adf-format.md §12.2: a vehicle cannot use bodies of its own file), with a
    located warning for what AMBF leaves out (a vehicle whose chassis is not found; a wheel with
    neither ``body`` nor ``mesh``, or without the keys its ray needs, which AMBF reads unset) and
    for a wheel body not found (its ray is kept, as AMBF keeps it)."""
    from .names import merge_namespace
    from .plan import loaded_so_far

    known = None
    out = []
    say = world._warn if warn else (lambda *a, **k: None)
    for m in models:
        ns = m.namespace or ""
        for veh in m.vehicles:
            key = merge_namespace(ns, veh.namespace) + veh.identifier
            found = (known.find(veh.chassis) if known is not None else (None, []))[0]
            chassis = known.items[found] if found is not None else None
            if chassis is None:
                say(
                    "runner-vehicle",
                    f"{veh.identifier}: chassis {veh.chassis!r} is not among the bodies made by the models loaded before this one; "
                    "AMBF makes no vehicle",
                    veh,
                    "list the chassis's model before the vehicle's in the launch file",
                )
                if warn:
                    world.not_played.append({"object": veh.identifier, "what": "vehicle", "why": "no chassis"})
                continue
            bodies, wheels = [], []
            for i, wd in enumerate(veh.wheels or []):
                wheel = _wheel(say, veh, i, wd, _com_in_body(chassis))
                if wheel is None:
                    continue
                body = None
                if wd.body is not None:
                    hit = known.find(wd.body)[0]
                    body = known.items[hit] if hit is not None else None
                    if body is None:
                        say(
                            "runner-vehicle-wheel",
                            f"{veh.identifier}: wheel {i + 1}'s body {wd.body!r} is not found; its ray is kept",
                            veh,
                        )
                bodies.append(body)
                wheels.append(wheel)
            out.append((key, veh, chassis, bodies, wheels))
        known = loaded_so_far(known, bodies_of(m))
    return out


def _com_in_body(body) -> np.ndarray:
    """An engine body's COM frame in its body frame (a MuJoCo plan's body: its file's, §7.2)."""
    com = getattr(body, "com_in_body", None)
    if com is not None:
        return com
    from ..model.semantics import inertial_offset
    from .rotations import pose_to_matrix

    return pose_to_matrix(inertial_offset(body.body))


def _wheel(say, veh, i: int, wd, com_in_body: np.ndarray) -> RaycastWheel | None:
    if wd.body is None and wd.mesh is None:
        say("runner-vehicle-wheel", f"{veh.identifier}: wheel {i + 1} has neither body nor mesh; AMBF skips it", veh)
        return None
    s = wd.suspension
    need = {
        "radius": wd.radius,
        "offset": wd.offset,
        "down direction": wd.down_direction,
        "axel direction": wd.axel_direction,
        "suspension": s
        if s is not None and None not in (s.stiffness, s.damping, s.compression, s.rest_length)
        else None,
    }
    missing = [k for k, v in need.items() if v is None]
    if missing:
        say(
            "runner-vehicle-wheel",
            f"{veh.identifier}: wheel {i + 1} lacks {', '.join(missing)} (AMBF reads it unset); the wheel is left out",
            veh,
        )
        return None
    to_com = np.linalg.inv(com_in_body)  # AMBF: the offset and the down direction into the COM frame
    return RaycastWheel(
        connection=(to_com @ np.array([*wd.offset, 1.0]))[:3],
        direction=to_com[:3, :3] @ np.array(wd.down_direction, dtype=float),
        axle=np.array(wd.axel_direction, dtype=float),
        rest_length=float(s.rest_length),
        radius=float(wd.radius),
        stiffness=float(s.stiffness),
        relaxation=float(s.damping),
        compression=float(s.compression),
        friction_slip=float(wd.friction) if wd.friction is not None else DEFAULT_FRICTION_SLIP,
        roll_influence=float(wd.roll_influence) if wd.roll_influence is not None else DEFAULT_ROLL_INFLUENCE,
    )
