"""PyBullet's side of the stability watch (runner/stability.py): NaN/Inf or a flung body."""

from __future__ import annotations

import numpy as np

from ..stability import FLUNG_SPEED, Instability, Watch


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
