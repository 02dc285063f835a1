"""CPU time of the PyBullet runner playing the suturing set for S seconds (default 10) under the
settings `adfkit run` and `adfkit parity` play (AMBF's ghosts, springs, bodies, the file's link
shapes) and under the legacy flags (``--springs implicit --ghosts hole-friction --bodies
pybullet``), alternated ``--rounds`` times on freshly built worlds so that both see the same load;
then, with ``--profile``, where one second of each goes, by cProfile on CPU time.

    .venv/bin/python bench/runner_cpu.py [--seconds S] [--rounds R] [--profile]

The figure is this process's CPU time (``time.process_time``) of the stepping alone, as
``adfkit parity`` times its side (building the world and reading the samples left out). The
profile's parts: Bullet's own step (``stepSimulation``: the floor no runner change removes), the
ghosts' collision pass (``interact._manifold_points``, wherever it runs the pass), the
springs (``SpringSet.apply``, at every physics step under AMBF's springs), the forces applied
again before each physics step (``held.replay``) and the rest of the control step. cProfile adds
its cost to every Python call, so the Python shares are upper bounds. The suturing set is the
corpus's (launch indices 6-11) when ``../shared/corpus`` is there, else the bundled suturing scene.
Prints figures, asserts nothing.
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import pstats
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

#: Options set by ``adfkit run`` / ``adfkit parity`` that the legacy flags put back
RULES = ("ghosts", "springs", "link_shapes", "bodies")
LEGACY = {"ghosts": "hole-friction", "springs": "implicit", "bodies": "pybullet", "link_shapes": "body"}

#: the profile's parts: (label, the functions whose cumulative time it is)
PARTS = (
    ("Bullet's step (stepSimulation)", ("stepSimulation",)),
    ("ghost collision pass", ("interact.py:_manifold_points",)),
    ("springs (SpringSet.apply)", ("spring_forces.py:apply",)),
    ("forces applied again (held.replay)", ("held.py:replay",)),
)


def options(rules: dict):
    from adfkit.runner import Options

    opt = Options(control_substeps=4, ground=True, visuals=False, renderer="tiny")  # parity/session.py's
    for k, v in rules.items():
        setattr(opt, k, v)
    return opt


def run_defaults() -> dict:
    """The four rules as ``adfkit parity`` (and ``adfkit run``) play them unless asked otherwise."""
    from adfkit.parity.session import Request

    return {f.name: f.default for f in dataclasses.fields(Request) if f.name in RULES}


def step_cpu(scene, rules: dict, seconds: float) -> float:
    from adfkit.runner import open_world

    world = open_world(scene, options(rules), engine="pybullet")
    try:
        n = int(round(seconds / (world.dt * world.opt.control_substeps)))
        c0 = time.process_time()
        world.step(n)
        return time.process_time() - c0
    finally:
        world.close()


def _name(key) -> str:
    file, _line, name = key
    return name.rstrip(">") if file == "~" else f"{Path(file).name}:{name}"


def profile(scene, rules: dict, seconds: float) -> None:
    from adfkit.runner import open_world

    world = open_world(scene, options(rules), engine="pybullet")
    try:
        n = int(round(seconds / (world.dt * world.opt.control_substeps)))
        prof = cProfile.Profile(time.process_time)  # CPU time: a loaded machine's waits left out
        prof.runcall(world.step, n)
    finally:
        world.close()
    st = pstats.Stats(prof)
    total = sum(v[3] for k, v in st.stats.items() if _name(k).endswith("world.py:step"))
    shown = 0.0
    for label, names in PARTS:
        t = sum(v[3] for k, v in st.stats.items() if any(_name(k).endswith(n) for n in names))
        shown += t
        print(f"    {label:40s} {t:6.2f} s  {100 * t / total:4.0f} %")
    print(f"    {'the rest of the control step':40s} {total - shown:6.2f} s  {100 * (total - shown) / total:4.0f} %")
    calls = sum(v[1] for k, v in st.stats.items() if k[0] == "~" and k[2].startswith("<built-in method pybullet."))
    print(f"    PyBullet calls: {calls} ({calls / n:.0f} a control step)")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--profile", action="store_true", help="also profile 1 s of each")
    args = ap.parse_args()
    from speed import scene_and_label

    scene, label = scene_and_label()
    settings = (("adfkit run / parity defaults", run_defaults()), ("legacy flags", LEGACY))
    print(f"scene: {label}; {args.seconds:g} s simulated, PyBullet, {args.rounds} round(s) alternated")
    cpu: dict[str, list[float]] = {name: [] for name, _ in settings}
    for _ in range(args.rounds):
        for name, rules in settings:
            cpu[name].append(step_cpu(scene, rules, args.seconds))
    for name, rules in settings:
        shown = ", ".join(f"{k} {rules[k]}" for k in RULES)
        runs = " ".join(f"{c:.2f}" for c in cpu[name])
        print(f"  {name} ({shown}): CPU {statistics.median(cpu[name]):.2f} s (runs: {runs})")
    if args.profile:
        for name, rules in settings:
            print(f"  where 1 s of it goes, {name} (cProfile, cumulative):")
            profile(scene, rules, 1.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
