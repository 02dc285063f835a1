"""Write the bundled suturing scene with the challenge phantom's springy holes and thread.

The trial scene of docs/parity.md ("The bundled scene at rest"), a copy: each Entry/Exit body
0.2 kg (damping 0.04 linear, 0.1 angular) hung on a six-dof spring to the phantom (100 N/m and
N·m/rad, damping 50, free 0-10 mm along the phantom's x, from the entry toward the exit side,
-30..+20 degrees about y and +-5 about z, as the corpus ``Phantoms/Simple`` holes), and the
thread's elements at 5e-5 kg·m² with 0.2 N·m/rad joints damped 0.01 N·m·s/rad (the corpus file's;
the bundled thread's joints have no springs, scenes/suturing/thread.py).

    .venv/bin/python bench/springy_holes.py OUT_DIR [--inertia 5e-5] [--stiffness 0.2] [--damping 0.01]
    .venv/bin/adfkit suture OUT_DIR/launch.yaml --pairs 4 --seed 8

Writes the scene and prints where; asserts nothing.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

#: the corpus phantom's hole springs (ADF/Phantoms/Simple/phantom.yaml, JOINT Phantom-Entry1)
SPRING, SPRING_DAMPING = 100.0, 50.0
SLIDE = 0.01  # m along the phantom's x
TURN_Y = (-0.5236, 0.34907)  # rad
TURN_Z = 0.08727  # rad, either way
HOLE_MASS = 0.2


def hole_spring(hole, phantom: str):
    """The six-dof spring holding a hole body where the file places it (the phantom's frame is
    the world's in the bundled scene)."""
    from adfkit.model import AxesGains, Vec3
    from adfkit.model.objects import Joint, JointLimits, Vec3Range

    z_in_hole = hole.location.orientation.inverse().rotate(Vec3(0.0, 0.0, 1.0))  # the world's up
    name = hole.name or hole.identifier.split()[-1]
    return Joint(
        identifier=f"JOINT Phantom-{name}",
        name=f"Phantom-{name}",
        parent=phantom,
        child=hole.identifier,
        type="six dof spring",
        parent_pivot=hole.location.position,
        child_pivot=Vec3(),
        parent_axis=Vec3(0.0, 0.0, 1.0),
        child_axis=Vec3(*(float(v) for v in z_in_hole)),
        joint_limits=JointLimits(
            linear=Vec3Range(low=Vec3(), high=Vec3(SLIDE, 0.0, 0.0)),
            angular=Vec3Range(low=Vec3(0.0, TURN_Y[0], -TURN_Z), high=Vec3(0.0, TURN_Y[1], TURN_Z)),
        ),
        stiffness=AxesGains(linear=Vec3(SPRING, SPRING, SPRING), angular=Vec3(SPRING, SPRING, SPRING)),
        damping=AxesGains(
            linear=Vec3(SPRING_DAMPING, SPRING_DAMPING, SPRING_DAMPING),
            angular=Vec3(SPRING_DAMPING, SPRING_DAMPING, SPRING_DAMPING),
        ),
        equilibrium_point=AxesGains(linear=Vec3(), angular=Vec3()),
        enable_feedback=False,
        passive=False,
        controller_output_type="VELOCITY",
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--inertia", type=float, default=5e-5, help="kg m2 of every thread element, each axis")
    ap.add_argument("--stiffness", type=float, default=0.2, help="N m/rad of the thread's joints")
    ap.add_argument("--damping", type=float, default=0.01, help="N m s/rad of the thread's joints")
    a = ap.parse_args()

    from adfkit.adf import load, write_file
    from adfkit.model import AxesGains, Vec3
    from adfkit.model.common import VelocityDamping
    from adfkit.model.objects import Inertia

    src = ROOT / "sample_scenes" / "suturing"
    if a.out.exists():
        shutil.rmtree(a.out)
    shutil.copytree(src, a.out)
    path = a.out / "phantom" / "phantom.yaml"
    m = load(path)
    phantom = next(b.identifier for b in m.bodies if b.identifier == "BODY Phantom")
    holes = [b for b in m.bodies if (b.name or "").startswith(("Entry", "Exit"))]
    for h in holes:
        h.mass = HOLE_MASS
        h.damping = VelocityDamping(linear=0.04, angular=0.1)
        m.joints.append(hole_spring(h, phantom))
    threads = [b for b in m.bodies if (b.name or "").startswith("Thread")]
    for b in threads:
        b.inertia = Inertia(ix=a.inertia, iy=a.inertia, iz=a.inertia)
    k, c = a.stiffness, a.damping
    springs = [j for j in m.joints if j.type == "six dof spring" and "Thread" in (j.child or "")]
    for j in springs:
        j.stiffness = AxesGains(linear=Vec3(), angular=Vec3(k, k, k))
        j.damping = AxesGains(linear=Vec3(), angular=Vec3(c, c, c))
    write_file(m, path)
    print(
        f"{a.out / 'launch.yaml'}: {len(holes)} hole bodies on springs, {len(threads)} thread elements "
        f"at {a.inertia:g} kg m2, {len(springs)} thread joints at {k:g} N m/rad, {c:g} N m s/rad"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
