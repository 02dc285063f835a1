"""External forces and torques held for a whole control step when the world steps PyBullet one
physics step at a time (Options.springs == "ambf": the springs act every physics step, as Bullet's
btGeneric6DofSpring2Constraint rows do in AMBF).

PyBullet clears every applied external force after each stepSimulation. A world that steps once per
control step (numSubSteps = control_substeps) holds what it applied over all its physics steps; one
that steps each physics step on its own applies again, before each of the control step's later
physics steps, what was applied for the control step (gravity overrides, damping, ghosts, clients'
commands), so that only the springs change inside it. Every force the runner applies goes through
push() and twist(); a world that records registers its client here."""

from __future__ import annotations

from collections import deque
from itertools import starmap
from operator import call

import pybullet as pb

# physics client id -> (call, *args) of each force applied since its last control step, in order
_recording: dict[int, list[tuple]] = {}


def push(uid: int, link: int, force, at, cid: int) -> None:
    """pb.applyExternalForce in the world frame, recorded when the client records."""
    pb.applyExternalForce(uid, link, force, at, pb.WORLD_FRAME, cid)
    held = _recording.get(cid)
    if held is not None:
        held.append((pb.applyExternalForce, uid, link, force, at, pb.WORLD_FRAME, cid))


def twist(uid: int, link: int, torque, cid: int) -> None:
    """pb.applyExternalTorque in the world frame, recorded when the client records."""
    pb.applyExternalTorque(uid, link, torque, pb.WORLD_FRAME, cid)
    held = _recording.get(cid)
    if held is not None:
        held.append((pb.applyExternalTorque, uid, link, torque, pb.WORLD_FRAME, cid))


def record(cid: int) -> None:
    _recording[cid] = []


def forget(cid: int) -> None:
    _recording.pop(cid, None)


def replay(cid: int) -> None:
    """Apply again what was applied since the control step began (PyBullet cleared it), in the
    order it was applied (the calls looped in C)."""
    deque(starmap(call, _recording.get(cid, ())), 0)


def clear(cid: int) -> None:
    """The control step is over: what comes next is the next one's."""
    held = _recording.get(cid)
    if held is not None:
        held.clear()
