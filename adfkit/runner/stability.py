"""Instability caught while a world plays, in either engine: never a silent reset.

An engine that blows up does not always leave a trace at the end of a run: MuJoCo meets NaN or
a huge value in its state, warns, and resets the whole state to the model's initial pose (a
PSM jumps home, and a check at the end sees a calm scene); PyBullet carries NaN on, or flings a
body off at hundreds of metres a second before it settles somewhere. So each world watches
while it steps and keeps every event, with the simulated time and the body, for the report,
``metrics.json`` and Gymnasium's ``info``; any event makes the run unstable.

- MuJoCo: its warning counters (``MjData.warning``) for NaN/Inf/huge values in the positions,
  velocities and accelerations (after which MuJoCo resets the state) and for a singular
  inertia, read at every control step through MuJoCo's warning callback, which this module
  installs once per process (it also keeps MuJoCo from writing ``MUJOCO_LOG.TXT`` into the
  current folder: the messages go into the report instead).
- PyBullet: every dynamic body's position and velocity every ``CHECK_EVERY_S`` of simulated
  time: NaN or Inf, or a speed above ``FLUNG_SPEED``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

#: Simulated seconds between two PyBullet checks (each reads every dynamic body's state once).
CHECK_EVERY_S = 0.02
#: A body faster than this (m/s) has been flung by the solver: nothing in a surgical scene moves so.
FLUNG_SPEED = 100.0
#: Events kept per world (the first ones say what went wrong; the rest are counted).
MAX_EVENTS = 50


@dataclass
class Instability:
    time_s: float
    body: str | None
    kind: str  # "state-reset" (MuJoCo), "singular-inertia" (MuJoCo), "nan", "flung"
    message: str

    def as_dict(self) -> dict:
        return asdict(self)

    def __str__(self) -> str:
        who = f" ({self.body})" if self.body else ""
        return f"t = {self.time_s:.3f} s{who}: {self.message}"


class Watch:
    """The events of one world, in order."""

    def __init__(self) -> None:
        self.events: list[Instability] = []
        self.dropped = 0

    def add(self, event: Instability) -> None:
        if len(self.events) < MAX_EVENTS:
            self.events.append(event)
        else:
            self.dropped += 1

    def report(self) -> dict:
        return {
            "instabilities": [e.as_dict() for e in self.events],
            **({"instabilities_not_listed": self.dropped} if self.dropped else {}),
        }


# ---- MuJoCo -----------------------------------------------------------------------------------
_MJ_MESSAGES: list[str] = []
_MJ_HANDLER_SET = False


def install_mujoco_handler() -> None:
    """Route MuJoCo's warnings into this module (once per process): each world drains them at
    its next control step. Without a handler MuJoCo appends them to ./MUJOCO_LOG.TXT."""
    global _MJ_HANDLER_SET
    if _MJ_HANDLER_SET:
        return
    import mujoco

    mujoco.set_mju_user_warning(_MJ_MESSAGES.append)
    _MJ_HANDLER_SET = True


def mujoco_pending() -> bool:
    return bool(_MJ_MESSAGES)


def drain_mujoco(world, watch: Watch) -> None:
    """Turn the warnings MuJoCo raised since the last call into events of ``world``: the kind and
    the body from the warning counters (``lastinfo`` is the DOF), the text from the callback."""
    import mujoco

    messages = list(_MJ_MESSAGES)
    _MJ_MESSAGES.clear()
    _m, d = world.model, world.data
    w = mujoco.mjtWarning
    kinds = {
        w.mjWARN_BADQPOS: ("state-reset", "positions", "QPOS"),
        w.mjWARN_BADQVEL: ("state-reset", "velocities", "QVEL"),
        w.mjWARN_BADQACC: ("state-reset", "accelerations", "QACC"),
        w.mjWARN_INERTIA: ("singular-inertia", None, "inertia"),
    }
    seen = getattr(world, "_warnings_seen", {})
    found = False
    for code, (kind, what, word) in kinds.items():
        stat = d.warning[int(code)]
        if stat.number > seen.get(code, 0):
            seen[code] = stat.number
            found = True
            body = _body_of_dof(world, int(stat.lastinfo))
            text = next((x for x in messages if word.lower() in x.lower()), None)
            if kind == "state-reset":
                message = (
                    f"MuJoCo met NaN, Inf or a huge value in the {what} (DOF {stat.lastinfo}) and reset "
                    "the whole state to the initial pose"
                )
            else:
                message = f"MuJoCo found a singular inertia at DOF {stat.lastinfo}"
            watch.add(Instability(world.sim_time, body, kind, message + (f" ({text.strip()})" if text else "")))
    world._warnings_seen = seen
    if not found:
        for text in messages:  # another warning (contact buffer full, ...): reported, not an instability
            world.engine_warnings.append(f"t = {world.sim_time:.3f} s: {text.strip()}")


def _body_of_dof(world, dof: int) -> str | None:
    m = world.model
    if not 0 <= dof < m.nv:
        return None
    bid = int(m.dof_bodyid[dof])
    sb = world._body_of_id.get(bid) if hasattr(world, "_body_of_id") else None
    return sb.key if sb is not None else None


# ---- PyBullet ---------------------------------------------------------------------------------
def check_pybullet(world, watch: Watch) -> None:
    """NaN/Inf or a flung body among the world's dynamic bodies, now."""
    for sb in world.bodies:
        if sb.static:
            continue
        p, _, v, _ = sb.state()
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(v))):
            if not any(e.body == sb.key and e.kind == "nan" for e in watch.events):
                watch.add(
                    Instability(
                        world.sim_time, sb.key, "nan", "PyBullet gives the body a NaN or Inf position or velocity"
                    )
                )
            continue
        speed = float(np.linalg.norm(v))
        if speed > FLUNG_SPEED and not any(e.body == sb.key and e.kind == "flung" for e in watch.events):
            watch.add(
                Instability(
                    world.sim_time,
                    sb.key,
                    "flung",
                    f"the solver flung the body at {speed:.3g} m/s (more than {FLUNG_SPEED:g} m/s)",
                )
            )
