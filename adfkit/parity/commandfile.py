"""The command file a parity run is driven by: one command a line,

    TIME, KIND, TARGET[, VALUE]

TIME in simulated seconds; KIND ``position``, ``velocity`` or ``effort`` (TARGET a joint, VALUE
the command: rad, rad/s, N·m, or m, m/s, N for a prismatic joint), ``grasp`` (TARGET a constraint
actuator, VALUE the body it fixes) or ``release`` (TARGET an actuator). Names are AMBF's (namespace
and `name`, spaces removed) or any unique end of one (``psm1/baselink-yawlink``, ``base link-yaw
link`` when only one model has it), or ``pose`` (TARGET a free body, VALUE ``x y z`` and a
quaternion ``qx qy qz qw`` or ``roll pitch yaw``, space-separated: its body frame's pose, steered
there each step as AMBF's ROS plugin steers a body under a pose command). ``#`` starts a
comment. A joint's or a body's command holds until its next command, as AMBF holds the last
command it received."""

from __future__ import annotations

import math
from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error
from ..model.pose import Quat, rpy_to_quat
from .ambf import Command

JOINT_KINDS = ("position", "velocity", "effort")
KINDS = JOINT_KINDS + ("grasp", "release", "pose")


def read(path: str | Path) -> list[tuple[Command, SourceLocation]]:
    """The commands of a file, each with where it stands; a located error for a bad line."""
    text = inputs.read_text(path, "text", what="command file")
    out = []
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0]
        if not line.strip():
            continue
        fields = [f.strip() for f in line.split(",")]
        where = SourceLocation(str(path), n, 1)
        hint = "e.g. `0.5, position, psm1/baselink-yawlink, 0.3` or `1.0, grasp, psm1/Actuator0, Needle`"
        if len(fields) < 3:
            raise AdfError(error("command-syntax", "expected TIME, KIND, TARGET[, VALUE]", where, hint))
        try:
            t = float(fields[0])
        except ValueError:
            raise AdfError(error("command-syntax", f"time {fields[0]!r} is not a number", where, hint)) from None
        kind = fields[1].lower()
        col = SourceLocation(str(path), n, line.find(fields[1]) + 1)
        if kind not in KINDS:
            raise AdfError(error("command-kind", f"{fields[1]!r} is not one of {', '.join(KINDS)}", col, hint))
        if t < 0 or t != t:
            raise AdfError(error("command-syntax", f"time {fields[0]} is before the start", where, hint))
        need = 3 if kind == "release" else 4
        if len(fields) != need:
            raise AdfError(
                error("command-syntax", f"a {kind} command has {need} fields, not {len(fields)}", where, hint)
            )
        cmd = Command(t, kind, fields[2])
        if kind in JOINT_KINDS:
            try:
                cmd.value = float(fields[3])
            except ValueError:
                raise AdfError(error("command-syntax", f"value {fields[3]!r} is not a number", where, hint)) from None
            if cmd.value != cmd.value or abs(cmd.value) == float("inf"):
                raise AdfError(error("command-syntax", f"value {fields[3]} is not finite", where, hint))
        elif kind == "grasp":
            cmd.body = fields[3]
        elif kind == "pose":
            cmd.numbers = _pose(fields[3], where)
        out.append((cmd, where))
    return out


def _pose(text: str, where: SourceLocation) -> tuple:
    """A pose command's body frame, (x, y, z, qx, qy, qz, qw), from x y z and a quaternion or
    roll pitch yaw (fixed-axis X-Y-Z, as ADF's ``rpy``)."""
    hint = "e.g. `0.0, pose, Box, 0.2 0 1 0.1 0 0.3` (x y z roll pitch yaw) or `... 0.2 0 1 0 0 0 1` (qx qy qz qw)"
    try:
        n = [float(v) for v in text.split()]
    except ValueError:
        raise AdfError(error("command-syntax", f"pose {text!r} is not numbers", where, hint)) from None
    if len(n) not in (6, 7) or not all(math.isfinite(v) for v in n):
        raise AdfError(error("command-syntax", f"a pose is 6 or 7 finite numbers, not {text!r}", where, hint))
    q = rpy_to_quat(*n[3:]) if len(n) == 6 else Quat(*n[3:])
    if abs(math.hypot(*q) - 1.0) > 1e-3:
        raise AdfError(error("command-syntax", f"the quaternion of {text!r} is not of unit length", where, hint))
    return (*n[:3], *q)


def resolve(text: str, names: list[str], what: str, where: SourceLocation | None) -> str:
    """The one name of ``names`` that ``text`` names: itself, or without its spaces, or the
    unique name ending in it (after a '/'); a located error otherwise."""
    squeezed = text.replace(" ", "")
    for t in (text, squeezed):
        if t in names:
            return t
    hits = sorted({n for n in names if n.endswith("/" + squeezed) or n.endswith(squeezed) and squeezed.startswith("/")})
    if len(hits) == 1:
        return hits[0]
    if hits:
        raise AdfError(
            error(
                "command-target",
                f"{text!r} names several {what}s: {', '.join(hits[:6])}",
                where,
                "write more of the name",
            )
        )
    shown = ", ".join(names[:8]) + (" …" if len(names) > 8 else "")
    raise AdfError(
        error("command-target", f"no {what} {text!r} in the scene", where, f"the {what}s: {shown or 'none'}")
    )


def resolved(commands: list[tuple[Command, SourceLocation]], made: dict[str, list[str]]) -> list[Command]:
    """The commands with their targets as AMBF names of what adfkit built (``made``)."""
    out = []
    for c, where in commands:
        kind = "joint" if c.kind in JOINT_KINDS else "body" if c.kind == "pose" else "actuator"
        r = Command(c.t, c.kind, resolve(c.target, made[kind], kind, where), c.value, numbers=c.numbers)
        if c.kind == "grasp":
            r.body = resolve(c.body, made["body"], "body", where)
        out.append(r)
    return out
