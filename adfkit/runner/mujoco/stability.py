"""MuJoCo's side of the stability watch (runner/stability.py): its warnings, caught through the
warning callback this module installs once per process, turned into events with the body."""

from __future__ import annotations

from ..stability import Instability, Watch

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


def pending_messages() -> list[str]:
    """The list MuJoCo's warnings land in (empty while there are none): a world's step loop
    tests it directly, without a call per step."""
    return _MJ_MESSAGES


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
