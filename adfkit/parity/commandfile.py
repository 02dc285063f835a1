"""The command file a parity run is driven by: one command a line,

    TIME, KIND, TARGET[, VALUE]

TIME in simulated seconds; KIND ``position``, ``velocity`` or ``effort`` (TARGET a joint, VALUE
the command: rad, rad/s, N·m, or m, m/s, N for a prismatic joint), ``grasp`` (TARGET a constraint
actuator, VALUE the body it fixes) or ``release`` (TARGET an actuator). Names are AMBF's (namespace
and `name`, spaces removed) or any unique end of one (``psm1/baselink-yawlink``, ``base link-yaw
link`` when only one model has it). ``#`` starts a comment. A joint command holds until the
joint's next command, as AMBF holds the last command it received."""

from __future__ import annotations

from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error
from .ambf import Command

JOINT_KINDS = ("position", "velocity", "effort")
KINDS = JOINT_KINDS + ("grasp", "release")


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
        out.append((cmd, where))
    return out


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
        kind = "joint" if c.kind in JOINT_KINDS else "actuator"
        r = Command(c.t, c.kind, resolve(c.target, made[kind], kind, where), c.value)
        if c.kind == "grasp":
            r.body = resolve(c.body, made["body"], "body", where)
        out.append(r)
    return out
