"""Joint programs: command files that drive every motorised revolute and prismatic joint of a
robot through a few moves (``adfkit parity --commands``), for a robot whose file has none. A
position program streams set-points every 10 ms along a smooth swing inside each joint's limits
(as a controller streams them: a jump of the set-point kicks the controller's derivative, and
with the KUKA's gains, P 1000-2000 and D 2-4 as efforts, AMBF's arm flails, measured); a
velocity program turns each joint one way then the other; an effort program pushes each one way
then the other."""

from __future__ import annotations

import math
from pathlib import Path

from ..runner.joint_commands import limits_of, motor_enabled


def program(joints, kind: str, seconds: float, size: float = 0.3) -> list[str]:
    """Command lines for ``joints`` ((AMBF name, ADF joint, kind "revolute"/"prismatic")).
    ``size``: rad (m for a prismatic joint: a tenth of it) of a position move, rad/s of a
    velocity, N·m (N) of an effort, scaled down for the joints further out of the chain."""
    lines = []
    half = round(seconds / 2, 3)
    for n, (name, joint, jkind) in enumerate(joints):
        scale = size * (0.1 if jkind == "prismatic" else 1.0) * (1.0 - 0.5 * n / max(1, len(joints)))
        sign = 1.0 if n % 2 == 0 else -1.0
        if kind == "position":
            lim = limits_of(joint)
            lo, hi = lim if lim is not None else (-3.0, 3.0)
            start = min(max(0.0, lo), hi)
            for k in range(1, int(round(seconds / 0.01)) + 1):
                t = k * 0.01
                q = start + sign * scale * math.sin(math.pi * t / seconds) ** 2
                lines.append(f"{t:.2f}, position, {name}, {min(max(q, lo), hi):.5f}")
        elif kind == "velocity":
            lines += [f"0.0, velocity, {name}, {sign * scale:.4f}", f"{half}, velocity, {name}, {-sign * scale:.4f}"]
        else:
            e = sign * scale * 0.01
            lines += [f"0.0, effort, {name}, {e:.5f}", f"{half}, effort, {name}, {-e:.5f}"]
    return lines


def driven_joints(world) -> list[tuple[str, object, str]]:
    """The motorised revolute and prismatic joints an adfkit world made and can drive (not a
    joint closing a kinematic loop), by AMBF's names."""
    from ..model.semantics import JointKind, joint_kind
    from ..runner.joint_commands import JointCommands
    from .traces import made_by

    names = made_by(world)["joint"]
    drives = JointCommands(world)
    out = []
    for name, (j, _p, child) in zip(names, world.joints_made):
        k = joint_kind(j.type)
        if k in (JointKind.REVOLUTE, JointKind.PRISMATIC) and motor_enabled(j) and drives.drivable(j, child):
            out.append((name, j, k.value))
    return out


def write_program(scene_path: Path, indices, kind: str, seconds: float, out: Path, size: float = 0.3) -> Path:
    """The program of ``kind`` for the scene's motorised joints, written to ``out``."""
    from ..adf import load_scene
    from ..runner import Options, open_world

    world = open_world(load_scene(scene_path, indices), Options(visuals=False, ground=False))
    try:
        lines = program(driven_joints(world), kind, seconds, size)
    finally:
        world.close()
    out.write_text(f"# {kind} program for {scene_path.name}: TIME, KIND, JOINT, VALUE\n" + "\n".join(lines) + "\n")
    return out
