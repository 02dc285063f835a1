"""Where everything of the suturing scene is (world frame, metres, z up) and the poses a
suture needs: the needle's start pose, its pose with the tip at entry hole k, and the PSM
end-effector poses that hold it there with the jaws from above.

The phantom rests on the floor (z = 0): a slab with a slot the needle lies across (so the jaws
can close around it from above), and a ridge of tissue blocks along y with four gaps. Each
gap holds an entry/exit pair across the ridge, 14 mm apart, the needle's circle passing
through both with its centre 6.3 mm above the ridge (48 degrees into the tissue).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .frames import look_frame, rot_x, rot_y, rot_z, translation

# Needle: the challenge's needle (corpus Needle.OBJ): a 3/8 circle (135 degrees) of radius
# 9.4 mm to the wire's centre line, wire about 1 mm thick (0.9 to 10.0 mm from the centre).
NEEDLE_RADIUS = 0.0094
NEEDLE_ARC = 3 * math.pi / 4
NEEDLE_WIRE = 0.0005  # wire radius
NEEDLE_TIP_ANGLE = math.pi / 4  # in the needle's frame (arc in its xy plane, centre at the origin)
NEEDLE_TAIL_ANGLE = math.pi  # the thread is fixed here
#: PyBullet gives a convex-hull collision shape a margin of about 1 mm around the hull (the
#: runner's contacts sit ~0.9 mm below the wire): the needle starts that far above the slab
HULL_CLEARANCE = 0.001
NEEDLE_GRASP_ANGLE = 5 * math.pi / 6  # where a PSM holds it (30 degrees from the tail)

SLAB = (0.080, 0.176, 0.016)  # x, y, z full sizes; top at SLAB[2]
SLOT_DEPTH = 0.008
RIDGE_HALF_X = 0.0105
RIDGE_TOP = 0.022
RIDGE_Y = (-0.050, 0.050)
HOLE_YS = (0.036, 0.012, -0.012, -0.036)
HOLE_HALF_GAP = 0.007  # entry at x = -7 mm, exit at +7 mm
RIDGE_GAP = 0.0055  # width of the ridge's gap at each pair

NEEDLE_GRASP_XY = (-0.026, 0.060)  # the slot's centre; the needle crosses it here
SLOT_X = (-0.034, -0.018)
SLOT_HALF_Y = 0.0035

THREAD_ELEMENTS = 40
THREAD_PITCH = 0.00244  # pivot-to-pivot length of an element (corpus)
THREAD_RADIUS = 0.00019
THREAD_MASS = 0.03  # kg per element (published tuning)

#: RCMs (DH base origins) of the two PSMs, and the point their shafts aim at when q1 = q2 = 0
RCM = {"psm1": (0.075, 0.055, 0.125), "psm2": (-0.075, 0.055, 0.125)}
AIM = (0.0, 0.0, 0.03)
Q_HOME_INSERTION = 0.10


def needle_centre_height() -> float:
    return math.sqrt(NEEDLE_RADIUS**2 - HOLE_HALF_GAP**2)


def entry_angle() -> float:
    """Angle below the horizontal of the needle's radius at the entry (and exit) point."""
    return math.asin(needle_centre_height() / NEEDLE_RADIUS)


def hole_poses(k: int) -> tuple[np.ndarray, np.ndarray]:
    """World poses of Entry k and Exit k (k = 1..4): on the ridge top, z along the needle's
    path through the hole (out of the tissue), x along world x tilted with it."""
    y = HOLE_YS[k - 1]
    tilt = entry_angle()  # the path is 90 degrees from the radius
    entry = translation(-HOLE_HALF_GAP, y, RIDGE_TOP) @ rot_y(-tilt)
    exit_ = translation(HOLE_HALF_GAP, y, RIDGE_TOP) @ rot_y(tilt)
    return entry, exit_


def needle_start() -> np.ndarray:
    """The needle lying flat on the slab in its own orientation: the wire leaves the tail along
    world +y, so the thread lies straight on along -y; the wire crosses the slot at
    NEEDLE_GRASP_XY (30 degrees from y there), where the jaws close on it from above."""
    gx, gy = NEEDLE_GRASP_XY
    a = NEEDLE_GRASP_ANGLE
    centre = (
        gx - NEEDLE_RADIUS * math.cos(a),
        gy - NEEDLE_RADIUS * math.sin(a),
        SLAB[2] + NEEDLE_WIRE + HULL_CLEARANCE,
    )
    return translation(*centre)


def needle_at_entry(k: int) -> np.ndarray:
    """The needle upright over pair k (its plane the world x-z plane), its tip at Entry k:
    turning it about its own -z axis (rot_z(-t) on the right) drives the tip along its arc
    through the tissue; a turn of 2·(pi/2 - entry_angle()) brings it out at Exit k."""
    centre = translation(0.0, HOLE_YS[k - 1], RIDGE_TOP + needle_centre_height())
    # needle y -> world -z, needle z -> world +y: a needle angle t is the world x-z angle -t
    plane = rot_x(-math.pi / 2)
    entry_world = math.pi + entry_angle()  # lower left, measured from +x toward +z
    return centre @ plane @ rot_z(-entry_world - NEEDLE_TIP_ANGLE)


def arc_point(needle: np.ndarray, angle: float) -> np.ndarray:
    """World point of the wire's centre line at ``angle`` (needle frame)."""
    p = needle @ np.array([NEEDLE_RADIUS * math.cos(angle), NEEDLE_RADIUS * math.sin(angle), 0.0, 1.0])
    return p[:3]


def arc_tangent(needle: np.ndarray, angle: float) -> np.ndarray:
    """World direction of the wire at ``angle``, pointing from the tail toward the tip."""
    t = needle[:3, :3] @ np.array([math.sin(angle), -math.cos(angle), 0.0])
    return t / np.linalg.norm(t)


def psm_base(name: str) -> np.ndarray:
    """World pose of the PSM's DH base frame: at its RCM, z pointing away from AIM (the
    shaft then points at AIM when q1 = q2 = 0), x horizontal."""
    rcm = np.array(RCM[name], float)
    z = rcm - np.array(AIM)
    z /= np.linalg.norm(z)
    x = np.cross((0.0, 0.0, 1.0), z)
    return look_frame(rcm, z, x)


def shaft_direction(name: str, needle: np.ndarray, angle: float = NEEDLE_GRASP_ANGLE) -> np.ndarray:
    """Unit vector from the PSM's RCM to the grasp point on ``needle``: jaws held along the
    shaft come from above (every RCM is above the phantom)."""
    d = arc_point(needle, angle) - np.array(RCM[name])
    return d / np.linalg.norm(d)


def q_home() -> np.ndarray:
    return np.array([0.0, 0.0, Q_HOME_INSERTION, 0.0, 0.0, 0.0])


def grasp_ee_pose(needle: np.ndarray, angle: float, tool_from_above=(0.0, 0.0, -1.0)) -> np.ndarray:
    """World end-effector pose of a PSM holding ``needle`` at ``angle`` (needle frame): the
    wire runs along the end effector's x between the fingers (they close along its y), the
    jaws (its z) point as close to ``tool_from_above`` as that allows, and the grasp point
    (the actuator, psm.grasp_offset()) sits on the wire."""
    from .psm import grasp_offset

    g = arc_point(needle, angle)
    t = arc_tangent(needle, angle)
    jaws = np.asarray(tool_from_above, float)
    at_grasp = look_frame(g, jaws - np.dot(jaws, t) * t, t)
    return at_grasp @ translation(*(-grasp_offset()[:3, 3]))


@dataclass
class Reach:
    name: str
    label: str
    q: np.ndarray | None
    error: str = ""


def check_reach(psms=("psm1", "psm2")) -> list[Reach]:
    """Closed-form IK of every PSM at: the needle's start pose (grasped from above) and the
    needle held with its tip at each entry hole. Returns one Reach per (PSM, pose)."""
    from ...runner.psm_kinematics import default

    kin = default()
    targets = [("needle start", needle_start())] + [(f"entry {k}", needle_at_entry(k)) for k in range(1, 5)]
    out = []
    for name in psms:
        base = psm_base(name)
        base_inv = np.linalg.inv(base)
        for label, needle in targets:
            ee = base_inv @ grasp_ee_pose(needle, NEEDLE_GRASP_ANGLE, shaft_direction(name, needle))
            try:
                out.append(Reach(name, label, kin.ik(ee)))
            except ValueError as e:
                out.append(Reach(name, label, None, str(e)))
    return out
