"""What the runner does the same way on every engine, as a mixin of the PyBullet and MuJoCo
worlds: playing for a while with a progress bar, and the scene's grasp (close the jaws of a PSM
and fix what its finger ghosts or sensors detect to the tool with its constraint actuator).
The engine supplies ``step``, ``actuate``/``release``, ``overlapping``, the bodies' poses and
the articulation's drive."""

from __future__ import annotations

import numpy as np


class EngineNeutral:
    def run(self, seconds: float, progress=None) -> None:
        """Play ``seconds`` of simulated time in chunks of ~50 ms, updating ``progress``."""
        per = self.dt * self.opt.control_substeps
        total = int(round(seconds / per))
        chunk = max(1, int(0.05 / per))
        done = 0
        while done < total:
            k = min(chunk, total - done)
            self.step(k)
            done += k
            if progress is not None:
                rtf = self.sim_time / self.wall_time if self.wall_time else 0.0
                progress.update(k, suffix=f"{rtf:.2f}x real time")

    def grasp(self, psm: str, on: bool):
        """Close the jaws of ``psm`` and fix the body its finger ghosts (or a sensor) detect to the
        tool (``self.actuate``); ``on=False`` releases it and opens the jaws. Returns the grasped
        body, or None. With nothing detected, the nearest free body within 2 cm of the actuator."""
        act = next((a for a in self.actuators if psm in a.key or psm in a.parent.key), None)
        if act is None:
            raise KeyError(f"no constraint actuator for {psm!r}")
        art = act.parent.articulation
        jaws = [i for i, n in enumerate(art.joint_names) if "gripper" in n] if art is not None else []
        if not on:
            self.release(act)
            for i in jaws:
                art.targets[i] = 0.5
            if art is not None:
                art.drive()
            return None
        for i in jaws:
            art.targets[i] = 0.0
        if art is not None:
            art.drive()
        found = [b for g in self.ghosts if psm in g.key for b in self.overlapping(g)]
        found += [b for s in self.sensors if psm in s.key for b in s.sensed]
        own = {id(b) for b in self.bodies if b.articulation is not None and b.articulation is art}
        found = [b for b in found if id(b) not in own]
        if not found:
            at = (act.parent.world_matrix() @ act.location)[:3, 3]
            free = [b for b in self.bodies if not b.static and id(b) not in own]
            if not free:
                return None
            near = min(free, key=lambda b: np.linalg.norm(np.array(b.com_position()) - at))
            if np.linalg.norm(np.array(near.com_position()) - at) > 0.02:
                return None
            found = [near]
        self.actuate(act, found[0])
        return found[0]
