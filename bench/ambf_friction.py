"""Friction as AMBF's Bullet solves it: one direction per contact, where PyBullet solves two.

Plays a scene of primitive bodies (and fixed joints) four ways for the same time and prints the
largest gaps between them (any body, any 20 ms sample):

- AMBF itself (headless, adfkit's plugin: what `adfkit parity` measures);
- AMBF's own Bullet (its external/bullet, linked from its build; bench/ambf_friction.cpp), the
  bodies made as afRigidBody makes them, with the one friction direction AMBF's world solves
  (btContactSolverInfo's default solver mode: the direction the contact slides in, its last
  impulse restarted along it at 0.85);
- the same, with the second friction direction PyBullet's world adds
  (btMultiBodyDynamicsWorld sets SOLVER_USE_2_FRICTION_DIRECTIONS), and nothing else changed;
- the same again, its friction rows started from zero each step (Bullet since 2019, and so
  PyBullet, no longer restarts them: "it can cause artifacts"), from a copy of AMBF's solver
  source changed at that one place;
- adfkit's PyBullet and MuJoCo worlds under `adfkit parity`'s options.

The first gap says the program plays AMBF's scene as AMBF does; the others say how much of
adfkit's gap from AMBF the two differences are. PyBullet has no setting for either.

    .venv/bin/python bench/ambf_friction.py [SCENE -l N] [--seconds S] [--engine pybullet|mujoco|both]

Default: the parity scenes' primitives dropped tilted (`adfkit build-scene parity`, -l 7) and
the two boxes on a fixed joint (-l 9). Needs an AMBF build (`make ambf`) and g++; skips, with
the reason, without them. Asserts nothing.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SOURCE = ROOT / "bench" / "ambf_friction.cpp"
EVERY = 20  # physics steps between samples: parity's 20 ms


def program(build) -> Path:
    """bench/ambf_friction.cpp built against the AMBF build's Bullet, once per source and build."""
    from adfkit.parity.ambf import cache_root

    lib = build.cmake_dir / "libbullet.a"
    src = build.root / "external" / "bullet" / "src"
    solver = src / "BulletDynamics" / "ConstraintSolver" / "btSequentialImpulseConstraintSolver.cpp"
    key = hashlib.sha256(SOURCE.read_bytes() + solver.read_bytes() + str(lib.stat().st_mtime_ns).encode())
    exe = cache_root() / "ambf-friction" / key.hexdigest()[:16] / "ambf_friction"
    if not exe.is_file():
        exe.parent.mkdir(parents=True, exist_ok=True)
        text = solver.read_text()
        for k in (1, 2):  # the friction rows' restart, in setFrictionConstraintImpulse
            old = f"cp.m_appliedImpulseLateral{k} * infoGlobal.m_warmstartingFactor"
            if old not in text:
                raise SystemExit(f"{solver}: no friction restart to switch off (not Bullet 2.88's solver)")
            text = text.replace(old, f"(gFrictionFromZero ? 0 : {old})")
        copy = exe.parent / f"solver.{os.getpid()}.cpp"
        copy.write_text("bool gFrictionFromZero = false;\n" + text)
        inc = [f"-I{src}", f"-I{solver.parent}"]
        part = exe.with_name(f"{exe.name}.{os.getpid()}")  # two processes may build it at once
        cmd = ["g++", "-O2", "-DBT_USE_DOUBLE_PRECISION", *inc, str(SOURCE), str(copy), str(lib), "-o", str(part)]
        try:
            subprocess.run(cmd, check=True)
        finally:
            copy.unlink()
        os.replace(part, exe)
    return exe


def _line(*values) -> str:
    return " ".join(v if isinstance(v, str) else repr(float(v)) for v in values)


def scene_text(world, seconds: float) -> str:
    """The world's bodies and fixed joints as bench/ambf_friction.cpp reads them."""
    import pybullet as pb

    from adfkit.model.semantics import (
        DEFAULT_ANGULAR_DAMPING,
        DEFAULT_LINEAR_DAMPING,
        DEFAULT_RESTITUTION,
        JointKind,
        ShapeKind,
        collision_primitives,
        joint_kind,
    )
    from adfkit.parity.traces import rigid_bodies
    from adfkit.runner.pybullet.joints import com_frames
    from adfkit.runner.rotations import invert, matrix_to_pq, pose_to_matrix

    names = {ShapeKind.BOX: "box", ShapeKind.SPHERE: "sphere", ShapeKind.CYLINDER: "cylinder"}
    names.update({ShapeKind.CAPSULE: "capsule", ShapeKind.CONE: "cone", ShapeKind.PLANE: "plane"})
    bodies = rigid_bodies(world)
    lines = [_line(str(round(seconds / world.dt)), str(EVERY))]
    for sb in bodies:
        b = sb.body
        prims = collision_primitives(b)
        if not prims:
            raise SystemExit(f"{sb.key}: only bodies of primitive shapes are played here")
        info = pb.getDynamicsInfo(sb.uid, sb.link, physicsClientId=world.cid)
        d = b.damping
        lin = d.linear if d is not None and d.linear is not None else DEFAULT_LINEAR_DAMPING
        ang = d.angular if d is not None and d.angular is not None else DEFAULT_ANGULAR_DAMPING
        p, q = matrix_to_pq(sb.body_world_matrix @ sb.com_in_body)
        mass = 0.0 if sb.static else sb.mass
        restitution = b.restitution if b.restitution is not None else DEFAULT_RESTITUTION
        g = sb.gravity if sb.gravity is not None else world.gravity  # a body's or its model's `gravity`
        lines.append(
            _line("body", mass, *sb.inertia, *p, *q, info[1], info[6], restitution, lin, ang, *g, str(len(prims)))
        )
        margin = b.collision_margin if b.collision_margin is not None else 0.001
        for prim in prims:
            g = prim.geometry
            axis = str(g.axis or "z").strip().lower()[-1:] or "z"
            if prim.kind is ShapeKind.BOX:
                dims = (g.x / 2, g.y / 2, g.z / 2)
            elif prim.kind is ShapeKind.PLANE:
                dims = tuple(g.normal or (0.0, 0.0, 1.0))
            else:
                dims = (g.radius, g.height or 0.0, 0.0)
            sp, sq = matrix_to_pq(invert(sb.com_in_body) @ pose_to_matrix(prim.pose))
            if prim.kind is ShapeKind.PLANE:
                sp = [g.offset or 0.0, 0.0, 0.0]
            lines.append(_line("shape", names[prim.kind], axis, margin, *dims, *sp, *sq))
    index = {id(sb): i for i, sb in enumerate(bodies)}
    for j, parent, child in world.joints_made:
        if joint_kind(j.type) is not JointKind.FIXED:
            raise SystemExit(f"joint {j.name}: only fixed joints are played here")
        frame_a, frame_b = com_frames(j, parent, child)  # afJoint's frames, in the bodies' COM frames
        ends = [*sum(matrix_to_pq(frame_a), []), *sum(matrix_to_pq(frame_b), [])]
        lines.append(_line("fixed", str(index[id(parent)]), str(index[id(child)]), *ends))
    return "\n".join(lines) + "\n"


def lab_trace(exe: Path, text: str, world, *modes: str):
    """The scene played by bench/ambf_friction.cpp in ``modes`` ("two", "fresh"), as a parity
    trace of the bodies' ADF frames."""
    from adfkit.parity.traces import Trace, made_by, rigid_bodies
    from adfkit.runner.rotations import invert, matrix_to_pq, pose_matrix

    out = subprocess.run([str(exe), *modes], input=text, capture_output=True, text=True, check=True)
    rows = np.array([[float(v) for v in line.split()] for line in out.stdout.splitlines()])
    bodies = rigid_bodies(world)
    times = np.unique(rows[:, 0])
    poses = np.zeros((len(times), len(bodies), 7))
    for r in rows:
        s, i = int(np.searchsorted(times, r[0])), int(r[1])
        frame = pose_matrix(r[2:5], r[5:9]) @ invert(bodies[i].com_in_body)
        p, q = matrix_to_pq(frame)
        poses[s, i] = [*p, *q]
    made = made_by(world)
    return Trace(" ".join(modes) or "ambf", made, made["body"], times, poses, [], np.zeros((len(times), 0)), 0.0)


def worst(c) -> str:
    pos, _ = c.worst
    return f"{pos.max_position * 1e3:.2f} mm ({pos.name.rsplit('/', 1)[-1]})" if pos is not None else "-"


def play(path: Path, indices: list[int], seconds: float, build, exe: Path, engines: list[str]) -> list[list[str]]:
    """A table row for each engine: the scene's largest gaps between the four ways it is played."""
    from adfkit.adf import load_scene
    from adfkit.parity import ambf as ambf_run
    from adfkit.parity.compare import compare
    from adfkit.parity.traces import AdfkitPlayer, from_ambf
    from adfkit.runner import Options, open_world

    opt = Options(control_substeps=4, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = "ambf", "ambf", "body", "ambf"  # adfkit parity's
    played = {}
    for engine in ["pybullet", *(e for e in engines if e != "pybullet")]:
        world = open_world(load_scene(path, indices, []), opt, engine=engine)
        try:
            if engine == "pybullet":  # the bodies as the PyBullet runner made them
                text = scene_text(world, seconds)
                stage = ambf_run.Stage(path.resolve(), indices)
                ambf = from_ambf(ambf_run.run(build, stage, seconds, EVERY * world.dt), stage.staged_bodies)
                one, two, fresh = (lab_trace(exe, text, world, *m) for m in ((), ("two",), ("two", "fresh")))
            played[engine] = AdfkitPlayer(world).play(seconds, EVERY * world.dt)
        finally:
            world.close()
    rows = []
    for engine in engines:
        adfkit = played[engine]
        cells = [compare(ambf, one), compare(ambf, two), compare(two, adfkit), compare(fresh, adfkit)]
        cells.append(compare(ambf, adfkit))
        rows.append([f"{path.name} -l {','.join(map(str, indices))}", engine, *(worst(c) for c in cells)])
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", type=Path, help="a launch file (default: the parity scenes, -l 7 and 9)")
    ap.add_argument("-l", "--indices", default=None, help="its models to load, e.g. 7")
    ap.add_argument("--seconds", type=float, default=1.0)
    ap.add_argument("--engine", choices=("pybullet", "mujoco", "both"), default="both", help="adfkit's engine")
    args = ap.parse_args(argv)
    engines = ["pybullet", "mujoco"] if args.engine == "both" else [args.engine]
    from adfkit.parity import ambf as ambf_run

    build, why = ambf_run.available()
    if build is None or shutil.which("g++") is None:
        print(f"skipped: {why if build is None else 'g++ is not installed'}")
        return 0
    exe = program(build)
    with tempfile.TemporaryDirectory(prefix="ambf-friction-") as tmp:
        if args.scene is None:
            from adfkit.scenes.parity import write_parity

            launch = write_parity(Path(tmp))
            runs = [(launch, [7]), (launch, [9])]
        else:
            runs = [(args.scene, [int(i) for i in args.indices.split(",")] if args.indices else [0])]
        head = ["scene", "adfkit", "AMBF / its Bullet", "AMBF / + 2nd direction", "+ 2nd direction / adfkit"]
        head += ["+ friction from zero / adfkit", "AMBF / adfkit"]
        print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
        for path, indices in runs:
            for row in play(path, indices, args.seconds, build, exe, engines):
                print("| " + " | ".join(row) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
