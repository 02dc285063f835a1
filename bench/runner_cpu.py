"""CPU time of the PyBullet runner playing the suturing set for S seconds (default 10) under the
settings `adfkit run` and `adfkit parity` play (AMBF's ghosts, springs, bodies, the file's link
shapes) and under the legacy flags (``--springs implicit --ghosts hole-friction --bodies
pybullet``), alternated ``--rounds`` times on freshly built worlds so that both see the same load;
then, with ``--profile``, where one second of each goes, by cProfile on CPU time.

    .venv/bin/python bench/runner_cpu.py [--seconds S] [--rounds R] [--profile] [--ambf [DIR]]
                                          [--against REV] [--each]

With ``--ambf`` (a built AMBF tree; no DIR: ``$ADFKIT_AMBF``, else the one ``make ambf`` builds)
each round also plays the same scene for the same seconds in ``ambf_simulator`` (headless, fixed
1 ms steps, as ``adfkit parity`` runs it) and once for no time at all, alternated with adfkit's
runs so that all see the same load, and prints AMBF's CPU (user + system of its process) for the
whole run and for the run less its loading, beside adfkit's.

With ``--against REV`` it times, under the run / parity settings only, this tree's runner and the
one at git revision REV (``git archive`` into a temporary folder) in fresh processes, alternated
round by round, and prints both (split into Bullet's steps, the springs, the ghosts, the forces
applied again and the rest, timed around their calls), their ratio, the sum over each 0.1 s
chunk of its least CPU time over the rounds (a shared machine's load only ever adds to a chunk)
and whether every body ended where the other's did (a change that only reorganises the runner
keeps them bit for bit).

With ``--each`` it prints what each of AMBF's behaviours costs: the run / parity settings, then
the same with one rule put back to its legacy flag (the others as ``adfkit run`` plays them), then
all four legacy, alternated ``--rounds`` times in one process, each with its split (as
``--against``'s) and its difference from the run / parity settings' median.

The figure is this process's CPU time (``time.process_time``) of the stepping alone, as
``adfkit parity`` times its side (building the world and reading the samples left out). The
profile's parts: Bullet's own step (``stepSimulation``: the floor no runner change removes), the
ghosts' collision pass (``interact._manifold_points``, wherever it runs the pass), the
springs (``SpringSet.apply``, at every physics step under AMBF's springs), the forces applied
again before each physics step (``held.replay``) and the rest of the control step. cProfile adds
its cost to every Python call, so the Python shares are upper bounds. The suturing set is the
corpus's (launch indices 6-11) when ``$ADFKIT_CORPUS`` (else ``../shared/corpus``) is there, else the bundled suturing scene.
Prints figures, asserts nothing.
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import hashlib
import json
import pstats
import statistics
import subprocess
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


#: --against's split of the CPU time, unprofiled: each part timed around its calls
SPLIT = ("Bullet's steps", "springs", "ghosts", "forces again")
#: --against times the stepping in chunks of so many control steps (0.1 s)
CHUNK = 25


def _timed(split: dict, part: str, fn):
    def timed(*args, **kw):
        t = time.process_time()
        try:
            return fn(*args, **kw)
        finally:
            split[part] += time.process_time() - t

    return timed


def step_cpu(scene, rules: dict, seconds: float, digest: bool = False):
    """CPU seconds of stepping; with ``digest``, (those, a digest of every body's final state,
    {part: CPU seconds} of SPLIT, the CPU seconds of each CHUNK control steps)."""
    import pybullet as pb

    from adfkit.runner import open_world
    from adfkit.runner.pybullet import held

    world = open_world(scene, options(rules), engine="pybullet")
    split = dict.fromkeys(SPLIT, 0.0)
    step, replay = pb.stepSimulation, held.replay
    if digest:  # stepSimulation and held.replay are looked up in their modules at each call
        pb.stepSimulation, held.replay = _timed(split, SPLIT[0], step), _timed(split, SPLIT[3], replay)
        world.springs.apply = _timed(split, SPLIT[1], world.springs.apply)
        world._update_ghosts = _timed(split, SPLIT[2], world._update_ghosts)
    try:
        n = int(round(seconds / (world.dt * world.opt.control_substeps)))
        if not digest:
            c0 = time.process_time()
            world.step(n)
            return time.process_time() - c0
        chunks = []  # CPU seconds of each CHUNK control steps
        for done in range(0, n, CHUNK):
            c0 = time.process_time()
            world.step(min(CHUNK, n - done))
            chunks.append(time.process_time() - c0)
        h = hashlib.sha256(repr([sb.state() for sb in world.bodies]).encode())
        return sum(chunks), h.hexdigest()[:12], split, chunks
    finally:
        pb.stepSimulation, held.replay = step, replay
        world.close()


def child(root: str, seconds: float) -> int:
    """One side of ``--against``: the runner under ``root`` (first on the path), run / parity settings."""
    from against import use_tree

    use_tree(root)
    from speed import scene_and_label

    scene, _ = scene_and_label()
    cpu, digest, split, chunks = step_cpu(scene, run_defaults(), seconds, digest=True)
    print(json.dumps({"cpu": cpu, "digest": digest, "split": split, "chunks": chunks}))
    return 0


def against(rev: str, seconds: float, rounds: int) -> None:
    """This tree's runner and REV's, in fresh processes, alternated round by round."""
    from against import alternated

    def one_round(tree: str) -> dict:
        cmd = [sys.executable, __file__, "--seconds", str(seconds), "--child", tree]
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
        return json.loads(out.strip().splitlines()[-1])

    runs = alternated(rev, rounds, one_round)
    for name, got in runs.items():
        cpu = [g["cpu"] for g in got]
        print(f"  {name}: CPU {statistics.median(cpu):.2f} s (runs: {' '.join(f'{c:.2f}' for c in cpu)})")
        parts = {p: statistics.median(g["split"][p] for g in got) for p in SPLIT}
        rest = statistics.median(cpu) - sum(parts.values())
        print("    " + ", ".join(f"{p} {t:.2f} s" for p, t in parts.items()) + f", the rest {rest:.2f} s (medians)")
    new, base = ([g["cpu"] for g in runs[k]] for k in ("this tree", rev))
    print(f"  this tree / {rev}: {statistics.median(new) / statistics.median(base):.3f} (median over median)")
    # each 0.1 s chunk's least CPU time over the rounds, summed: what a quiet machine would take
    # (a chunk does the same work in every round; another process's load only ever adds)
    least = {k: sum(map(min, zip(*(g["chunks"] for g in got)))) for k, got in runs.items()}
    new_l, base_l = least["this tree"], least[rev]
    print(f"  least per chunk, summed: at {rev} {base_l:.2f} s, this tree {new_l:.2f} s, ratio {new_l / base_l:.3f}")
    same = {g["digest"] for got in runs.values() for g in got}
    print(f"  final states: {'the same to the bit' if len(same) == 1 else 'differ: ' + ', '.join(sorted(same))}")


def each(scene, seconds: float, rounds: int) -> None:
    """--each: the run / parity settings, each rule alone back to its legacy flag, all legacy."""
    run = run_defaults()
    sets = [("run / parity settings", run)]
    sets += [(f"{k} {LEGACY[k]}", {**run, k: LEGACY[k]}) for k in RULES if LEGACY[k] != run[k]]
    sets.append(("all legacy", dict(LEGACY)))
    got: dict[str, list[tuple]] = {name: [] for name, _ in sets}
    for r in range(rounds):
        for name, rules in sets[:: 1 if r % 2 == 0 else -1]:
            cpu, _digest, split, _chunks = step_cpu(scene, rules, seconds, digest=True)
            got[name].append((cpu, split))
    base = statistics.median(c for c, _ in got[sets[0][0]])
    for name, _ in sets:
        cpu = statistics.median(c for c, _ in got[name])
        parts = ", ".join(f"{p} {statistics.median(s[p] for _, s in got[name]):.2f}" for p in SPLIT)
        runs = " ".join(f"{c:.2f}" for c, _ in got[name])
        print(f"  {name:28s} CPU {cpu:6.2f} s, {cpu - base:+.2f} s (runs: {runs}; {parts})")


def _name(key) -> str:
    file, _line, name = key
    return name.rstrip(">") if file == "~" else f"{Path(file).name}:{name}"


def profile(scene, rules: dict, seconds: float) -> None:
    from adfkit.runner import open_world
    from adfkit.runner.pybullet import held

    world = open_world(scene, options(rules), engine="pybullet")
    replay, replayed = held.replay, [0]

    def counted(cid: int) -> None:  # held.replay's calls go through starmap, which cProfile does not see
        replayed[0] += len(held._recording.get(cid, ()))
        replay(cid)

    held.replay = counted
    try:
        n = int(round(seconds / (world.dt * world.opt.control_substeps)))
        prof = cProfile.Profile(time.process_time)  # CPU time: a loaded machine's waits left out
        prof.runcall(world.step, n)
    finally:
        held.replay = replay
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
    # the springs apply their torques and forces through map, whose calls cProfile does not see
    springs, hidden = world.springs, 0
    if springs.joints:
        hidden = len(springs._twisted[0]) + (len(springs._pushed[1]) if springs.free_lin.size else 0)
    calls += hidden * sum(v[1] for k, v in st.stats.items() if _name(k).endswith("spring_forces.py:apply"))
    calls += replayed[0]
    print(f"    PyBullet calls: {calls} ({calls / n:.0f} a control step)")


def scene_stage():
    """The launch file and model indices of ``speed.scene_and_label``'s scene, for AMBF."""
    from speed import CORPUS

    launch = CORPUS / "src" / "launch.yaml"
    if launch.is_file():
        return launch, [6, 7, 8, 9, 10, 11]
    from adfkit.adf import load

    launch = ROOT / "sample_scenes" / "suturing" / "launch.yaml"
    return launch, list(range(len(load(launch, "launch").multibody_configs or [])))


def ambf_cpu(build, seconds: float) -> float:
    """CPU seconds (user + system) of one ``ambf_simulator`` process playing the scene for
    ``seconds`` (0: loading it alone), as ``adfkit parity`` runs it."""
    import resource

    from adfkit.parity import ambf

    launch, indices = scene_stage()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    ambf.run(build, ambf.Stage(launch.resolve(), indices), seconds, every=max(seconds, 0.1))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--profile", action="store_true", help="also profile 1 s of each")
    ap.add_argument("--against", metavar="REV", help="time this tree's runner against git revision REV's")
    ap.add_argument("--each", action="store_true", help="what each of AMBF's behaviours costs")
    ap.add_argument("--ambf", nargs="?", const="", metavar="DIR", help="time AMBF on the same scene too")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args.child, args.seconds)
    from speed import scene_and_label

    if args.against:
        print(f"{args.seconds:g} s simulated, PyBullet, run / parity settings, {args.rounds} round(s) alternated")
        against(args.against, args.seconds, args.rounds)
        return 0
    scene, label = scene_and_label()
    if args.each:
        print(f"scene: {label}; {args.seconds:g} s simulated, PyBullet, {args.rounds} round(s) alternated")
        each(scene, args.seconds, args.rounds)
        return 0
    settings = (("adfkit run / parity defaults", run_defaults()), ("legacy flags", LEGACY))
    print(f"scene: {label}; {args.seconds:g} s simulated, PyBullet, {args.rounds} round(s) alternated")
    build = None
    if args.ambf is not None:
        from adfkit.parity import ambf

        build = ambf.find_build(args.ambf or None)
    cpu: dict[str, list[float]] = {name: [] for name, _ in settings}
    whole: list[float] = []
    loading: list[float] = []
    for _ in range(args.rounds):
        for name, rules in settings:
            cpu[name].append(step_cpu(scene, rules, args.seconds))
        if build is not None:
            whole.append(ambf_cpu(build, args.seconds))
            loading.append(ambf_cpu(build, 0.0))
    for name, rules in settings:
        shown = ", ".join(f"{k} {rules[k]}" for k in RULES)
        runs = " ".join(f"{c:.2f}" for c in cpu[name])
        print(f"  {name} ({shown}): CPU {statistics.median(cpu[name]):.2f} s (runs: {runs})")
    if build is not None:
        runs = " ".join(f"{w:.2f}" for w in whole)
        stepping = [w - x for w, x in zip(whole, loading)]
        print(f"  AMBF (ambf_simulator, whole process): CPU {statistics.median(whole):.2f} s (runs: {runs})")
        print(
            f"  AMBF less its loading (each run less a 0 s run's {statistics.median(loading):.2f} s): "
            f"CPU {statistics.median(stepping):.2f} s (runs: {' '.join(f'{v:.2f}' for v in stepping)})"
        )
    if args.profile:
        for name, rules in settings:
            print(f"  where 1 s of it goes, {name} (cProfile, cumulative):")
            profile(scene, rules, 1.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
