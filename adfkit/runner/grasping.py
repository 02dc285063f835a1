"""The scene's grasp, the same for every engine: close the jaws of a PSM and fix what its finger
ghosts (or sensors) detect to the tool with its constraint actuator; open them to release.
The engine supplies ``actuate``/``release``, ``overlapping``, the bodies' poses and the
articulation's drive."""
from __future__ import annotations

import numpy as np


def grasp(world, psm: str, on: bool):
    """Close the jaws of ``psm`` and fix the body its finger ghosts (or a sensor) detect to the
    tool (``world.actuate``); ``on=False`` releases it and opens the jaws. Returns the grasped
    body, or None. With nothing detected, the nearest free body within 2 cm of the actuator."""
    act = next((a for a in world.actuators if psm in a.key or psm in a.parent.key), None)
    if act is None:
        raise KeyError(f"no constraint actuator for {psm!r}")
    art = act.parent.articulation
    jaws = [i for i, n in enumerate(art.joint_names) if "gripper" in n] if art is not None else []
    if not on:
        world.release(act)
        for i in jaws:
            art.targets[i] = 0.5
        if art is not None:
            art.drive()
        return None
    for i in jaws:
        art.targets[i] = 0.0
    if art is not None:
        art.drive()
    found = [b for g in world.ghosts if psm in g.key for b in world.overlapping(g)]
    found += [b for s in world.sensors if psm in s.key for b in s.sensed]
    own = {id(b) for b in world.bodies if b.articulation is not None and b.articulation is art}
    found = [b for b in found if id(b) not in own]
    if not found:
        at = (act.parent.world_matrix() @ act.location)[:3, 3]
        free = [b for b in world.bodies if not b.static and id(b) not in own]
        if not free:
            return None
        near = min(free, key=lambda b: np.linalg.norm(np.array(b.com_position()) - at))
        if np.linalg.norm(np.array(near.com_position()) - at) > 0.02:
            return None
        found = [near]
    world.actuate(act, found[0])
    return found[0]
